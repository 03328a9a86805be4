#!/usr/bin/env bash
# Build the part of Trilinos that cfdmpm uses with the Kokkos OpenMP backend, from Debian's own
# Trilinos source package, and install it into a prefix. Debian's binary Trilinos has Kokkos Serial
# only (see doc/threads.md). Resumable: run it again after an interruption and it carries on.
# Not part of CI or of the README build; cfdmpm uses the result with
#   cmake -S . -B build-omp -G Ninja -DCFDMPM_TRILINOS_PREFIX=<prefix>
set -Eeuo pipefail

readonly SCRIPT_NAME=${0##*/}
readonly INVOCATION="$0${*:+ $*}"
readonly STAMP_NAME=.cfdmpm-trilinos-openmp-installed
readonly INFO_NAME=cfdmpm-build-info.txt
readonly PACKAGES=(Teuchos Kokkos KokkosKernels Tpetra Belos Amesos2 Ifpack2 Xpetra MueLu)
# Debian packages the build needs (dpkg-dev: dpkg-source unpacks and patches the source package).
readonly BUILD_DEPS=(build-essential cmake ninja-build dpkg-dev xz-utils openmpi-bin libopenmpi-dev
                     libblas-dev liblapack-dev)

usage() {
  cat <<EOF
Usage: $SCRIPT_NAME [options]

Builds Trilinos (${PACKAGES[*]})
with Kokkos' OpenMP backend from Debian's trilinos source package and installs it.
Tpetra and its dependants are instantiated for Scalar=double, LO=int, GO=long long and
Node=Kokkos::OpenMP only. Kokkos keeps its Serial backend as well (it costs a few files).

Stages: apt (deb-src line, build dependencies) -> source (apt-get source trilinos)
        -> configure (CMake + Ninja) -> build (ninja) -> install.
Every stage is skipped when already done, so running the script again after an interruption
resumes the build; when the install is complete (stamp file <prefix>/$STAMP_NAME)
it does nothing. The configuration, the versions and the time of each stage are appended to
<prefix>/$INFO_NAME.

Options (environment variable in brackets):
  --prefix DIR       install prefix            [TRILINOS_OPENMP_PREFIX, default <work>/install]
  --work-dir DIR     work directory            [TRILINOS_OPENMP_WORK,   default trilinos-openmp beside the project]
  --src-dir DIR      source download directory [TRILINOS_OPENMP_SRC,    default <work>/src]
  --build-dir DIR    build directory (kept)    [TRILINOS_OPENMP_BUILD,  default <work>/build]
  --jobs N           parallel compile jobs     [TRILINOS_OPENMP_JOBS,   default nproc = $(nproc)]
  --stop-after STAGE stop after apt, source or configure (configure also prints the plan size)
  --no-apt           do not touch apt: no deb-src line, no apt-get update/install
  --no-ccache        do not install or use ccache (default: use it, cache in <work>/ccache)
  -h, --help         this text

A full build is 801 ninja steps (739 compile units): an estimated 1.5-3 h on 2 cores, with
about 1-2 GB of memory per compile job. The download is 166 MB, the unpacked tree 830 MB.
To share the machine, run it as: nice -n 19 $0 --jobs 1
Then configure cfdmpm with:
  cmake -S . -B build-omp -G Ninja -DCFDMPM_TRILINOS_PREFIX=<prefix>
EOF
}

# --- Options --------------------------------------------------------------------------------------
project_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
work_dir=${TRILINOS_OPENMP_WORK:-$(dirname "$project_root")/trilinos-openmp}
prefix=${TRILINOS_OPENMP_PREFIX:-}
src_dir=${TRILINOS_OPENMP_SRC:-}
build_dir=${TRILINOS_OPENMP_BUILD:-}
jobs=${TRILINOS_OPENMP_JOBS:-$(nproc)}
stop_after=
use_apt=1
use_ccache=1

die() { echo "$SCRIPT_NAME: error: $*" >&2; exit 1; }
need_arg() { [[ $# -ge 2 && -n $2 ]] || die "$1 needs a value (see --help)"; }

while [[ $# -gt 0 ]]; do
  case $1 in
    --prefix)     need_arg "$@"; prefix=$2; shift 2 ;;
    --prefix=*)   prefix=${1#*=}; shift ;;
    --work-dir)   need_arg "$@"; work_dir=$2; shift 2 ;;
    --work-dir=*) work_dir=${1#*=}; shift ;;
    --src-dir)    need_arg "$@"; src_dir=$2; shift 2 ;;
    --src-dir=*)  src_dir=${1#*=}; shift ;;
    --build-dir)  need_arg "$@"; build_dir=$2; shift 2 ;;
    --build-dir=*) build_dir=${1#*=}; shift ;;
    --jobs|-j)    need_arg "$@"; jobs=$2; shift 2 ;;
    --jobs=*)     jobs=${1#*=}; shift ;;
    --stop-after) need_arg "$@"; stop_after=$2; shift 2 ;;
    --stop-after=*) stop_after=${1#*=}; shift ;;
    --no-apt)     use_apt=0; shift ;;
    --no-ccache)  use_ccache=0; shift ;;
    -h|--help)    usage; exit 0 ;;
    *)            die "unknown argument '$1' (see --help)" ;;
  esac
done

[[ $jobs =~ ^[1-9][0-9]*$ ]] || die "--jobs needs a positive integer, got '$jobs'"
case $stop_after in ''|apt|source|configure) ;; *) die "--stop-after takes apt, source or configure" ;; esac
work_dir=$(realpath -m -- "$work_dir")
prefix=$(realpath -m -- "${prefix:-$work_dir/install}")
src_dir=$(realpath -m -- "${src_dir:-$work_dir/src}")
build_dir=$(realpath -m -- "${build_dir:-$work_dir/build}")
export CCACHE_DIR=${CCACHE_DIR:-$work_dir/ccache}
readonly info_file=$prefix/$INFO_NAME

# --- Messages, timing and interruption ------------------------------------------------------------
now() { date '+%Y-%m-%d %H:%M:%S'; }
say() { printf '[%s] %s: %s\n' "$(now)" "$SCRIPT_NAME" "$*"; }
record() { printf '%s\n' "$*" >>"$info_file"; }
hms() { printf '%dh%02dm%02ds' $(($1 / 3600)) $(($1 % 3600 / 60)) $(($1 % 60)); }

stage='' stage_start=0 child=''
begin_stage() { stage=$1; stage_start=$SECONDS; say "== stage $stage: $2"; }
end_stage() {  # end_stage [note]
  local took=$((SECONDS - stage_start))
  say "== stage $stage done in $(hms "$took")"
  record "stage $stage: $took s ($(hms "$took"))${1:+, $1}"
  stage=
}
on_exit() {
  local rc=$?
  if [[ -n $stage ]]; then
    local took=$((SECONDS - stage_start))
    say "stage $stage stopped after $(hms "$took") (exit code $rc); run $SCRIPT_NAME again to resume"
    [[ -f $info_file ]] && record "stage $stage: stopped after $took s, exit code $rc"
  fi
}
on_signal() {  # stop the running child process group, then exit (the EXIT trap records it)
  trap - INT TERM HUP
  if [[ -n $child ]]; then kill -TERM -- "-$child" 2>/dev/null || true; wait "$child" 2>/dev/null || true; fi
  exit 130
}
trap on_exit EXIT
trap on_signal INT TERM HUP

# run_logged LOG CMD...: run CMD with its output on the terminal and appended to LOG. The command runs
# in its own process group so that an interruption of this script stops it and all its children.
run_logged() {
  local log=$1 rc=0; shift
  set -m
  ( "$@" 2>&1 | tee -a "$log" ) &
  child=$!
  set +m
  wait "$child" || rc=$?
  child=
  return "$rc"
}

as_root() {
  if [[ $(id -u) -eq 0 ]]; then "$@"
  elif command -v sudo >/dev/null; then sudo "$@"
  else die "needs root for: $* (run that by hand, then use --no-apt)"; fi
}

# --- The CMake configuration ----------------------------------------------------------------------
cmake_args() {  # cmake_args SOURCE_DIR: prints one argument per line
  local src=$1 p
  printf '%s\n' -S "$src" -B "$build_dir" -G Ninja \
    -DCMAKE_BUILD_TYPE=Release \
    "-DCMAKE_INSTALL_PREFIX=$prefix" \
    -DCMAKE_C_COMPILER=mpicc \
    -DCMAKE_CXX_COMPILER=mpicxx \
    -DBUILD_SHARED_LIBS=ON \
    "-DCMAKE_INSTALL_RPATH=$prefix/lib" \
    -DCMAKE_INSTALL_RPATH_USE_LINK_PATH=ON \
    -DTrilinos_LIBRARY_NAME_PREFIX=trilinos_ \
    -DTPL_ENABLE_MPI=ON \
    -DTrilinos_ENABLE_Fortran=OFF \
    -DTrilinos_ENABLE_DEVELOPMENT_MODE=OFF \
    -DTrilinos_ASSERT_MISSING_PACKAGES=OFF \
    -DTrilinos_ENABLE_ALL_PACKAGES=OFF \
    -DTrilinos_ENABLE_ALL_OPTIONAL_PACKAGES=OFF \
    -DTrilinos_ENABLE_SECONDARY_TESTED_CODE=OFF
  for p in "${PACKAGES[@]}"; do printf '%s\n' "-DTrilinos_ENABLE_$p=ON"; done
  printf '%s\n' \
    -DTrilinos_ENABLE_TESTS=OFF \
    -DTrilinos_ENABLE_EXAMPLES=OFF \
    -DTrilinos_ENABLE_EXPLICIT_INSTANTIATION=ON \
    -DTrilinos_ENABLE_COMPLEX=OFF \
    -DTrilinos_ENABLE_FLOAT=OFF \
    -DTrilinos_ENABLE_OpenMP=ON \
    -DKokkos_ENABLE_OPENMP=ON \
    -DKokkos_ENABLE_SERIAL=ON \
    -DTpetra_INST_OPENMP=ON \
    -DTpetra_INST_SERIAL=OFF \
    -DTpetra_INST_DOUBLE=ON \
    -DTpetra_INST_FLOAT=OFF \
    -DTpetra_INST_COMPLEX_DOUBLE=OFF \
    -DTpetra_INST_COMPLEX_FLOAT=OFF \
    -DTpetra_INST_INT_LONG_LONG=ON \
    -DTpetra_INST_INT_INT=OFF \
    -DTpetra_INST_INT_LONG=OFF \
    -DTpetra_INST_INT_UNSIGNED=OFF \
    -DTpetra_INST_INT_UNSIGNED_LONG=OFF \
    -DKokkosKernels_INST_EXECSPACE_SERIAL=OFF \
    -DKokkosKernels_INST_EXECSPACE_OPENMP=ON
  if [[ $use_ccache -eq 1 ]]; then
    printf '%s\n' -DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache
  fi
}

# --- Start ------------------------------------------------------------------------------------------
mkdir -p "$prefix"
if [[ -f $prefix/$STAMP_NAME ]]; then
  say "Trilinos with Kokkos OpenMP is already installed in $prefix (stamp $prefix/$STAMP_NAME)."
  say "Nothing to do. Delete the stamp file to build and install again."
  trap - EXIT
  exit 0
fi
mkdir -p "$work_dir" "$src_dir" "$build_dir"
exec 9>"$build_dir/.cfdmpm-build.lock"
flock -n 9 || die "another $SCRIPT_NAME is running on $build_dir (lock $build_dir/.cfdmpm-build.lock)"
record ""
record "===== $SCRIPT_NAME run started $(now)"
record "command: $INVOCATION"
record "host: $(uname -srm), $(nproc) cores, jobs $jobs"
record "directories: source $src_dir, build $build_dir, prefix $prefix"
say "prefix $prefix, source $src_dir, build $build_dir, $jobs jobs; log: $info_file"

# --- Stage apt: deb-src line and build dependencies -------------------------------------------------
src_stamp=$src_dir/.cfdmpm-source-unpacked
if [[ $use_apt -eq 1 ]]; then
  begin_stage apt "deb-src line and build dependencies"
  updated=0
  if [[ ! -f $src_stamp ]] && ! apt-cache showsrc trilinos 2>/dev/null | grep -q '^Package: trilinos'; then
    if ! grep -rqsE '^[[:space:]]*(deb-src[[:space:]]|Types:.*deb-src)' /etc/apt/sources.list /etc/apt/sources.list.d/; then
      # shellcheck source=/dev/null
      codename=$(. /etc/os-release && echo "${VERSION_CODENAME:-}")
      [[ -n $codename ]] || die "cannot tell the Debian release from /etc/os-release"
      mirror=$(grep -rhsoE 'https?://[^ ]*/debian/?$' /etc/apt/sources.list /etc/apt/sources.list.d/ | head -n1 || true)
      mirror=${mirror:-http://deb.debian.org/debian}
      say "adding a deb-src entry for $codename ($mirror) in /etc/apt/sources.list.d/debian-src.sources"
      printf '%s\n' "Types: deb-src" "URIs: $mirror" "Suites: $codename $codename-updates" \
        "Components: main" "Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg" |
        as_root tee /etc/apt/sources.list.d/debian-src.sources >/dev/null
    fi
    say "apt-get update"
    as_root apt-get update -q
    updated=1
  fi
  wanted=("${BUILD_DEPS[@]}")
  if [[ $use_ccache -eq 1 ]]; then wanted+=(ccache); fi
  missing=()
  for pkg in "${wanted[@]}"; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q 'install ok installed' || missing+=("$pkg")
  done
  if [[ ${#missing[@]} -gt 0 ]]; then
    [[ $updated -eq 1 ]] || as_root apt-get update -q
    say "installing ${missing[*]}"
    as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
  else
    say "build dependencies present: ${wanted[*]}"
  fi
  end_stage
  if [[ $stop_after == apt ]]; then say "stopping after stage apt as asked"; exit 0; fi
fi
if [[ $use_ccache -eq 1 ]] && ! command -v ccache >/dev/null; then
  say "ccache not found; building without it"
  use_ccache=0
fi

# --- Stage source: apt-get source trilinos ------------------------------------------------------------
if [[ -f $src_stamp ]]; then
  trilinos_src=$(sed -n 's/^dir=//p' "$src_stamp")
  src_version=$(sed -n 's/^version=//p' "$src_stamp")
  say "source already unpacked: $trilinos_src (Debian trilinos $src_version)"
else
  begin_stage source "apt-get source trilinos into $src_dir"
  cd "$src_dir"
  # A download or unpack that was interrupted leaves a partial tree, which dpkg-source refuses to
  # overwrite. Downloaded files that are complete are checked and kept by apt-get.
  for d in trilinos-[0-9]*/; do
    if [[ -d $d ]]; then say "removing partial tree $src_dir/$d"; rm -rf -- "$d"; fi
  done
  run_logged "$src_dir/apt-get-source.log" apt-get source -q trilinos
  dscs=(trilinos_*.dsc)
  [[ ${#dscs[@]} -eq 1 && -f ${dscs[0]} ]] || die "expected one trilinos_*.dsc in $src_dir, found: ${dscs[*]}"
  dsc=${dscs[0]}
  src_version=$(sed -n 's/^Version: //p' "$dsc")
  upstream=${src_version%-*}; upstream=${upstream#*:}
  trilinos_src=$src_dir/trilinos-$upstream
  [[ -f $trilinos_src/CMakeLists.txt ]] || die "no $trilinos_src/CMakeLists.txt after apt-get source"
  download=$(du -cb trilinos_"${upstream}"* | tail -n1 | cut -f1)
  printf 'dir=%s\nversion=%s\n' "$trilinos_src" "$src_version" >"$src_stamp"
  end_stage "Debian trilinos $src_version, download $((download / 1000000)) MB, tree $(du -sm "$trilinos_src" | cut -f1) MB"
fi
if [[ $stop_after == source ]]; then say "stopping after stage source as asked"; exit 0; fi

# --- Versions and configuration -------------------------------------------------------------------
mapfile -t args < <(cmake_args "$trilinos_src")
config_id=$( { printf '%s\n' "$src_version" "${args[@]}"; } | sha256sum | cut -c1-16)
record "Debian trilinos source: $src_version ($trilinos_src)"
record "versions: $(g++ --version | head -n1); $(cmake --version | head -n1); ninja $(ninja --version);" \
  "$(mpirun --version 2>/dev/null | head -n1)$(if [[ $use_ccache -eq 1 ]]; then echo "; $(ccache --version | head -n1)"; fi)"
record "configuration id: $config_id"
record "cmake command: cmake $(printf '%q ' "${args[@]}")"

# --- Stage configure ------------------------------------------------------------------------------
conf_stamp=$build_dir/.cfdmpm-configured
if [[ -f $build_dir/build.ninja && -f $conf_stamp && $(cat "$conf_stamp") == "$config_id" ]]; then
  say "already configured in $build_dir (configuration $config_id)"
else
  begin_stage configure "cmake (TriBITS) in $build_dir"
  rm -f "$conf_stamp"
  run_logged "$build_dir/configure.log" cmake "${args[@]}"
  echo "$config_id" >"$conf_stamp"
  end_stage
fi
planned=$(ninja -C "$build_dir" -n | tail -n1 | sed -nE 's/^\[[0-9]+\/([0-9]+)\].*/\1/p')
planned=${planned:-0}
compiles=$(ninja -C "$build_dir" -t commands | grep -c -- ' -c ' || true)
say "ninja plans $planned build steps still to run (the whole build has $compiles compile commands)"
record "ninja: $planned build steps still to run; $compiles compile commands in all"
if [[ $stop_after == configure ]]; then say "stopping after stage configure as asked"; exit 0; fi

# --- Stage build ----------------------------------------------------------------------------------
begin_stage build "ninja -j $jobs ($planned steps; progress [done/total] below, log $build_dir/build.log)"
run_logged "$build_dir/build.log" ninja -C "$build_dir" -j "$jobs"
end_stage "$planned steps"

# --- Stage install --------------------------------------------------------------------------------
begin_stage install "ninja install into $prefix"
run_logged "$build_dir/install.log" ninja -C "$build_dir" install >/dev/null
grep -qs '^#define KOKKOS_ENABLE_OPENMP' "$prefix/include/KokkosCore_config.h" ||
  die "the installed KokkosCore_config.h does not define KOKKOS_ENABLE_OPENMP"
[[ -f $prefix/lib/cmake/Trilinos/TrilinosConfig.cmake ]] || die "no TrilinosConfig.cmake under $prefix/lib"
echo "$config_id" >"$prefix/$STAMP_NAME"
end_stage
record "installed $(now): use -DCFDMPM_TRILINOS_PREFIX=$prefix"
say "done. Configure cfdmpm with: cmake -S . -B build-omp -G Ninja -DCFDMPM_TRILINOS_PREFIX=$prefix"
