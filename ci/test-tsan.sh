#!/usr/bin/env bash
# Builds the threaded code and its suites with ThreadSanitizer into build-tsan/ and runs them: the
# mapper's batches, the simulation's beams, the divisions study, the fan image, the map command's
# outputs written side by side, the ground truth's direct echoes, the label files' records, and a
# whole scenario at 1 and 2 threads. clang with LLVM's OpenMP and its Archer tool, so that TSan
# sees OpenMP's barriers.
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/install-deps.sh
werror=OFF
if [ "${CI:-}" = "true" ]; then werror=ON; fi
mkdir -p build-tsan
CC=clang CXX=clang++ cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DSONARBENCH_TSAN=ON -DSONARBENCH_BUILD_BENCHMARKS=OFF -DSONARBENCH_WERROR="$werror" \
  > build-tsan/configure.log 2>&1 || { cat build-tsan/configure.log; exit 1; }
cmake --build build-tsan -j "$(nproc)" --target sonarbench test_mapping test_sonar test_report \
  test_app test_scenario test_eval
cd build-tsan
export OMP_TOOL_LIBRARIES=/usr/lib/llvm-14/lib/libarcher.so
export TSAN_OPTIONS="halt_on_error=1 ignore_noninstrumented_modules=1 suppressions=$PWD/../ci/tsan.supp"
ctest --output-on-failure -j "$(nproc)" \
  -R '^(IntegrateBatch|ExactBeamCells|ArcEvidence|MapTree|BeamRaster|Simulation|DivisionsStudy|RenderFanImage|RunTasks|DirectEchoes|LabelFileBeams)\.|^RealLogMap\.OutputsAreTheSameOnOneThreadAsOnTwo$'
./tests/test_scenario --gtest_filter='Scenario.MapIsIdenticalForOneAndTwoThreads'
