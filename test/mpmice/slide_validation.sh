#!/usr/bin/env bash
# The seed scene, input/rzadkiewicz.yaml, at 20 mm cells to 0.4 s on 2 ranks (label validation):
# check_seed_scene.py (every material's mass, descent, finiteness, energy budget), then
# check_slide_validation.py: the wave's trough at 0.4 s against cfdmpm's committed 5 mm run
# (data/reference/cfdmpm-rzadkiewicz-5mm.csv).
set -eu
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed -e "s|directory: .*|directory: $work/out|" -e "s|^    cell_size: 0.01 .*|    cell_size: 0.02|" \
    -e "s|    end_time: 0.8|    end_time: 0.4|" -e "s|    interval: 0.05|    interval: 0.1|" \
    -e "s|    fields: .*|    fields: [volume_fraction, velocity, pressure, particle_velocity, particle_material]|" \
    "$SOURCE_DIR/input/rzadkiewicz.yaml" > "$work/slide.yaml"
grep -q "^    cell_size: 0.02$" "$work/slide.yaml"
grep -q "end_time: 0.4" "$work/slide.yaml"
grep -q "interval: 0.1" "$work/slide.yaml"
"$MPIEXEC" -n 2 "$CFDMPM" "$work/slide.yaml" > "$work/log"
/usr/bin/python3 "$SOURCE_DIR/test/mpmice/check_seed_scene.py" "$work/out"
/usr/bin/python3 "$SOURCE_DIR/test/mpmice/check_slide_validation.py" "$work/out" \
    "$SOURCE_DIR/data/reference/cfdmpm-rzadkiewicz-5mm.csv"
