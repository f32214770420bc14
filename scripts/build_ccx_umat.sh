#!/usr/bin/env bash
# Builds CalculiX CrunchiX (ccx) from Debian's source package calculix-ccx with bulkflow's
# Abaqus/Standard UMAT (build/abaqus/bulkflow_abaqus_standard.f) linked in place of ccx's
# example umat.f, and installs it as <prefix>/bin/ccx_bulkflow.
#
#   bash scripts/build_ccx_umat.sh [--prefix DIR] [--umat FILE] [--no-install]
#
# Idempotent and cached: the Debian source and ccx's objects live in $BULKFLOW_CCX_CACHE
# (default ~/.cache/bulkflow-ccx) and are built once; a later call only compiles the UMAT file
# and links again when that file changed (stamp = its sha256). Needs root (or sudo -n) only
# the first time, to add a deb-src entry and install the build dependencies; --no-install
# refuses to touch the system and fails when something is missing.
# Nothing of CalculiX is written into the repository.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
prefix=${BULKFLOW_CCX_PREFIX:-$repo/build-ccx}
umat=$repo/build/abaqus/bulkflow_abaqus_standard.f
cache=${BULKFLOW_CCX_CACHE:-$HOME/.cache/bulkflow-ccx}
install_ok=1
while [ $# -gt 0 ]; do
  case "$1" in
    --prefix) prefix=$2; shift 2 ;;
    --umat) umat=$2; shift 2 ;;
    --no-install) install_ok=0; shift ;;
    -h|--help) sed -n 2,13p "$0"; exit 0 ;;
    *) echo "build_ccx_umat.sh: unknown argument '$1' (expected --prefix DIR, --umat FILE, --no-install)" >&2; exit 2 ;;
  esac
done
if [ ! -f "$umat" ]; then
  echo "build_ccx_umat.sh: $umat not found; build bulkflow first (bash scripts/build.sh release)" >&2
  exit 2
fi
umat=$(cd "$(dirname "$umat")" && pwd)/$(basename "$umat")
mkdir -p "$prefix/bin" "$cache"
prefix=$(cd "$prefix" && pwd)

as_root() {
  if [ "$install_ok" -eq 0 ]; then
    echo "build_ccx_umat.sh: '$*' is needed but --no-install was given" >&2; exit 2
  fi
  if [ "$(id -u)" -eq 0 ]; then "$@"
  elif sudo -n true 2>/dev/null; then sudo -n "$@"
  else echo "build_ccx_umat.sh: '$*' needs root (or sudo without password)" >&2; exit 2
  fi
}

# 1. Debian source of calculix-ccx (deb-src of the mirror and suites the system already uses).
srcdir=$(ls -d "$cache"/calculix-ccx-*/ccx_*/src 2>/dev/null | head -n1 || true)
if [ -z "$srcdir" ]; then
  if ! apt-cache showsrc calculix-ccx >/dev/null 2>&1 || [ -z "$(apt-cache showsrc calculix-ccx 2>/dev/null)" ]; then
    list=/etc/apt/sources.list.d/bulkflow-deb-src.sources
    if [ -f /etc/apt/sources.list.d/debian.sources ]; then
      # deb822: the same stanzas with Types: deb-src.
      sed 's/^Types: *deb$/Types: deb-src/' /etc/apt/sources.list.d/debian.sources > "$cache/deb-src.sources"
    else
      # one-line format: every 'deb' line again as 'deb-src'.
      grep -h '^deb ' /etc/apt/sources.list /etc/apt/sources.list.d/*.list 2>/dev/null \
        | sed 's/^deb /deb-src /' > "$cache/deb-src.sources"
      list=/etc/apt/sources.list.d/bulkflow-deb-src.list
    fi
    as_root cp "$cache/deb-src.sources" "$list"
    as_root apt-get update -qq
  fi
  (cd "$cache" && apt-get source calculix-ccx)
  srcdir=$(ls -d "$cache"/calculix-ccx-*/ccx_*/src | head -n1)
fi
version=$(basename "$(dirname "$srcdir")"); version=${version#ccx_}

# 2. Build dependencies (those of the package's Build-Depends).
missing=()
for pkg in gfortran libarpack2-dev libspooles-dev liblapack-dev libblas-dev; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q 'install ok installed' || missing+=("$pkg")
done
if [ ${#missing[@]} -gt 0 ]; then
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
fi

# 3. ccx's own objects, once (the flags of the Debian package's debian/rules).
jobs=${BULKFLOW_CCX_JOBS:-2}
if [ ! -f "$srcdir/ccx_$version.a" ] || [ ! -f "$srcdir/ccx_$version.o" ]; then
  start=$(date +%s)
  make -C "$srcdir" -j"$jobs" \
    CFLAGS="-O2 -w -I/usr/include/spooles -DARCH=\"Linux\" -DSPOOLES -DARPACK -DMATRIXSTORAGE -DUSE_MT=1" \
    FFLAGS="-O2 -w -fallow-argument-mismatch" "ccx_$version.a" "ccx_$version.o" >"$cache/make.log" 2>&1 \
    || { echo "build_ccx_umat.sh: ccx build failed, see $cache/make.log" >&2; tail -n 20 "$cache/make.log" >&2; exit 1; }
  echo "build_ccx_umat.sh: ccx $version objects built in $(( $(date +%s) - start )) s (make -j$jobs)"
fi
# The archive without ccx's example umat, so that ours is the only one.
if [ ! -f "$cache/libccx_no_umat.a" ] || [ "$srcdir/ccx_$version.a" -nt "$cache/libccx_no_umat.a" ]; then
  cp "$srcdir/ccx_$version.a" "$cache/libccx_no_umat.a"
  ar d "$cache/libccx_no_umat.a" umat.o
fi

# ccx without its umat, for links with another umat (tests/calculix links a tracing wrapper).
libs="-lspooles -lpthread -larpack -llapack -lblas -lm -lc -fopenmp"
mkdir -p "$prefix/lib"
if [ ! -f "$prefix/lib/libccx_no_umat.a" ] || [ "$cache/libccx_no_umat.a" -nt "$prefix/lib/libccx_no_umat.a" ]; then
  cp "$cache/libccx_no_umat.a" "$prefix/lib/libccx_no_umat.a"
  cp "$srcdir/ccx_$version.o" "$prefix/lib/ccx_main.o"
  echo "$libs" > "$prefix/lib/ccx_link_libraries.txt"
fi

# 4. Our UMAT and the link, when the UMAT file changed.
host=$repo/umat/abaqus/standard_host.f90   # stdb_abqerr and xit, which ccx lacks
stamp=$prefix/bin/ccx_bulkflow.sha256
want=$(cat "$umat" "$host" | sha256sum | cut -d' ' -f1)
if [ -x "$prefix/bin/ccx_bulkflow" ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
  echo "build_ccx_umat.sh: $prefix/bin/ccx_bulkflow is up to date"
  exit 0
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp "$umat" "$work/"
include_dir=$repo/umat/abaqus
(cd "$work" && gfortran -O2 -ffree-form -ffree-line-length-none -I "$include_dir" -c "$(basename "$umat")" -o umat.o \
  && gfortran -O2 -c "$host" -o host.o)
# shellcheck disable=SC2086
gfortran -O2 -o "$prefix/bin/ccx_bulkflow" "$prefix/lib/ccx_main.o" "$work/umat.o" "$work/host.o" \
  "$prefix/lib/libccx_no_umat.a" $libs
echo "$want" > "$stamp"
echo "build_ccx_umat.sh: installed $prefix/bin/ccx_bulkflow (CalculiX $version with bulkflow's UMAT)"
