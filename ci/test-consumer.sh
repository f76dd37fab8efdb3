#!/usr/bin/env bash
# Builds the mapping library alone (none of the simulator's packages needed), installs it into a
# prefix, and builds and runs tests/consumer against it: find_package(sonarbench COMPONENTS
# mapping), as another project would.
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/install-deps.sh
werror=OFF
if [ "${CI:-}" = "true" ]; then werror=ON; fi
prefix="$PWD/build-consumer/prefix"
rm -rf build-consumer
cmake -S . -B build-consumer/mapping -DCMAKE_BUILD_TYPE=Release -DSONARBENCH_MAPPING_ONLY=ON \
  -DSONARBENCH_WERROR="$werror" -DCMAKE_INSTALL_PREFIX="$prefix" > /dev/null
cmake --build build-consumer/mapping -j "$(nproc)"
cmake --install build-consumer/mapping > /dev/null
cmake -S tests/consumer -B build-consumer/consumer -DCMAKE_PREFIX_PATH="$prefix" > /dev/null
cmake --build build-consumer/consumer -j "$(nproc)"
./build-consumer/consumer/map_a_wall
