#!/usr/bin/env bash
# The same scenes on the Serial build (one rank) and on the OpenMP build (one rank of
# OMP_NUM_THREADS threads, default 2), compared field by field with utilities/compare_runs.py:
#   - the dam break, 50 x 20 cells to 0.05 s, pressure solved to a relative residual of 1e-12;
#   - the dry granular column (Drucker-Prager sand), 160 x 60 cells to 0.02 s;
#   - the coupled seed scene (input/rzadkiewicz.yaml: sand, rigid bed, water, air) at 20 mm to
#     0.05 s, pressure solved to 1e-12, on one rank of the Serial build and of the OpenMP build
#     with 1 thread and with OMP_NUM_THREADS; the two OpenMP runs are compared with each other
#     as well (1 against 2 threads: the same free surface and particle positions to 1e-8 of their
#     scales, as the 1-vs-2-rank test of the coupled step asks).
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
sed -e "s|^    cell_size: 0.01 .*|    cell_size: 0.02|" -e "s|    end_time: 0.8|    end_time: 0.05|" \
    -e "s|^    interval: 0.05|    interval: 0.025|" -e "s|^    outer_tolerance: 1.0e-7|&\n    solver_tolerance: 1.0e-12|" \
    "$root/input/rzadkiewicz.yaml" > "$work/rzadkiewicz.yaml"
grep -q "solver_tolerance: 1.0e-12" "$work/rzadkiewicz.yaml"
# run_omp N NAME: the OpenMP build on one rank of N threads, scene $work/NAME.yaml, log NAME.log.
run_omp() {
  OMP_NUM_THREADS=$1 OMP_PROC_BIND=spread OMP_PLACES=threads \
    mpiexec -n 1 --map-by "slot:PE=$1" -x OMP_NUM_THREADS -x OMP_PROC_BIND -x OMP_PLACES \
    "$omp/cfdmpm" "$work/$2.yaml" > "$work/$2.log"
}
status=0
for scene in dam-break granular-column; do
  for build in serial omp; do
    sed "s|directory: .*|directory: $work/$scene-$build|" "$work/$scene.yaml" > "$work/$scene-$build.yaml"
  done
  mpiexec -n 1 "$serial/cfdmpm" "$work/$scene-serial.yaml" > "$work/$scene-serial.log"
  run_omp "$threads" "$scene-omp"
  echo "$scene: Serial build vs OpenMP build with $threads threads"
  /usr/bin/python3 "$root/utilities/compare_runs.py" "$work/$scene-serial" "$work/$scene-omp" --tolerance 1e-10 || status=1
done
# The coupled scene: Serial, OpenMP on 1 thread, OpenMP on $threads threads.
scene=rzadkiewicz
for run in serial omp1 omp; do
  sed "s|directory: .*|directory: $work/$scene-$run|" "$work/$scene.yaml" > "$work/$scene-$run.yaml"
done
mpiexec -n 1 "$serial/cfdmpm" "$work/$scene-serial.yaml" > "$work/$scene-serial.log"
run_omp 1 "$scene-omp1"
run_omp "$threads" "$scene-omp"
echo "$scene: OpenMP build, 1 thread vs $threads threads"
/usr/bin/python3 "$root/utilities/compare_runs.py" "$work/$scene-omp1" "$work/$scene-omp" --tolerance 1e-8 || status=1
echo "$scene: Serial build vs OpenMP build with $threads threads"
/usr/bin/python3 "$root/utilities/compare_runs.py" "$work/$scene-serial" "$work/$scene-omp" --tolerance 1e-8 || status=1
exit $status
