#!/usr/bin/env bash
# Runs the default dam-break scene on N ranks into a temporary directory, stopped before its first
# step (time.max_steps: 0), and checks its initial state with check_initial_state.py. A second run
# without --overwrite must be refused.
set -eu
ranks=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed -e "s|directory: .*|directory: $work/out|" -e "s|    end_time: 0.25|    end_time: 0.25\n    max_steps: 0|" \
    "$SOURCE_DIR/input/dam-break.yaml" > "$work/dam-break.yaml"
grep -q "max_steps: 0" "$work/dam-break.yaml"
grep -q "directory: $work/out" "$work/dam-break.yaml"
"$MPIEXEC" -n "$ranks" "$CFDMPM" "$work/dam-break.yaml"
"$PYTHON" "$SOURCE_DIR/test/app/check_initial_state.py" "$work/out" "$work/dam-break.yaml"
# The directory now holds a run: a second run must refuse it (exit 2) and leave it untouched.
before=$(ls -l --time-style=+%s.%N "$work/out" | md5sum)
set +e
"$MPIEXEC" -n "$ranks" "$CFDMPM" "$work/dam-break.yaml" 2> "$work/second.err"
code=$?
set -e
[ "$code" = 2 ] || { echo "second run: exit code $code, expected 2"; exit 1; }
grep -q "output.directory" "$work/second.err" || { echo "second run: message lacks output.directory"; cat "$work/second.err"; exit 1; }
[ "$before" = "$(ls -l --time-style=+%s.%N "$work/out" | md5sum)" ] || { echo "second run changed the directory"; exit 1; }
"$MPIEXEC" -n "$ranks" "$CFDMPM" --overwrite "$work/dam-break.yaml" > /dev/null
echo "initial state on $ranks rank(s): ok"
