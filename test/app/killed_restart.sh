#!/usr/bin/env bash
# A 2-rank run killed with SIGKILL after its first checkpoint and restarted from its output
# directory (`cfdmpm --restart <directory>`, the scene the checkpoint keeps) must end with the same
# output directory as a run that was never interrupted, byte for byte (cmp): the step files written
# after the checkpoint are rewritten, the CSV has each step once, no temporary file is left.
# Scene: test/app/restart/dam-break.yaml to 0.15 s (a checkpoint every 0.02 s).
set -u
work=$(mktemp -d)
pid=
trap '[ -n "$pid" ] && kill -9 $(pgrep -P "$pid") "$pid" 2>/dev/null; rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL $*"; failures=$((failures + 1)); }
# Both runs in their own folder with the same scene text and relative paths, so that even the
# checkpoints (which keep the scene) must be the same bytes.
for run in A K; do
  mkdir -p "$work/$run"
  sed -e "s|OUTPUT|out|" -e "s|END|0.15|" "$SOURCE_DIR/test/app/restart/dam-break.yaml" > "$work/$run/scene.yaml"
done
(cd "$work/A" && "$MPIEXEC" -n 2 "$CFDMPM" scene.yaml > ../A.log 2>&1) || { echo "FAIL the uninterrupted run"; cat "$work/A.log"; exit 1; }

# The run to kill: as soon as its first checkpoint has its final name, SIGKILL both ranks (the
# processes mpiexec started), as a crash or an out-of-memory killer would.
cd "$work/K"
"$MPIEXEC" -n 2 "$CFDMPM" scene.yaml > ../K.log 2>&1 &
pid=$!
for _ in $(seq 1 6000); do
  ls out/checkpoints 2>/dev/null | grep -q '\.h5$' && break
  kill -0 "$pid" 2>/dev/null || break
  sleep 0.02
done
ranks=$(pgrep -P "$pid")
[ -n "$ranks" ] && kill -9 $ranks
wait "$pid"
code=$?
pid=
killed_at=$(tail -n 1 out/scene.csv | cut -d, -f1)
last=$(tail -n 1 "$work/A/out/scene.csv" | cut -d, -f1)
echo "killed with exit code $code at step $killed_at of $last; checkpoints: $(ls out/checkpoints | tr '\n' ' ')"
[ "$code" != 0 ] && [ "$killed_at" -lt "$last" ] || { echo "FAIL the run was not killed before its end"; exit 1; }

"$MPIEXEC" -n 2 "$CFDMPM" --restart out > "$work/R.log" 2>&1 || { echo "FAIL the restart"; cat "$work/R.log"; exit 1; }
grep "restarted from" "$work/R.log"
(cd "$work/A/out" && find . -type f | sort) > "$work/files.A"
(cd "$work/K/out" && find . -type f | sort) > "$work/files.K"
cmp -s "$work/files.A" "$work/files.K" || { fail "the output directories hold different files:"; diff "$work/files.A" "$work/files.K"; }
different=0
while read -r f; do
  cmp -s "$work/A/out/$f" "$work/K/out/$f" || { echo "  differs: $f"; different=$((different + 1)); }
done < "$work/files.A"
echo "$(wc -l < "$work/files.A") files compared byte for byte, $different differ"
[ "$different" = 0 ] || fail "$different files differ from the uninterrupted run's"
"$PYTHON" "$SOURCE_DIR/utilities/compare_runs.py" "$work/A/out" "$work/K/out" --tolerance 0 --last > /dev/null || fail "compare_runs.py --tolerance 0"
[ "$failures" = 0 ] && echo "PASS" || exit 1
