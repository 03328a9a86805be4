#!/usr/bin/env bash
# The dam break in 2-D and in 3-D (five cells deep, free-slip in z) on N ranks: every z-slice of
# the 3-D run must equal the 2-D run (check_3d_equals_2d.py states the bound).
set -eu
ranks=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$PYTHON" "$SOURCE_DIR/test/app/check_3d_equals_2d.py" write "$SOURCE_DIR/input/dam-break.yaml" "$work"
"$MPIEXEC" -n "$ranks" "$CFDMPM" "$work/2d.yaml" > "$work/2d.log"
"$MPIEXEC" -n "$ranks" "$CFDMPM" "$work/3d.yaml" > "$work/3d.log"
"$PYTHON" "$SOURCE_DIR/test/app/check_3d_equals_2d.py" check "$work"
