#!/usr/bin/env bash
# The same scenes on the Serial build (one rank) and on the OpenMP build (one rank of
# OMP_NUM_THREADS threads, default 2), compared field by field with utilities/compare_runs.py:
#   - the dam break, 50 x 20 cells to 0.05 s, pressure solved to a relative residual of 1e-12;
#   - the dry granular column (Drucker-Prager sand), 160 x 60 cells to 0.02 s.
# Threads change only the order of sums: reductions (dot products in CG, diagnostics) and the
# particle-to-grid scatter (tile colour by tile colour on threads). Each differs from the serial
# sum by round-off (~1e-16 relative);
# CG turns that into differences at the linear solver's tolerance per solve, as between 1 and 2
# MPI ranks, so the bound is the same as the 1-vs-2-rank tests': 1e-10 of each field's scale.
#
# usage: utilities/compare-builds.sh <serial build dir> <openmp build dir>
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
serial=${1:?usage: utilities/compare-builds.sh <serial build dir> <openmp build dir>}
omp=${2:?usage: utilities/compare-builds.sh <serial build dir> <openmp build dir>}
threads=${OMP_NUM_THREADS:-2}
source "$root/utilities/mpi-env.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed -e "s|cells: \[200, 80\]|cells: [50, 20]|" -e "s|patch_cells: \[25, 20\]|patch_cells: [10, 10]|" \
    -e "s|end_time: 0.25|end_time: 0.05|" -e "s|  ice: {}|  ice: {solver_tolerance: 1.0e-12}|" \
    "$root/input/dam-break.yaml" > "$work/dam-break.yaml"
sed -e "s|end_time: 0.4|end_time: 0.02|" -e "s|interval: 0.05|interval: 0.01|" \
    "$root/input/granular-column.yaml" > "$work/granular-column.yaml"
status=0
for scene in dam-break granular-column; do
  for build in serial omp; do
    sed "s|directory: .*|directory: $work/$scene-$build|" "$work/$scene.yaml" > "$work/$scene-$build.yaml"
  done
  mpiexec -n 1 "$serial/cfdmpm" "$work/$scene-serial.yaml" > "$work/$scene-serial.log"
  OMP_NUM_THREADS=$threads OMP_PROC_BIND=spread OMP_PLACES=threads \
    mpiexec -n 1 --map-by "slot:PE=$threads" -x OMP_NUM_THREADS -x OMP_PROC_BIND -x OMP_PLACES \
    "$omp/cfdmpm" "$work/$scene-omp.yaml" > "$work/$scene-omp.log"
  echo "$scene: Serial build vs OpenMP build with $threads threads"
  /usr/bin/python3 "$root/utilities/compare_runs.py" "$work/$scene-serial" "$work/$scene-omp" --tolerance 1e-10 || status=1
done
exit $status
