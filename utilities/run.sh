#!/usr/bin/env bash
# Builds cfdmpm (installing dependencies when missing) and runs a scene, by default the dam break
# on two MPI ranks (and then charts its surge front and column height against the experiment). The
# scene's output directory is replaced (--overwrite), so the command can be repeated.
#
# usage: utilities/run.sh [scene.yaml] [ranks]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
scene=${1:-$root/input/dam-break.yaml}
ranks=${2:-2}
"$root/utilities/setup.sh"
source "$root/utilities/mpi-env.sh"
cd "$root"
mpiexec -n "$ranks" "$root/build/cfdmpm" --overwrite "$scene"
# The dam break is compared with Martin & Moyce (1952): errors printed, chart drawn.
if [ "$(basename "$scene")" = dam-break.yaml ]; then
  out=$(sed -n 's/^ *directory: *//p' "$scene" | head -n 1)
  /usr/bin/python3 "$root/utilities/dam_break.py" "$out" --png "$out/surge-front.png"
fi
