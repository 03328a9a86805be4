#!/usr/bin/env bash
# A failed step is undone and retried with half its time step (doc/input.md, "A failed step").
#
#   retry.sh fail <ranks>
#     test/app/retry/moving-block.yaml: water moving diagonally at Courant number 1, where a step at
#     the convective limit carries 1.5 cells' volume out of a cell and the advection refuses it.
#     1. time.step_retries 3: the run ends (exit 0); the CSV column `retries` counts the retried
#        steps, and the terminal names each undone step and what failed.
#     2. time.step_retries 0: the run stops at the first such step with exit 1, naming the step,
#        the cell, the material and the quantity; the last good state is written as a step file and
#        a checkpoint, and the CSV ends with its row.
#     3. `cfdmpm --restart` from that checkpoint with retries allowed runs to the end.
#
#   retry.sh undo <scene> <T> <ranks> <step>
#     A scene of test/app/restart/ run to T twice: as it is, and with CFDMPM_TEST_UNDO_STEP=<step>,
#     which undoes that step after it succeeded and runs it again with the same time step. Undoing
#     restores everything the step changed (cells, particles, solver state), so the two runs write
#     the same step files byte for byte, and the same CSV except in the columns retries and
#     dt_limiter of that step.
set -u
mode=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL $*"; failures=$((failures + 1)); }

if [ "$mode" = fail ]; then
  ranks=$2
  scene() {  # <directory> <dt_initial> <step_retries>
    sed -e "s|OUTPUT|$work/$1|" -e "s|DT_INITIAL|$2|" -e "s|RETRIES|$3|" \
      "$SOURCE_DIR/test/app/retry/moving-block.yaml" > "$work/$1.yaml"
  }
  # 1. Retried and finished. dt_initial 0.02 s is below the convective limit (0.025 s) but moves
  #    1.2 cells' volume: the first step already needs a retry.
  scene retried 0.02 3
  "$MPIEXEC" -n "$ranks" "$CFDMPM" "$work/retried.yaml" > "$work/retried.log" 2>&1
  code=$?
  [ "$code" = 0 ] || { fail "retried run: exit $code, expected 0"; cat "$work/retried.log"; }
  grep -q "step 1 undone: ice: advection: the outflux of water from cell (" "$work/retried.log" ||
    fail "retried run: the terminal does not name the undone first step and its cause"
  grep -q "retry 1 of 3 with dt = 0.01 s" "$work/retried.log" || fail "retried run: no 'retry 1 of 3 with dt = 0.01 s'"
  "$PYTHON" - "$work/retried/retried.csv" "$work/retried.log" <<'PY' || fail "retried run: the CSV's retries column or the log's count"
import csv, re, sys
rows = list(csv.DictReader(open(sys.argv[1])))
# The run's last lines count the retried steps and the undone attempts, as the CSV does.
summary = re.search(r"retried steps: (\d+) \((\d+) attempts undone\) in this run to step (\d+)", open(sys.argv[2]).read())
counts = (sum(int(r["retries"]) > 0 for r in rows), sum(int(r["retries"]) for r in rows), int(rows[-1]["step"]))
print(f"log's summary {summary.groups() if summary else None}, CSV's counts {counts}")
if not summary or tuple(int(g) for g in summary.groups()) != counts:
    sys.exit(1)
retried = [r for r in rows if int(r["retries"]) > 0]
print(f"retried run: {len(rows) - 1} steps, {len(retried)} retried "
      f"(steps {', '.join(r['step'] for r in retried)}), end t = {rows[-1]['time']} s")
ok = rows[1]["retries"] == "1" and abs(float(rows[1]["dt"]) - 0.01) < 1e-15 and "+retry" in rows[1]["dt_limiter"]
ok = ok and len(retried) >= 2 and abs(float(rows[-1]["time"]) - 0.1) < 1e-12
# After a retried step the next one grows by ice.dt_growth (1.2) from the Δt that worked.
nxt = rows[2]
ok = ok and abs(float(nxt["dt"]) - 1.2 * float(rows[1]["dt"])) < 1e-15 and nxt["retries"] == "0"
ok = ok and all(r["max_outflux_fraction"] == "" or float(r["max_outflux_fraction"]) <= 1 for r in rows[1:])
sys.exit(0 if ok else 1)
PY

  # 2. No retries allowed: dt_initial 0.01 s passes, the growth limit raises dt by 1.2 per step and
  #    the third step (0.0144 s) carries 1.36 cells' volume of water out of cell (10, 2).
  scene stops 0.01 0
  "$MPIEXEC" -n "$ranks" "$CFDMPM" "$work/stops.yaml" > "$work/stops.log" 2> "$work/stops.err"
  code=$?
  [ "$code" = 1 ] || { fail "run without retries: exit $code, expected 1"; cat "$work/stops.log" "$work/stops.err"; }
  echo "run without retries: exit $code: $(cat "$work/stops.err")"
  [ "$(grep -c 'cfdmpm: error:' "$work/stops.err")" = 1 ] || fail "not one error line (one per run, not per rank)"
  for needle in "step 3 from t = 0.022 s failed: ice: advection: the outflux of water from cell (10, 2) is 1.3" \
      "of its volume in one step (at most 1)" "time.step_retries is 0" \
      "The last good state, step 2 at t = 0.022 s, is in $work/stops/stops_000002.h5 and its checkpoint in" \
      "cfdmpm --restart $work/stops"; do
    grep -qF -- "$needle" "$work/stops.err" || fail "the message lacks '$needle'"
  done
  [ -f "$work/stops/stops_000002.h5" ] || fail "no step file of the last good state"
  [ -f "$work/stops/checkpoints/stops_000002.h5" ] || fail "no checkpoint of the last good state"
  [ "$(tail -n 1 "$work/stops/stops.csv" | cut -d, -f1)" = 2 ] || fail "the CSV does not end with step 2"
  head -n 1 "$work/stops/stops.csv" | grep -q '^step,time,dt,dt_limiter,retries,' || fail "no retries column"
  grep -q 'stops_000002.h5' "$work/stops/stops.xmf" || fail "the XDMF series lacks the last good state"

  # 3. Restarted from the last good state with retries allowed: runs to the end.
  scene stops 0.01 3
  "$MPIEXEC" -n "$ranks" "$CFDMPM" --restart "$work/stops" "$work/stops.yaml" > "$work/restart.log" 2>&1
  code=$?
  [ "$code" = 0 ] || { fail "restart with retries: exit $code"; cat "$work/restart.log"; }
  grep -q "step 3 undone" "$work/restart.log" || fail "the restart did not retry step 3"

  # 4. A stable time step below time.dt_min stops the run before the step (run on at dt_min, it
  #    would take unstable steps, or hold the run at dt_min without end): time.dt_min 0.03 s above
  #    the block's convective limit, 0.05 m / 2 m/s = 0.025 s, named with the block's first cell.
  sed -e "s|OUTPUT|$work/floor|" -e "s|DT_INITIAL|0.03|" -e "s|RETRIES|3|" -e "s|dt_max: 0.1|dt_max: 0.1\n    dt_min: 0.03|" \
    "$SOURCE_DIR/test/app/retry/moving-block.yaml" > "$work/floor.yaml"
  "$MPIEXEC" -n "$ranks" "$CFDMPM" "$work/floor.yaml" > "$work/floor.log" 2> "$work/floor.err"
  code=$?
  [ "$code" = 1 ] || { fail "run below dt_min: exit $code, expected 1"; cat "$work/floor.log" "$work/floor.err"; }
  echo "run below dt_min: exit $code: $(cat "$work/floor.err")"
  for needle in "step 1 from t = 0 s failed: its stable time step is 0.025 s (convection(water), cell (4, 3), where water" \
      "moves at (2, 1) m/s), below time.dt_min (0.03 s). The last good state, step 0"; do
    grep -qF -- "$needle" "$work/floor.err" || fail "the message lacks '$needle'"
  done
elif [ "$mode" = undo ]; then
  scene=$2 end=$3 ranks=$4 undo=$5
  for run in A U; do
    mkdir -p "$work/scene$run"
    sed -e "s|OUTPUT|$work/$run|" -e "s|END|$end|" "$SOURCE_DIR/test/app/restart/$scene.yaml" > "$work/scene$run/scene.yaml"
  done
  "$MPIEXEC" -n "$ranks" "$CFDMPM" "$work/sceneA/scene.yaml" > "$work/A.log" 2>&1 || { fail "run A exited $?"; cat "$work/A.log"; }
  CFDMPM_TEST_UNDO_STEP=$undo "$MPIEXEC" -x CFDMPM_TEST_UNDO_STEP -n "$ranks" "$CFDMPM" "$work/sceneU/scene.yaml" \
    > "$work/U.log" 2>&1 || { fail "run U exited $?"; cat "$work/U.log"; }
  grep -q "step $undo undone: undone by CFDMPM_TEST_UNDO_STEP" "$work/U.log" || fail "run U did not undo step $undo"
  different=0 files=0
  for f in $(cd "$work/A" && find . -maxdepth 1 -type f -name '*.h5' | sort); do
    files=$((files + 1))
    cmp -s "$work/A/$f" "$work/U/$f" || { echo "  differs: $f"; different=$((different + 1)); }
  done
  echo "$scene on $ranks rank(s), step $undo undone: $files step files compared byte for byte, $different differ"
  [ "$files" -gt 1 ] && [ "$different" = 0 ] || fail "the step files differ"
  # Checkpoints by content: their attributes scene and scene_path name each run's own directory.
  for f in $(cd "$work/A" && ls checkpoints); do
    "$PYTHON" "$SOURCE_DIR/test/app/same_checkpoint.py" "$work/A/checkpoints/$f" "$work/U/checkpoints/$f" ||
      fail "checkpoint $f differs in content"
  done
  "$PYTHON" - "$work/A/scene.csv" "$work/U/scene.csv" "$undo" <<'PY' || fail "the CSVs differ"
import csv, sys
a, u = (list(csv.DictReader(open(p))) for p in sys.argv[1:3])
undo = sys.argv[3]
ok = len(a) == len(u) and int(a[-1]["step"]) > int(undo)
for ra, ru in zip(a, u):
    if ra["step"] == undo:
        ok = ok and ru["retries"] == "1" and ru["dt_limiter"] == ra["dt_limiter"] + "+retry"
    ra.pop("dt_limiter"), ru.pop("dt_limiter"), ra.pop("retries"), ru.pop("retries")
    ok = ok and ra == ru
print(f"CSV: {len(a)} rows, the same but for step {undo}'s retries and dt_limiter" if ok else "CSV rows differ")
sys.exit(0 if ok else 1)
PY
else
  echo "usage: retry.sh fail <ranks> | undo <scene> <T> <ranks> <step>"; exit 2
fi
[ "$failures" = 0 ] && echo "PASS" || exit 1
