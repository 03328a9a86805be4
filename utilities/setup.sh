#!/usr/bin/env bash
# Installs what cfdmpm needs from Debian's packages (only the missing ones, as root, with
# `apt-get update` first), then configures and builds the Release build with ninja. Idempotent: an
# existing build directory is reused and only what changed is rebuilt.
#
# usage: utilities/setup.sh [--build-dir DIR] [--no-install] [-- extra cmake arguments]
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="$root/build"
install=1
cmake_args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build=$2; shift 2 ;;
    --no-install) install=0; shift ;;
    -h|--help) sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    --) shift; cmake_args=("$@"); break ;;
    *) echo "setup.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
done

# Debian packages: compiler and build tools, MPI, parallel HDF5, METIS, GoogleTest, the Trilinos
# packages (MueLu's CMake config pulls in ~30 of them), and matplotlib for the plot scripts.
packages=(
  build-essential cmake ninja-build openmpi-bin libopenmpi-dev
  libhdf5-openmpi-dev hdf5-tools libmetis-dev libgtest-dev libptscotch-dev
  libtrilinos-amesos-dev libtrilinos-amesos2-dev libtrilinos-anasazi-dev libtrilinos-aztecoo-dev
  libtrilinos-belos-dev libtrilinos-epetra-dev libtrilinos-epetraext-dev libtrilinos-galeri-dev
  libtrilinos-ifpack-dev libtrilinos-ifpack2-dev libtrilinos-intrepid2-dev libtrilinos-isorropia-dev
  libtrilinos-kokkos-dev libtrilinos-kokkos-kernels-dev libtrilinos-ml-dev libtrilinos-muelu-dev
  libtrilinos-rtop-dev libtrilinos-sacado-dev libtrilinos-shards-dev libtrilinos-shylu-dev
  libtrilinos-stratimikos-dev libtrilinos-teko-dev libtrilinos-teuchos-dev libtrilinos-thyra-dev
  libtrilinos-tpetra-dev libtrilinos-trilinosss-dev libtrilinos-triutils-dev libtrilinos-xpetra-dev
  libtrilinos-zoltan-dev libtrilinos-zoltan2-dev
  python3 python3-numpy python3-matplotlib python3-h5py python3-yaml
)

if [ "$install" = 1 ]; then
  missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "setup: installing ${#missing[@]} missing Debian packages: ${missing[*]}"
    sudo=""
    if [ "$(id -u)" != 0 ]; then
      command -v sudo >/dev/null || { echo "setup: not root and no sudo; install these packages: ${missing[*]}" >&2; exit 1; }
      sudo=sudo
    fi
    export DEBIAN_FRONTEND=noninteractive
    $sudo apt-get update -q
    $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
  else
    echo "setup: all Debian packages present"
  fi
fi

if [ ! -f "$build/build.ninja" ]; then
  echo "setup: configuring $build (Release, ninja)"
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release "${cmake_args[@]}"
elif [ ${#cmake_args[@]} -gt 0 ]; then
  cmake "$build" "${cmake_args[@]}"
fi
# Each Trilinos-heavy translation unit takes ~0.7 GB: two jobs per core pair is safe.
jobs=$(nproc 2>/dev/null || echo 2)
echo "setup: building with $jobs jobs"
cmake --build "$build" -j "$jobs"
echo "setup: build ready in $build (program: $build/cfdmpm)"
