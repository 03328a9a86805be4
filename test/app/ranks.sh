#!/usr/bin/env bash
# The same scene on 1 rank and on R ranks (4 and 8 here, more ranks than cores: Open MPI
# oversubscribes, utilities/mpi-env.sh) must give the same answer to BOUND: every output field at
# every output step, largest |a - b| / max |a| per field (utilities/compare_runs.py; particles
# matched by id). The scenes are those of the restart tests (test/app/restart/) with patches of
# PATCH cells, so that every rank has a few, and without checkpoints. The reasons for the bounds
# are given where the tests are registered (test/app/CMakeLists.txt). With SOLVER_TOLERANCE, the
# scene's pressure solves stop at that relative residual (ice.solver_tolerance; the scene must have
# no ice section or an empty one).
#   usage: ranks.sh <scene> <end time> <R> <BOUND> <PATCH> [SOLVER_TOLERANCE]
set -u
scene=$1 end=$2 ranks=$3 bound=$4 patch=$5 tolerance=${6:-}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for n in 1 "$ranks"; do
  mkdir -p "$work/np$n"
  sed -e "s|OUTPUT|$work/out$n|" -e "s|END|$end|" -e "s|patch_cells: \[[0-9, ]*\]|patch_cells: [$patch, $patch]|" \
      -e "/checkpoint_interval:/d" "$SOURCE_DIR/test/app/restart/$scene.yaml" > "$work/np$n/scene.yaml"
  grep -q "patch_cells: \[$patch, $patch\]" "$work/np$n/scene.yaml" || { echo "FAIL no patch_cells in $scene.yaml"; exit 1; }
  if [ -n "$tolerance" ]; then
    sed -i "/^  ice: {}/d" "$work/np$n/scene.yaml"
    grep -q "^  ice:" "$work/np$n/scene.yaml" && { echo "FAIL $scene.yaml has an ice section"; exit 1; }
    echo "  ice: {solver_tolerance: $tolerance}" >> "$work/np$n/scene.yaml"
  fi
  start=$(date +%s%N)
  "$MPIEXEC" -n "$n" "$CFDMPM" "$work/np$n/scene.yaml" > "$work/np$n.log" 2>&1 ||
    { echo "FAIL cfdmpm on $n rank(s) exited $?"; cat "$work/np$n.log"; exit 1; }
  echo "$scene on $n rank(s): $(tail -n 1 "$work/out$n/scene.csv" | cut -d, -f1) steps," \
       "$(( ($(date +%s%N) - start) / 1000000 )) ms wall; $(grep -o '[0-9]* patches on [0-9]* rank(s)' "$work/np$n.log")"
done
"$PYTHON" "$SOURCE_DIR/utilities/compare_runs.py" "$work/out1" "$work/out$ranks" --tolerance "$bound" ||
  { echo "FAIL $scene: 1 and $ranks ranks differ by more than $bound"; exit 1; }
echo "PASS"
