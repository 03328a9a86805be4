#!/usr/bin/env bash
# Checkpoint and restart (doc/output.md, "Checkpoints"). Three runs of one small scene
# (test/app/restart/<scene>.yaml, which writes a checkpoint every few output intervals):
#   A  to 2T without stopping, on R ranks;
#   B  to T on R ranks: it ends with a checkpoint at T;
#   C  `cfdmpm --restart B` with A's scene (end 2T) on R' ranks: continues B in B's directory.
# With R' = R, B's directory must then hold the same files as A's, byte for byte (cmp): every step
# file, every XDMF file, the CSV (no row missing or repeated) and the checkpoints;
# utilities/compare_runs.py --tolerance 0 must agree. With R' != R the restart continues on another
# decomposition: the fields must agree with A's to BOUND (largest |a - b| / max |a| per field; the
# sums of the pressure solve and the particle-to-grid transfer run in another order, so the runs
# differ by round-off, which the pressure solver's tolerance and the flow then carry on), and the
# CSV rows up to the checkpoint must be A's exactly.
#   usage: restart.sh <scene> <T> <R> <R'> [BOUND]
set -u
scene=$1 half=$2 ranks=$3 restart_ranks=$4 bound=${5:-0}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL $*"; failures=$((failures + 1)); }
end=$("$PYTHON" -c "print(repr(2 * $half))")
# The same file name in both directories: the run's name (its files' prefix) is the scene's.
for run in A B; do
  mkdir -p "$work/scene$run"
  [ "$run" = A ] && t=$end || t=$half
  sed -e "s|OUTPUT|$work/$run|" -e "s|END|$t|" "$SOURCE_DIR/test/app/restart/$scene.yaml" > "$work/scene$run/scene.yaml"
done
run() {  # <ranks> <log> <arguments...>
  local n=$1 log=$2
  shift 2
  "$MPIEXEC" -n "$n" "$CFDMPM" "$@" > "$work/$log" 2>&1 || { echo "FAIL cfdmpm $* exited $?"; cat "$work/$log"; exit 1; }
}
run "$ranks" A.log "$work/sceneA/scene.yaml"
run "$ranks" B.log "$work/sceneB/scene.yaml"
checkpoint=$(ls "$work/B/checkpoints" | tail -n 1)
run "$restart_ranks" C.log --restart "$work/B" "$work/sceneA/scene.yaml"
grep -q "restarted from $work/B/checkpoints/$checkpoint" "$work/C.log" || fail "the restart did not start from B's last checkpoint $checkpoint"
step=$(echo "$checkpoint" | sed 's/scene_0*\([0-9][0-9]*\)\.h5/\1/')
last=$(tail -n 1 "$work/A/scene.csv" | cut -d, -f1)
echo "$scene: A ran $last steps; B stopped at step $step (checkpoint $checkpoint); restart on $restart_ranks rank(s)"
[ "$step" -gt 0 ] && [ "$step" -lt "$last" ] || fail "the checkpoint's step $step is not inside the run (0, $last)"

# The same files, and no temporary one.
(cd "$work/A" && find . -type f | sort) > "$work/files.A"
(cd "$work/B" && find . -type f | sort) > "$work/files.B"
cmp -s "$work/files.A" "$work/files.B" || { fail "the output directories hold different files:"; diff "$work/files.A" "$work/files.B"; }
if [ "$restart_ranks" = "$ranks" ]; then
  # Byte for byte, except checkpoints B wrote before it stopped: they keep B's own scene (another
  # end time and directory), so their attributes scene and scene_path differ; the rest must not.
  different=0
  while read -r f; do
    case "$f" in
      ./checkpoints/*)
        [ "$(echo "$f" | sed 's/.*_0*\([0-9][0-9]*\)\.h5/\1/')" -le "$step" ] && continue ;;
    esac
    cmp -s "$work/A/$f" "$work/B/$f" || { echo "  differs: $f"; different=$((different + 1)); }
  done < "$work/files.A"
  echo "$(wc -l < "$work/files.A") files compared byte for byte (B's own checkpoints by content), $different differ"
  for f in $(cd "$work/A" && ls checkpoints); do
    "$PYTHON" "$SOURCE_DIR/test/app/same_checkpoint.py" "$work/A/checkpoints/$f" "$work/B/checkpoints/$f" ||
      fail "checkpoint $f differs in content"
  done
  [ "$different" = 0 ] || fail "$different files differ between the run that never stopped and the restarted one"
  "$PYTHON" "$SOURCE_DIR/utilities/compare_runs.py" "$work/A" "$work/B" --tolerance 0 || fail "compare_runs.py --tolerance 0"
else
  "$PYTHON" "$SOURCE_DIR/utilities/compare_runs.py" "$work/A" "$work/B" --tolerance "$bound" || fail "compare_runs.py --tolerance $bound"
  # Rows 0 to the checkpoint's step were written by B itself; the rest by the restart.
  head -n $((step + 2)) "$work/A/scene.csv" > "$work/rows.A"
  head -n $((step + 2)) "$work/B/scene.csv" > "$work/rows.B"
  cmp -s "$work/rows.A" "$work/rows.B" || fail "the CSV rows up to the checkpoint differ"
  [ "$(wc -l < "$work/A/scene.csv")" = "$(wc -l < "$work/B/scene.csv")" ] || fail "the CSVs have different numbers of rows"
  cut -d, -f1 "$work/B/scene.csv" | tail -n +2 | "$PYTHON" -c "
import sys
steps = [int(s) for s in sys.stdin]
sys.exit(0 if steps == list(range(len(steps))) else 1)" || fail "the CSV's steps are not 0, 1, 2, ... once each"
fi
[ "$failures" = 0 ] && echo "PASS" || exit 1
