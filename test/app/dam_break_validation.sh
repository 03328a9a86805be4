#!/usr/bin/env bash
# Dam break against Martin & Moyce (1952) at two resolutions (5 mm and 2.5 mm cells): prints the
# surge-front and column-height errors of both and fails unless the finer one is within the
# acceptance bound (10 % RMS for Z(T), T in [1, 3.33], and for H(tau), tau in [0.5, 3.5]; no time
# shift). Label "validation": not part of the default test run (minutes of CPU).
set -eu
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
status=0
for cells in "100, 40" "200, 80"; do
  name=$(echo "$cells" | sed "s/, */x/")
  sed -e "s|directory: .*|directory: $work/$name|" -e "s|cells: \[200, 80\]|cells: [$cells]|" \
      "$SOURCE_DIR/input/dam-break.yaml" > "$work/$name.yaml"
  "$MPIEXEC" -n 2 "$CFDMPM" "$work/$name.yaml" > "$work/$name.log"
  echo "cells [$cells]:"
  "$PYTHON" "$SOURCE_DIR/utilities/dam_break.py" "$work/$name" --json "$work/$name.json"
done
"$PYTHON" - "$work/200x80.json" <<'PY' || status=1
import json, sys
r = json.load(open(sys.argv[1]))
z, h = r["surge_front"]["rms"], r["column_height"]["rms"]
print("finest: Z RMS %.1f %%, H RMS %.1f %% (bound 10 %%)" % (100 * z, 100 * h))
sys.exit(0 if z <= 0.10 and h <= 0.10 else 1)
PY
exit $status
