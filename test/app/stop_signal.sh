#!/usr/bin/env bash
# A run stopped by SIGINT or SIGTERM before its end time exits with code 3 on every rank, says so,
# and leaves complete files: the CSV's last row is the step of the last step file. With 2 ranks the
# signal goes to one rank only, as a batch system's may.
#   usage: stop_signal.sh <ranks> <INT|TERM>
set -u
ranks=${1:-1}
signal=${2:-INT}
work=$(mktemp -d)
trap 'kill -9 "$pid" 2>/dev/null; rm -rf "$work"' EXIT
# The still-water tank for 1 s of simulated time: minutes of work, stopped after its first steps.
sed "s#output/still-water#$work/out#; s/progress_interval: [0-9.e+-]*//" "$SOURCE_DIR/input/still-water.yaml" > "$work/scene.yaml"
grep -q "$work/out" "$work/scene.yaml" || { echo "FAIL the scene's output directory was not redirected"; exit 1; }
if [ "$ranks" = 1 ]; then
  "$CFDMPM" "$work/scene.yaml" > "$work/out.txt" 2> "$work/err.txt" &
else
  "$MPIEXEC" -n "$ranks" "$CFDMPM" "$work/scene.yaml" > "$work/out.txt" 2> "$work/err.txt" &
fi
pid=$!
# Wait until the time loop runs (the CSV has a row after the header and step 0), at most 120 s.
rows() { { wc -l < "$work/out/scene.csv"; } 2>/dev/null || echo 0; }
for _ in $(seq 1 1200); do
  [ "$(rows)" -ge 3 ] && break
  sleep 0.1
done
[ "$(rows)" -ge 3 ] || { echo "FAIL the run did not start stepping"; cat "$work/err.txt"; exit 1; }
if [ "$ranks" = 1 ]; then
  target=$pid
else
  target=$(pgrep -n -f "$CFDMPM $work/scene.yaml" | head -1)  # the newest rank process: one rank only
fi
kill -s "$signal" "$target"
wait "$pid"
code=$?
failures=0
[ "$code" = 3 ] || { echo "FAIL exit code $code, expected 3"; failures=$((failures + 1)); }
grep -q "stopped by a signal at t = " "$work/out.txt" || { echo "FAIL no 'stopped by a signal' line"; cat "$work/out.txt"; failures=$((failures + 1)); }
# Complete files: no temporary file left, and the last step file is the CSV's last step.
ls "$work/out" | grep -q '\.tmp$' && { echo "FAIL a temporary file was left"; failures=$((failures + 1)); }
last_csv=$(tail -n 1 "$work/out/scene.csv" | cut -d, -f1)
last_h5=$(ls "$work/out" | grep -E '^scene_[0-9]+\.h5$' | sort | tail -n 1 | sed 's/scene_0*\([0-9]*\)\.h5/\1/')
[ "${last_h5:-0}" = "$last_csv" ] || [ "$last_h5" = "" -a "$last_csv" = 0 ] || { echo "FAIL last step file $last_h5, last CSV step $last_csv"; failures=$((failures + 1)); }
echo "exit code $code after SIG$signal on $ranks rank(s); last step $last_csv"
[ "$failures" = 0 ]
