#!/usr/bin/env bash
# Builds cfdmpm (installing dependencies when missing) and runs the whole test suite with ctest.
# Extra arguments go to ctest (e.g. -R ice). A plain ctest runs the default suite: the benchmarks
# (label "bench") and the long validation and stability runs ("validation", "stability") opt in by
# label (`utilities/run-tests.sh -L validation` runs the validation runs only); see test/opt_in/.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/utilities/setup.sh"
source "$root/utilities/mpi-env.sh"
cd "$root/build"
ctest --output-on-failure -j 2 "$@"
