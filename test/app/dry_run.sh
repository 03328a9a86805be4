#!/usr/bin/env bash
# A dry scene (ice.enabled: false) runs the particle solver alone through the program: the granular
# column collapses for 0.05 s on N ranks; check_dry_run.py checks the CSV and the particle output.
set -eu
ranks=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed -e "s|directory: .*|directory: $work/out|" -e "s|    end_time: 0.4|    end_time: 0.05|" -e "s|    interval: 0.05|    interval: 0.025|" \
    "$SOURCE_DIR/input/granular-column.yaml" > "$work/column.yaml"
grep -q "end_time: 0.05" "$work/column.yaml"
"$MPIEXEC" -n "$ranks" "$CFDMPM" "$work/column.yaml" > "$work/log"
"$PYTHON" "$SOURCE_DIR/test/app/check_dry_run.py" "$work/out"
