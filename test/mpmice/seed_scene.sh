#!/usr/bin/env bash
# The seed scene, input/rzadkiewicz.yaml, at 20 mm cells for 0.1 s on N ranks through the program;
# check_seed_scene.py checks masses, the slide's descent, finiteness and the energy budget.
set -eu
ranks=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed -e "s|directory: .*|directory: $work/out|" -e "s|^    cell_size: 0.01 .*|    cell_size: 0.02|" \
    -e "s|    end_time: 0.8|    end_time: 0.1|" -e "s|    fields: .*|    fields: [volume_fraction, velocity, pressure, particle_velocity, particle_material]|" \
    "$SOURCE_DIR/input/rzadkiewicz.yaml" > "$work/slide.yaml"
grep -q "^    cell_size: 0.02$" "$work/slide.yaml"
grep -q "end_time: 0.1" "$work/slide.yaml"
"$MPIEXEC" -n "$ranks" "$CFDMPM" "$work/slide.yaml" > "$work/log"
/usr/bin/python3 "$SOURCE_DIR/test/mpmice/check_seed_scene.py" "$work/out"
