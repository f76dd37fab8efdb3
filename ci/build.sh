#!/usr/bin/env bash
# Configures and builds sonarbench into build/ (Release): everything, or only the targets named
# by leading `--target NAME` arguments (and what they need). Further arguments go to CMake.
# In CI (CI=true) warnings are errors.
set -euo pipefail
cd "$(dirname "$0")/.."
targets=()
names=()
while [ $# -ge 2 ] && [ "$1" = "--target" ]; do targets+=(--target "$2"); names+=("$2"); shift 2; done
if [ ${#targets[@]} -gt 0 ]; then bash ci/install-deps.sh run; else bash ci/install-deps.sh; fi
# three.js for report.html's 3D view (from the npm registry; without it the page says so).
bash ci/install-three.sh
build_dir=${SONARBENCH_BUILD_DIR:-build}
werror=OFF
if [ "${CI:-}" = "true" ]; then werror=ON; fi
mkdir -p "$build_dir"
echo "ci/build.sh: configuring $build_dir (CMake, log in $build_dir/configure.log)"
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE="${SONARBENCH_BUILD_TYPE:-Release}" \
  -DSONARBENCH_WERROR="$werror" "$@" > "$build_dir/configure.log" 2>&1 || {
  cat "$build_dir/configure.log"; exit 1; }
echo "ci/build.sh: building ${names[*]:-everything} on $(nproc) cores"
cmake --build "$build_dir" -j "$(nproc)" "${targets[@]}"
