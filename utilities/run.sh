#!/usr/bin/env bash
# Builds cfdmpm (installing dependencies when missing) and runs a scene, by default the dam break
# on two MPI ranks. The scene's output directory is replaced (--overwrite), so the command can be
# repeated.
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
