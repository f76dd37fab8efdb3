#!/usr/bin/env bash
# Builds the libFuzzer harnesses with clang, ASan and UBSan into build-fuzz/ and runs each for a
# short, bounded time on its corpus (fuzz/corpus/, which holds every input a harness once broke
# on), so a regression in any reader fails CI. Longer runs: fuzz/run.sh, docs/testing.md.
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/install-deps.sh
werror=OFF
if [ "${CI:-}" = "true" ]; then werror=ON; fi
mkdir -p build-fuzz
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DSONARBENCH_FUZZ=ON -DSONARBENCH_BUILD_TESTS=OFF -DSONARBENCH_BUILD_BENCHMARKS=OFF \
  -DSONARBENCH_WERROR="$werror" > build-fuzz/configure.log 2>&1 || {
  cat build-fuzz/configure.log; exit 1; }
cmake --build build-fuzz -j "$(nproc)" --target fuzzers
# A fixed seed and count, about 20 s a harness: the same inputs as every run of this commit.
export SEED=1
fuzz/run.sh build-fuzz 60 5000 scene mesh
fuzz/run.sh build-fuzz 60 20000 sensor_model dataset
fuzz/run.sh build-fuzz 60 60000 criteria mat_log
