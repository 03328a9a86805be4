#!/usr/bin/env bash
# Bad scene files stop the program before anything is written: exit code 2, a message naming the
# key, the value and what is allowed, and no output directory.
set -u
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0

# expect <name> <yaml text> <substring of the message>...
expect() {
  local name=$1 yaml=$2
  shift 2
  printf '%s\n' "$yaml" > "$work/$name.yaml"
  "$CFDMPM" "$work/$name.yaml" > "$work/$name.out" 2> "$work/$name.err"
  local code=$?
  if [ "$code" != 2 ]; then
    echo "FAIL $name: exit code $code, expected 2"; cat "$work/$name.err"; failures=$((failures + 1)); return
  fi
  for needle in "$@"; do
    if ! grep -qF -- "$needle" "$work/$name.err"; then
      echo "FAIL $name: message lacks '$needle':"; cat "$work/$name.err"; failures=$((failures + 1)); return
    fi
  done
  if [ -e "$work/out" ]; then
    echo "FAIL $name: output directory was created"; failures=$((failures + 1)); rm -rf "$work/out"; return
  fi
  echo "ok   $name: $(head -c 300 "$work/$name.err")"
}

# A valid scene to break one key at a time.
good() {
  cat <<YAML
cfdmpm:
  domain: {dimension: 2, lower: [0.0, 0.0], upper: [1.0, 0.5], cells: [20, 10], patch_cells: [5, 5], gravity: [0.0, -9.81]}
  materials:
    water:
      kind: fluid
      equation_of_state: {type: linear_water, bulk_modulus: 2.15e9, reference_density: 998.0, reference_pressure: 101325.0, reference_temperature: 293.15, thermal_expansion: 0.18}
      viscosity: ${VISCOSITY:-1.0e-3}
      specific_heat: 4186.0
    air:
      kind: ${AIR_KIND:-fluid}
      equation_of_state: {type: ideal_gas, gas_constant: 287.0, gamma: 1.4}
      viscosity: 1.8e-5
  initial_state: {background_material: air, temperature: 293.15, pressure: 101325.0}
  regions:
    column: {material: ${REGION_MATERIAL:-water}, shape: box, lower: [0.0, 0.0], upper: [${REGION_X:-0.2}, 0.3]}
  time: {end_time: 0.1, cfl: ${CFL:-0.25}}
  output: {directory: $work/out, interval: 0.01}
YAML
}

# The unbroken scene must pass, or the failures below would prove nothing.
good > "$work/good.yaml"
if ! "$CFDMPM" --check "$work/good.yaml" > /dev/null; then
  echo "FAIL the reference scene is refused"; exit 1
fi

expect negative_viscosity "$(VISCOSITY=-1 good)" "viscosity" "-1" ">= 0"
expect negative_density "$(good | sed 's/reference_density: 998.0/reference_density: -998.0/')" "reference_density" "-998" "> 0"
expect wrong_type "$(good | sed 's/end_time: 0.1/end_time: soon/')" "end_time" "soon" "number"
expect cfl_out_of_range "$(CFL=1.5 good)" "cfl" "1.5" "(0, 1]"
expect unknown_material "$(REGION_MATERIAL=mud good)" "mud" "water" "air"
expect unknown_kind "$(AIR_KIND=gas good)" "kind" "gas" "fluid"
expect region_outside "$(REGION_X=1.7 good)" "column" "1.7"
expect unknown_key "$(good | sed 's/  time: {/  time: {end_tme: 1, /')" "end_tme"
expect missing_key "$(good | grep -v '  time:')" "time"
expect two_top_level_keys "$(good; echo 'extra: {a: 1}')" "extra"
"$CFDMPM" "$work/does-not-exist.yaml" > /dev/null 2> "$work/missing.err"
code=$?
if [ "$code" != 2 ] || ! grep -q "does-not-exist.yaml" "$work/missing.err"; then
  echo "FAIL unreadable file: exit $code"; cat "$work/missing.err"; failures=$((failures + 1))
else
  echo "ok   unreadable file: $(cat "$work/missing.err")"
fi
"$CFDMPM" --no-such-option > /dev/null 2>&1
[ $? = 2 ] || { echo "FAIL unknown option: exit code not 2"; failures=$((failures + 1)); }

echo "$failures failure(s)"
[ "$failures" = 0 ]
