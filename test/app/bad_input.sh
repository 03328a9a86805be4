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

# expect_both <name> <yaml text> <substring>...: `--check` and the run both refuse the scene with exit
# code 2 and the same message, and neither writes anything. With RANKS=N both run on N ranks.
expect_both() {
  local name=$1 yaml=$2
  shift 2
  printf '%s\n' "$yaml" > "$work/$name.yaml"
  local launch=("$CFDMPM")
  [ "${RANKS:-1}" = 1 ] || launch=("$MPIEXEC" -n "$RANKS" "$CFDMPM")
  "${launch[@]}" --check "$work/$name.yaml" > "$work/$name.check.out" 2> "$work/$name.check.err"
  local check_code=$?
  "${launch[@]}" "$work/$name.yaml" > "$work/$name.run.out" 2> "$work/$name.run.err"
  local run_code=$?
  if [ "$check_code" != 2 ] || [ "$run_code" != 2 ]; then
    echo "FAIL $name: exit codes --check $check_code, run $run_code; expected 2 and 2"
    cat "$work/$name.check.err" "$work/$name.run.err"; failures=$((failures + 1)); return
  fi
  local check_line run_line
  check_line=$(grep -m1 '^cfdmpm: error:' "$work/$name.check.err")
  run_line=$(grep -m1 '^cfdmpm: error:' "$work/$name.run.err")
  if [ -z "$check_line" ] || [ "$check_line" != "$run_line" ]; then
    echo "FAIL $name: --check and the run say different things:"; echo "  $check_line"; echo "  $run_line"
    failures=$((failures + 1)); return
  fi
  for needle in "$@"; do
    if ! grep -qF -- "$needle" <<< "$check_line"; then
      echo "FAIL $name: message lacks '$needle': $check_line"; failures=$((failures + 1)); return
    fi
  done
  if [ -n "${KEEP_OUT:-}" ]; then
    [ "$(ls -A "$work/out")" = "$KEEP_OUT" ] || { echo "FAIL $name: the output directory changed"; failures=$((failures + 1)); }
  elif [ -e "$work/out" ]; then
    echo "FAIL $name: output directory was created"; failures=$((failures + 1)); rm -rf "$work/out"; return
  fi
  echo "ok   $name (--check and run): $(head -c 300 <<< "$check_line")"
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
expect negative_checkpoint_interval "$(good | sed 's/interval: 0.01}/interval: 0.01, checkpoint_interval: -0.5}/')" \
  "cfdmpm.output.checkpoint_interval" "-0.5" ">= 0 (s)"
expect negative_checkpoint_wall_interval "$(good | sed 's/interval: 0.01}/interval: 0.01, checkpoint_wall_interval: -60}/')" \
  "cfdmpm.output.checkpoint_wall_interval" "-60" ">= 0 (s)"
expect no_checkpoints_kept "$(good | sed 's/interval: 0.01}/interval: 0.01, checkpoints_kept: 0}/')" \
  "cfdmpm.output.checkpoints_kept" "'0'" ">= 1"
expect negative_rebalance_interval "$(good | sed 's/gravity: \[0.0, -9.81\]}/gravity: [0.0, -9.81], rebalance_interval: -5}/')" \
  "cfdmpm.domain.rebalance_interval" "-5" ">= 0"
expect fractional_rebalance_interval "$(good | sed 's/gravity: \[0.0, -9.81\]}/gravity: [0.0, -9.81], rebalance_interval: 2.5}/')" \
  "cfdmpm.domain.rebalance_interval" "2.5" "integer"
expect missing_key "$(good | grep -v '  time:')" "time"
# Values as written, not as read (40.0 used to be echoed as 40, 1e-400 as 0); a repeated key named
# with its own line (it used to be 'already exists in list "ANONYMOUS"' at the next line).
expect echoed_as_written "$(CFL=40.0 good)" "cfdmpm.time.cfl: got '40.0'; must be in (0, 1]"
expect below_double_range "$(good | sed 's/end_time: 0.1,/end_time: 1e-400,/')" \
  "cfdmpm.time.end_time: got '1e-400' (read as 0: beyond the range of a double); must be > 0"
expect repeated_key "$(good | sed 's/^  time: {end_time: 0.1, cfl: \(.*\)}$/  time: {end_time: 0.1, cfl: \1}\n  time: {end_time: 0.2}/')" \
  ":17:3: key 'time' of cfdmpm given twice (first on line 16)"
expect two_top_level_keys "$(good; echo 'extra: {a: 1}')" "extra"
# Refused at set-up: by --check as by the run, with the same message.
dry() {  # the granular column: sand alone, the fluid solver off
  sed "s#output/granular-column#$work/out#; s/end_time: 0.4/end_time: 0.001/" "$SOURCE_DIR/input/granular-column.yaml"
}
expect_both thin_solid_region "$(dry | sed 's/upper: \[0.1, 0.1\]}/upper: [0.0001, 0.1]}/')" \
  "cfdmpm.regions.column" "no particle" "sand" "the box from [0, 0]" "1.25 mm apart"
expect_both linear_solver_key "$(good; echo '  ice: {linear_solver: {nonsense: 1}}')" \
  "cfdmpm.ice.linear_solver.nonsense" "unknown key" "reuse mode"
expect_both sound_speed_field "$(good | sed 's/interval: 0.01}/interval: 0.01, fields: [pressure, sound_speed]}/')" \
  "cfdmpm.output.fields" "sound_speed" "specific_volume"
expect_both hydrostatic_off_axis "$(good | sed 's/gravity: \[0.0, -9.81\]/gravity: [1.0, -9.81]/')" \
  "cfdmpm.initial_state.hydrostatic" "[1, -9.81]"
expect_both bulk_modulus_1e308 "$(good | sed 's/bulk_modulus: 2.15e9/bulk_modulus: 1.0e308/')" \
  "equation_of_state.bulk_modulus" "1e+308" "compressibility"
expect_both pressure_1e308 "$(good | sed 's/pressure: 101325.0}/pressure: 1.0e308}/')" \
  "cfdmpm.initial_state.pressure" "1e+308" "compressibility"
expect_both gravity_1e308 "$(good | sed 's/gravity: \[0.0, -9.81\]/gravity: [0.0, -1.0e308]/')" \
  "cfdmpm.domain.gravity" "[0, -1e+308]" "dt_min"
expect_both collinear_polygon "$(good | sed 's#shape: box, lower: \[0.0, 0.0\], upper: \[[^]]*\]#shape: polygon, vertices: [[0.1, 0.1], [0.2, 0.2], [0.3, 0.3]]#')" \
  "cfdmpm.regions.column.vertices" "enclose no area"
expect_both figure_eight "$(good | sed 's#shape: box, lower: \[0.0, 0.0\], upper: \[[^]]*\]#shape: polygon, vertices: [[0.1, 0.1], [0.4, 0.4], [0.4, 0.1], [0.1, 0.4]]#')" \
  "cfdmpm.regions.column.vertices" "vertex 1 to 2" "vertex 3 to 4"
expect_both half_plane_outside "$(good | sed 's#shape: box, lower: \[0.0, 0.0\], upper: \[[^]]*\]#shape: half_plane, point: [0.0, -1.0], normal: [0.0, 1.0]#')" \
  "cfdmpm.regions.column" "places no water" "half-plane"
expect_both patch_count_overflow "$(good | sed 's/cells: \[20, 10\]/cells: [1000000, 1000000]/')" \
  "cfdmpm.domain.cells" "[1000000, 1000000]" "patches" "domain.patch_cells"
# 10^10 cells of 2 materials: ~12 TB, more than any machine these tests run on.
expect_both memory "$(good | sed 's/cells: \[20, 10\], patch_cells: \[5, 5\]/cells: [100000, 100000], patch_cells: [1000, 1000]/')" \
  "cfdmpm.domain.cells" "memory" "TB" "1e+10 cells"
RANKS=2 expect_both one_patch_two_ranks "$(good | sed 's/patch_cells: \[5, 5\]/patch_cells: [20, 10]/')" \
  "domain.patch_cells" "1 patches for 2 ranks"
mkdir -p "$work/out" && touch "$work/out/earlier-run.csv"
KEEP_OUT=earlier-run.csv expect_both output_directory_not_empty "$(good)" "output.directory" "not empty" "overwrite"
rm -rf "$work/out"
# A directory that permission bits allow but that cannot be made (/proc takes no new entries, even
# for root): --check must refuse it as the run does, not pass a scene the run then refuses.
if [ -d /proc/self ]; then
  expect_both output_directory_uncreatable "$(good | sed 's#directory: [^,]*,#directory: /proc/cfdmpm_out,#')" \
    "cfdmpm.output.directory" "/proc/cfdmpm_out" "cannot be created"
fi

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
