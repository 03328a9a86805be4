#!/usr/bin/env bash
# input/floating-block.yaml as shipped (5 mm cells, 2.5 s) on 2 ranks (label validation, ~10
# minutes): check_floating_block.py (the block turns corner-down to 45 +- 5 degrees, its centre at
# the water level, every material's mass kept).
set -eu
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed -e "s|directory: .*|directory: $work/out|" "$SOURCE_DIR/input/floating-block.yaml" > "$work/block.yaml"
grep -q "directory: $work/out" "$work/block.yaml"
"$MPIEXEC" -n 2 "$CFDMPM" "$work/block.yaml" > "$work/log"
# The scene's block is turned 5 degrees; the water level is at y = 0.1 m; cells of 5 mm.
/usr/bin/python3 "$SOURCE_DIR/test/mpmice/check_floating_block.py" "$work/out" 5 0.1 0.005
