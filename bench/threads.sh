#!/usr/bin/env bash
# Threads against ranks, in one run: the ICE dam-break benchmark and the MPM benchmark
#   - on the Serial build (Debian's Trilinos) with 1 and 2 MPI ranks,
#   - on the OpenMP build (utilities/build-trilinos-openmp.sh) with 1 rank of 1 and of 2 threads,
# then a table of the per-phase times, the speed-up of 2 threads over 1 and of 2 ranks over 1, and
# the parallel efficiency (speed-up / 2). See doc/threads.md.
#
# usage: bench/threads.sh <serial build dir> <openmp build dir> [ice args] [mpm args] [repeats]
#   ice args default "840 336 20" (cells x, cells y, steps; a 4th argument: the scene's ice section)
#   mpm args default "1000 10" (cells per side, steps)
#   repeats default 3: the eight runs are repeated in turn (so that a burst of load on the shared
#   machine hits every configuration alike) and each configuration reports its fastest run.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
serial=${1:?usage: bench/threads.sh <serial build dir> <openmp build dir>}
omp=${2:?usage: bench/threads.sh <serial build dir> <openmp build dir>}
ice_args=${3:-840 336 20}
mpm_args=${4:-1000 10}
repeats=${5:-3}
for b in "$serial" "$omp"; do
  for exe in bench/bench_ice bench/bench_mpm; do
    [ -x "$b/$exe" ] || { echo "bench/threads.sh: $b/$exe not built (ninja -C $b bench_ice bench_mpm)" >&2; exit 2; }
  done
done
source "$here/../utilities/mpi-env.sh"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
# Ranks: one core each (Open MPI's default binding). Threads: one rank given both cores, threads
# bound one per core.
run_ranks() { mpiexec -n "$2" "$serial/bench/$1" $3 > "$out/$1.ranks$2.run$4.txt"; }
run_threads() {
  OMP_NUM_THREADS=$2 OMP_PROC_BIND=spread OMP_PLACES=threads \
    mpiexec -n 1 --map-by "slot:PE=$2" -x OMP_NUM_THREADS -x OMP_PROC_BIND -x OMP_PLACES \
    "$omp/bench/$1" $3 > "$out/$1.threads$2.run$4.txt"
}
for r in $(seq "$repeats"); do
  echo "round $r of $repeats: bench_ice and bench_mpm on 1 and 2 ranks (Serial build), 1 and 2 threads (OpenMP build)"
  for n in 1 2; do
    run_ranks bench_ice $n "$ice_args" "$r"
    run_threads bench_ice $n "$ice_args" "$r"
    run_ranks bench_mpm $n "$mpm_args" "$r"
    run_threads bench_mpm $n "$mpm_args" "$r"
  done
done
echo "load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)"
/usr/bin/python3 "$here/threads_report.py" "$out"
