#!/usr/bin/env bash
# The ICE benchmark of two builds (e.g. an older commit's and the current one) in alternating runs,
# so that a burst of load on a shared machine hits both alike; reports per phase the median over
# rounds of each pair's time ratio (this / reference) and the fastest time of each build.
# Absolute times on shared machines drift by tens of percent within an hour; the paired ratio holds.
#
# usage: bench/compare.sh <reference build dir> <build dir> [ranks] [ice args] [rounds]
#   ranks default 1; ice args default "840 336 20" (see bench_ice); rounds default 5.
# A reference build of an older commit:
#   git worktree add --detach ../cfdmpm-ref <commit>
#   cmake -S ../cfdmpm-ref -B ../cfdmpm-ref/build -G Ninja -DCMAKE_BUILD_TYPE=Release
#   ninja -C ../cfdmpm-ref/build bench_ice
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
usage="usage: bench/compare.sh <reference build dir> <build dir> [ranks] [ice args] [rounds]"
reference=${1:?$usage}
current=${2:?$usage}
ranks=${3:-1}
ice_args=${4:-840 336 20}
rounds=${5:-5}
for b in "$reference" "$current"; do
  [ -x "$b/bench/bench_ice" ] || { echo "bench/compare.sh: $b/bench/bench_ice not built (ninja -C $b bench_ice)" >&2; exit 2; }
done
source "$here/../utilities/mpi-env.sh"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for r in $(seq "$rounds"); do
  echo "round $r of $rounds"
  mpiexec -n "$ranks" "$reference/bench/bench_ice" $ice_args > "$out/reference.run$r.txt"
  mpiexec -n "$ranks" "$current/bench/bench_ice" $ice_args > "$out/current.run$r.txt"
done
echo "load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)"
/usr/bin/python3 "$here/compare_report.py" "$out"
