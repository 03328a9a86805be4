#!/usr/bin/env bash
# Granular column collapse (input/granular-column.yaml, aspect ratio 1, Drucker-Prager with
# friction angle 30 deg) run to rest; check_granular_heap.py compares the runout with the
# experimental scaling and the heap's slope with the friction angle. Label "validation" (minutes).
set -eu
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed -e "s|directory: .*|directory: $work/out|" "$SOURCE_DIR/input/granular-column.yaml" > "$work/column.yaml"
"$MPIEXEC" -n 2 "$CFDMPM" "$work/column.yaml" > "$work/log"
"$PYTHON" "$SOURCE_DIR/test/app/check_granular_heap.py" "$work/out"
