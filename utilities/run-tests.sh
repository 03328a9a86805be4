#!/usr/bin/env bash
# Builds cfdmpm (installing dependencies when missing) and runs the whole test suite with ctest.
# Extra arguments go to ctest (e.g. -R ice). Benchmarks (label "bench") and the long validation runs
# (label "validation", run them with `ctest -L validation`) and the coupled cases that do not pass
# yet (label "coupled-open") are left out.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/utilities/setup.sh"
source "$root/utilities/mpi-env.sh"
cd "$root/build"
ctest --output-on-failure -LE "bench|validation|coupled-open" -j 2 "$@"
