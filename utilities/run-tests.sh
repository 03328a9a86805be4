#!/usr/bin/env bash
# Builds cfdmpm (installing dependencies when missing) and runs the whole test suite with ctest.
# Extra arguments go to ctest (e.g. -R ice, -L mpi). Benchmarks (label "bench") are not run.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/utilities/setup.sh"
source "$root/utilities/mpi-env.sh"
cd "$root/build"
ctest --output-on-failure -LE bench -j 2 "$@"
