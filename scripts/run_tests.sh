#!/usr/bin/env bash
# Build and test bulkflow twice: debug (runtime checks, FP traps) then release, so that the last
# CTest summary printed is the release one. Exits non-zero if a build or any test fails.
# With CI=true compiler warnings are errors (-DBULKFLOW_WERROR=ON).
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

# OpenMPI refuses to run as root (CI is root) and to start more ranks than cores (2 here).
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1

cmake_args=()
if [ "${CI:-}" = true ]; then
  cmake_args+=(-DBULKFLOW_WERROR=ON)
fi

status=0
for kind in debug release; do
  if [ "$kind" = debug ]; then build_dir="$repo/build-debug"; else build_dir="$repo/build"; fi
  echo "=== $kind build"
  bash "$repo/scripts/build.sh" "$kind" "${cmake_args[@]}"
  echo "=== $kind tests"
  (cd "$build_dir" && ctest --output-on-failure --parallel "$(nproc)") || status=1
done
exit $status
