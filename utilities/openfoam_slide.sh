#!/bin/bash
# The Rzadkiewicz submarine slide (input/rzadkiewicz.yaml) in OpenFOAM v1912 (Debian's `openfoam`
# package, multiphaseInterFoam; water, a Bingham sand and air), for the cross-check of doc/openfoam-slide.md.
#
# usage: utilities/openfoam_slide.sh H_MM [WORK_DIR] [CORES]
#   H_MM      cell size in mm: 40, 20, 10 or 5 (the tank, 3.52 x 2.04 m, divides into these)
#   WORK_DIR  the case directory to create (default /tmp/openfoam-rzadkiewicz-<H_MM>mm; removed first)
#   CORES     1 (default): a serial run; N > 1: the mesh divided into N strips in x of equal cell
#             counts (decomposePar, method simple), mpirun -np N multiphaseInterFoam -parallel, the
#             parts joined again (reconstructPar)
# Copies the case template data/reference/openfoam-rzadkiewicz/, meshes the tank with uniform square
# cells (blockMesh), removes the cells whose centre lies inside the rigid bed (subsetMesh: a staircase
# bed), sets the water, sand and air volume shares (utilities/openfoam_slide.py init), runs the solver
# under nice to t = 0.8 s on CORES cores, and writes data/reference/openfoam-rzadkiewicz-<H_MM>mm.csv
# (-<H_MM>mm-<CORES>cores.csv for CORES > 1) and the summary (utilities/openfoam_slide.py extract).
# Needs OpenFOAM (apt-get install openfoam) and python3 with numpy; nothing else in the project
# depends on it.
set -eo pipefail
H_MM=${1:?usage: openfoam_slide.sh H_MM [WORK_DIR] [CORES]}
WORK=${2:-/tmp/openfoam-rzadkiewicz-${H_MM}mm}
CORES=${3:-1}
[[ "$CORES" =~ ^[1-9][0-9]*$ ]] || { echo "openfoam_slide.sh: CORES must be a positive integer, not '$CORES'" >&2; exit 2; }
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BASHRC=${FOAM_BASHRC:-$(dpkg -L openfoam 2>/dev/null | grep '/etc/bashrc$' | head -1)}
BASHRC=${BASHRC:-/usr/share/openfoam/etc/bashrc}
# Debian's bashrc complains about helper scripts it does not ship; the environment it sets is enough.
source "$BASHRC" > /dev/null 2>&1 || true
command -v multiphaseInterFoam > /dev/null || { echo "openfoam_slide.sh: no multiphaseInterFoam" >&2; exit 1; }

# A python3 with numpy (Debian's python3-numpy if the first python3 on PATH has none).
PY=${PYTHON:-python3}
"$PY" -c "import numpy" 2> /dev/null || PY=/usr/bin/python3

H=$($PY -c "print($H_MM / 1000)")
read -r NX NY < <($PY -c "print(round(3.52 / $H), round(2.04 / $H))")
rm -rf "$WORK"
mkdir -p "$WORK"
cp -r "$ROOT/data/reference/openfoam-rzadkiewicz/." "$WORK/"
cd "$WORK"
sed -i -e "s/^H .*/H   $H;/" -e "s/^NX .*/NX  $NX;/" -e "s/^NY .*/NY  $NY;/" system/blockMeshDict

echo "openfoam_slide.sh: ${H_MM} mm, ${NX} x ${NY} cells before the bed is removed, case $WORK"
blockMesh > log.blockMesh 2>&1
"$PY" "$ROOT/utilities/openfoam_slide.py" bed . "$H"
subsetMesh -overwrite -patch walls fluid > log.subsetMesh 2>&1
rm -rf 0 && cp -r 0.orig 0
postProcess -func writeCellCentres -time 0 > log.writeCellCentres 2>&1
"$PY" "$ROOT/utilities/openfoam_slide.py" init . "$H"
checkMesh > log.checkMesh 2>&1 || { tail -20 log.checkMesh; exit 1; }
grep -E "cells:|Mesh OK|Failed" log.checkMesh || true

echo "openfoam_slide.sh: running multiphaseInterFoam (log: $WORK/log.multiphaseInterFoam)"
status=0
if [ "$CORES" -eq 1 ]; then
  nice -n 10 multiphaseInterFoam > log.multiphaseInterFoam 2>&1 || status=$?
else
  cat > system/decomposeParDict << EOF
FoamFile { version 2.0; format ascii; class dictionary; location "system"; object decomposeParDict; }
numberOfSubdomains $CORES;
method simple;
simpleCoeffs { n ($CORES 1 1); delta 0.001; }
EOF
  decomposePar -force > log.decomposePar 2>&1 || { tail -5 log.decomposePar; exit 1; }
  # Open MPI refuses root unless told (a container); harmless otherwise.
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
  nice -n 10 mpirun -np "$CORES" multiphaseInterFoam -parallel > log.multiphaseInterFoam 2>&1 || status=$?
  reconstructPar > log.reconstructPar 2>&1 || { tail -5 log.reconstructPar; exit 1; }
fi
[ $status -eq 0 ] || echo "openfoam_slide.sh: multiphaseInterFoam exited with $status" >&2
"$PY" "$ROOT/utilities/openfoam_slide.py" extract . "$H" --cores "$CORES"
exit $status
