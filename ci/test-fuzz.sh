#!/usr/bin/env bash
# Builds the libFuzzer harnesses with clang, ASan and UBSan into build-fuzz/ and runs each on its
# corpus (fuzz/corpus/, which holds every input a harness once broke on), so a regression in any
# reader fails CI. Longer runs: fuzz/run.sh, docs/testing.md.
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
# Each harness replays its whole corpus (-runs=0: no new inputs), the same every time: new inputs
# are found by longer runs of fuzz/run.sh, not by CI.
fuzz/run.sh build-fuzz 60 0
