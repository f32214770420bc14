#!/usr/bin/env bash
# Configure and build bulkflow.
#   scripts/build.sh [release|debug] [extra cmake arguments...]
# release (default) builds in build/, debug in build-debug/. Runs scripts/setup.sh first, so a
# fresh Debian 12 machine needs nothing else. Ninja is used when installed, else Makefiles.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

kind=release
if [ $# -gt 0 ]; then
  case "$1" in
    release | debug) kind=$1; shift ;;
    -*) ;;
    *) echo "usage: $0 [release|debug] [cmake arguments...]" >&2; exit 2 ;;
  esac
fi
if [ "$kind" = debug ]; then
  build_dir="$repo/build-debug"
  build_type=Debug
else
  build_dir="$repo/build"
  build_type=Release
fi

bash "$repo/scripts/setup.sh"
python="$repo/.venv/bin/python"   # the interpreter setup.sh prepared

# An existing build directory keeps its generator; a new one gets Ninja if available.
generator=()
if [ ! -f "$build_dir/CMakeCache.txt" ] && command -v ninja >/dev/null 2>&1; then
  generator=(-G Ninja)
fi

# Configure quietly: show bulkflow's own summary lines, or everything if it fails.
mkdir -p "$build_dir"
log="$build_dir/configure.log"
if ! cmake -S "$repo" -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE="$build_type" \
     -DPython3_EXECUTABLE="$python" "$@" >"$log" 2>&1; then
  cat "$log" >&2
  echo "build.sh: cmake configure failed (log: $log)" >&2
  exit 1
fi
if grep -q 'CMake Warning' "$log"; then cat "$log"; else grep '^-- bulkflow:' "$log" || true; fi
cmake --build "$build_dir" --parallel "$(nproc)"
