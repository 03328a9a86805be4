#!/usr/bin/env bash
# A column of the seed scene's saturated sand (0.4 m wide, 0.6 m high, E = 5e7 Pa, Tresca 200 Pa)
# collapses under 1 m of water on a flat floor, 20 mm cells, one rank, 0.3 s (~10 500 steps). The
# same sand and fluids as input/rzadkiewicz.yaml without the bed: the smallest scene that showed the
# coupled step's instability (the kinetic energy outgrowing what the sand's descent released, from
# the water next to the sand's faces, at 0.14 s; doc/mpmice.md). check_seed_scene.py checks masses,
# descent, finiteness and the energy budget at every output.
set -eu
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cat > "$work/column.yaml" <<YAML
cfdmpm:
  title: "Sand column collapse under water, 20 mm cells"
  domain: {dimension: 2, lower: [0.0, 0.0], upper: [2.0, 1.2], cells: [100, 60], patch_cells: [20, 20], gravity: [0.0, -9.81]}
  materials:
    sand:
      kind: solid
      density: 1985.0
      model: {type: tresca, youngs_modulus: 5.0e7, poisson_ratio: 0.25, yield_stress: 200.0}
      particles_per_cell: 2
    water:
      kind: fluid
      equation_of_state: {type: linear_water, bulk_modulus: 2.15e9, reference_density: 999.8, reference_pressure: 101325.0, reference_temperature: 278.15, thermal_expansion: 0.18}
      viscosity: 855.0e-6
      specific_heat: 4200.0
      thermal_conductivity: 0.0
    air:
      kind: fluid
      equation_of_state: {type: ideal_gas, gas_constant: 287.0, gamma: 1.4}
      viscosity: 18.45e-6
      thermal_conductivity: 0.0
  initial_state: {background_material: air, temperature: 278.15, pressure: 101325.0, hydrostatic: true}
  regions:
    water_level: {material: water, shape: half_plane, point: [0.0, 1.0], normal: [0.0, 1.0]}
    column: {material: sand, shape: polygon, vertices: [[0.0, 0.0], [0.4, 0.0], [0.4, 0.6], [0.0, 0.6]]}
  boundary_conditions:
    x-: {velocity: no_slip}
    x+: {velocity: no_slip}
    y-: {velocity: no_slip}
    y+: {velocity: no_slip}
  ice: {odd_even_filter: 0.25}
  time: {end_time: ${END_TIME:-0.3}, cfl: 0.25}
  output:
    directory: $work/out
    interval: 0.02
    fields: [volume_fraction, velocity, pressure, particle_velocity, particle_material]
YAML
"$CFDMPM" "$work/column.yaml" > "$work/log"
/usr/bin/python3 "$SOURCE_DIR/test/mpmice/check_seed_scene.py" "$work/out" 0
