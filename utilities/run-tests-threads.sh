#!/usr/bin/env bash
# The test suite on threads: builds cfdmpm against a Trilinos with Kokkos OpenMP (made by
# utilities/build-trilinos-openmp.sh) in build-omp/ and runs the same tests as run-tests.sh with
# OMP_NUM_THREADS threads per rank (default 2). Tests run one at a time (each already uses the
# cores), and Open MPI does not bind ranks to single cores, so that a rank's threads can spread.
# Extra arguments go to ctest (e.g. -R mpm). See doc/threads.md.
#
# usage: utilities/run-tests-threads.sh [ctest arguments]
#   TRILINOS_OPENMP_PREFIX  the Trilinos prefix (default: ../trilinos-openmp/install beside the project)
#   OMP_NUM_THREADS         threads per rank (default 2)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
prefix=${TRILINOS_OPENMP_PREFIX:-$(dirname "$root")/trilinos-openmp/install}
if [ ! -f "$prefix/.cfdmpm-trilinos-openmp-installed" ]; then
  echo "run-tests-threads.sh: no finished OpenMP Trilinos in $prefix" >&2
  echo "  build one with utilities/build-trilinos-openmp.sh (1.5-3 h on 2 cores), or set TRILINOS_OPENMP_PREFIX" >&2
  exit 2
fi
build=$root/build-omp
if [ ! -f "$build/build.ninja" ]; then
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCFDMPM_TRILINOS_PREFIX="$prefix"
fi
cmake --build "$build" -j "$(nproc)"
grep -q "KOKKOS_ENABLE_OPENMP" "$prefix/include/KokkosCore_config.h" 2>/dev/null ||
  find "$prefix" -name KokkosCore_config.h -exec grep -q "KOKKOS_ENABLE_OPENMP" {} \; -quit
source "$root/utilities/mpi-env.sh"
# Passive waiting: with 2 and 3 ranks of 2 threads on 2 cores the threads outnumber the cores, and
# spinning threads then wait on each other (test_advection_np2 took 175 s instead of ~10 s).
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-2} OMP_PROC_BIND=false OMP_WAIT_POLICY=passive
export OMPI_MCA_hwloc_base_binding_policy=none
cd "$build"
ctest --output-on-failure -j 1 "$@"
