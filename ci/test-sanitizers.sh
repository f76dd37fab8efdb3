#!/usr/bin/env bash
# One clang build with AddressSanitizer and UndefinedBehaviorSanitizer (any report aborts), into
# build-asan/: the test suite runs there, then each fuzz harness replays its corpus (fuzz/corpus/,
# every input a harness once broke on), so a regression in any reader fails CI. Replaying needs
# no coverage instrumentation; finding new inputs does (fuzz/run.sh, docs/testing.md).
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/install-deps.sh
werror=OFF
if [ "${CI:-}" = "true" ]; then werror=ON; fi
mkdir -p build-asan
# Line tables are enough for the sanitizers' stack traces, and build faster than full -g.
CC=clang CXX=clang++ cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" \
  -DSONARBENCH_SANITIZE=ON -DSONARBENCH_FUZZ=ON -DSONARBENCH_FUZZ_COVERAGE=OFF \
  -DSONARBENCH_BUILD_BENCHMARKS=OFF -DSONARBENCH_WERROR="$werror" \
  -DSONARBENCH_THREE_DIR="$PWD/build-asan/no-three" \
  > build-asan/configure.log 2>&1 || { cat build-asan/configure.log; exit 1; }
cmake --build build-asan -j "$(nproc)"
# Left out here, run by ci/test.sh: tests whose code a test kept here runs under the sanitizers
# already (the tank scenario's variants and the simulated tank's fidelity runs repeat
# scenario.cras-tank's simulation and mapping), the torture runs, whose killed processes never
# reach a sanitizer's report, and the docs' figures, which are the Release build's. This build
# embeds no three.js, so its tests check the page that says so; the browser test is the Release's.
(cd build-asan && ctest --output-on-failure -j "$(nproc)" \
  -E '^(scenario\.cras-tank-(nav-drift|sparse-rays)|Fidelity\.SimulatedTank.*|tool\.torture|docs\.scenario_table|report\.view3d_in_chromium)$')
fuzz/run.sh build-asan 60 0
