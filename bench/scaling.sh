#!/usr/bin/env bash
# The measurements behind doc/scaling.md, into one directory, and the estimates from them:
#   1. per-phase times on one rank (the slide in 2-D at 10 and 5 mm, in 3-D at 20 mm, a dry granular
#      column), each with 2 and 3 particles per cell and direction where the split between cell and
#      particle work is needed; every timing run twice, the faster kept (the machine is shared);
#   2. per-phase MPI traffic (messages, bytes, reductions) of the 2-D slide at 5 mm on 2, 4 and 8
#      ranks and of the 3-D slide at 20 mm on 8 (oversubscribed: counts only, not times);
#   3. pressure iterations per step at 20, 10 and 5 mm, and on 1-8 ranks (from the CSVs);
#   4. halo sizes and balance of the 5 mm slides on 8, 64, 512 and 4096 ranks (bench_halos);
#   5. what a rebalance costs (the 5 mm slide on 2 ranks, rebalanced before its first step).
# Then bench/scaling.py model prints the tables of doc/scaling.md.
#   usage: bench/scaling.sh [build directory [output directory]]    (~10 minutes on 2 cores)
set -eu
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
out=${2:-$build/scaling}
mkdir -p "$out"
out=$(cd "$out" && pwd)
source "$root/utilities/mpi-env.sh"
python=/usr/bin/python3
profile=$build/bench/libcfdmpm_phase_profile.so
"$python" "$root/bench/scaling.py" scenes "$root" "$out"

# run <name> <ranks> <scene> [profile skip]: the scene with the phase profile, into $out/<name>.
run() {
  local name=$1 ranks=$2 scene=$3 skip=${4:-2}
  echo "$name: $scene on $ranks rank(s)"
  sed "s|OUTPUT|$out/$name|" "$out/$scene.yaml" > "$out/$name.yaml"
  LD_PRELOAD=$profile CFDMPM_PROFILE_JSON=$out/$name.json CFDMPM_PROFILE_SKIP=$skip \
    mpiexec -x LD_PRELOAD -x CFDMPM_PROFILE_JSON -x CFDMPM_PROFILE_SKIP -n "$ranks" \
    "$build/cfdmpm" --overwrite "$out/$name.yaml" > "$out/$name.log" 2>&1 || { cat "$out/$name.log"; exit 1; }
}

for repeat in a b; do
  for scene in slide2d_10mm slide2d_10mm_ppc3 slide2d_5mm slide3d_20mm slide3d_20mm_ppc3 column column_ppc3; do
    run "${scene}_np1_$repeat" 1 "$scene"
  done
done
run slide2d_20mm_np1_a 1 slide2d_20mm
for ranks in 2 4 8; do run "slide2d_5mm_np${ranks}_a" "$ranks" slide2d_5mm; done
run slide3d_20mm_np8_a 8 slide3d_20mm
run rebalance_5mm_np2 2 slide2d_5mm_rebalance 0
"$build/bench/bench_halos" "$out/slide2d_5mm.yaml" 0.13 8:25 64:16 512:8 4096:4 --json "$out/halos_2d.json" > "$out/halos_2d.txt"
"$build/bench/bench_halos" "$out/slide2d_5mm.yaml" 0.25 8:25 64:32 512:16 4096:8 --depth 1.0 200 \
  --json "$out/halos_3d.json" > "$out/halos_3d.txt"
"$build/bench/bench_halos" "$out/slide2d_20mm.yaml" 0.25 8:16 --depth 0.2 10 --json "$out/halos_3d_20mm.json" \
  > "$out/halos_3d_20mm.txt"
"$python" "$root/bench/scaling.py" model "$out"
