#!/usr/bin/env bash
# The decomposition redone with particle weights (domain.rebalance_interval, doc/scaling.md): sand
# gathered in a corner of a water tank (test/app/restart/sand-corner.yaml) on R ranks, run A with
# rebalance_interval 0, run B with the scene's 5, both with pressure solves to a relative residual
# of 1e-14. check_rebalance.py checks B's CSV: the imbalance
# before and after on the rows of steps 1, 6, 11, ... (the rebalance is made before the step),
# empty elsewhere; on more than one rank the first rebalance moves patches and lowers the
# imbalance, on one rank nothing moves. Then A and B must give the same answer to BOUND
# (utilities/compare_runs.py; the reason for the bound is given where the test is registered).
#   usage: rebalance.sh <R> <BOUND> <end time>
set -u
ranks=$1 bound=$2 end=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for run in A B; do
  mkdir -p "$work/scene$run"
  interval=5
  [ "$run" = A ] && interval=0
  sed -e "s|OUTPUT|$work/$run|" -e "s|END|$end|" -e "/checkpoint_interval:/d" \
      -e "s|rebalance_interval: 5 |rebalance_interval: $interval |" \
      "$SOURCE_DIR/test/app/restart/sand-corner.yaml" > "$work/scene$run/scene.yaml"
  grep -q "rebalance_interval: $interval " "$work/scene$run/scene.yaml" || { echo "FAIL no rebalance_interval"; exit 1; }
  # Pressure solves to round-off, so that what remains of a difference is the division's own.
  echo "  ice: {solver_tolerance: 1.0e-14}" >> "$work/scene$run/scene.yaml"
  "$MPIEXEC" -n "$ranks" "$CFDMPM" "$work/scene$run/scene.yaml" > "$work/$run.log" 2>&1 ||
    { echo "FAIL cfdmpm (run $run) exited $?"; cat "$work/$run.log"; exit 1; }
done
grep "patches divided again" "$work/B.log"
"$PYTHON" "$SOURCE_DIR/test/app/check_rebalance.py" "$work/A/scene.csv" "$work/B/scene.csv" "$ranks" 5 ||
  { echo "FAIL the CSV of the rebalanced run"; exit 1; }
if [ "$ranks" -gt 1 ]; then
  grep -q "patches divided again" "$work/B.log" || { echo "FAIL B's log does not report a rebalance"; exit 1; }
else
  grep -q "patches divided again" "$work/B.log" && { echo "FAIL a rebalance on one rank"; exit 1; }
fi
"$PYTHON" "$SOURCE_DIR/utilities/compare_runs.py" "$work/A" "$work/B" --tolerance "$bound" ||
  { echo "FAIL with and without rebalancing the runs differ by more than $bound"; exit 1; }
echo "PASS"
