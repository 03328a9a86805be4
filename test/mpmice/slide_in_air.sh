#!/usr/bin/env bash
# The seed scene with its water level lowered to y = 0.8 m, so that the sand starts wholly in air, at
# 20 mm cells for 0.15 s on N ranks: no step may be undone and retried (the air in the gaps of the
# sliding sand's particles refused 939 of 3871 steps before it was tied to the sand on the faces
# inside it and let leave whole where it is a trace; the first at 0.07 s), and the seed scene's
# checks with the sand's weight in air.
set -eu
ranks=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed -e "s|directory: .*|directory: $work/out|" -e "s|^    cell_size: 0.01 .*|    cell_size: 0.02|" \
    -e "s|      point: \[0.0, 1.6\]|      point: [0.0, 0.8]|" \
    -e "s|    end_time: 0.8|    end_time: 0.15|" -e "s|    fields: .*|    fields: [volume_fraction, velocity, pressure, particle_velocity, particle_material]|" \
    "$SOURCE_DIR/input/rzadkiewicz.yaml" > "$work/slide.yaml"
grep -q "^    cell_size: 0.02$" "$work/slide.yaml"
grep -q "point: \[0.0, 0.8\]" "$work/slide.yaml"
grep -q "end_time: 0.15" "$work/slide.yaml"
"$MPIEXEC" -n "$ranks" "$CFDMPM" "$work/slide.yaml" > "$work/log"
# Air: 1.27 kg/m^3 at 278.15 K (the scene's ideal gas).
/usr/bin/python3 "$SOURCE_DIR/test/mpmice/check_seed_scene.py" "$work/out" 1 1.27 --no-retries
