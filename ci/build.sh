#!/usr/bin/env bash
# Configures and builds sonarbench into build/ (Release). Extra arguments go to CMake.
# In CI (CI=true) warnings are errors.
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/install-deps.sh
build_dir=${SONARBENCH_BUILD_DIR:-build}
werror=OFF
if [ "${CI:-}" = "true" ]; then werror=ON; fi
mkdir -p "$build_dir"
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE="${SONARBENCH_BUILD_TYPE:-Release}" \
  -DSONARBENCH_WERROR="$werror" "$@" > "$build_dir/configure.log" 2>&1 || {
  cat "$build_dir/configure.log"; exit 1; }
cmake --build "$build_dir" -j "$(nproc)"
