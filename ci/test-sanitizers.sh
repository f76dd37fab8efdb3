#!/usr/bin/env bash
# Builds with AddressSanitizer and UndefinedBehaviorSanitizer (any report aborts the test) into
# build-asan/ and runs the whole test suite there.
set -euo pipefail
cd "$(dirname "$0")/.."
SONARBENCH_BUILD_DIR=build-asan SONARBENCH_BUILD_TYPE=RelWithDebInfo \
  bash ci/build.sh -DSONARBENCH_SANITIZE=ON -DSONARBENCH_BUILD_BENCHMARKS=OFF
cd build-asan
ctest --output-on-failure -j "$(nproc)"
