#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite with ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/build.sh
# The Python module's tests must run here too (ci/install-deps.sh installed pybind11).
test -f build/python/sonarbench/__init__.py || {
  echo "ci/test.sh: the Python module was not built (build/configure.log says why)" >&2; exit 1; }
# The readers the ROS 2 bag test checks sonarbench's bags with; that test must run here.
bash ci/install-npm.sh build/npm
export SONARBENCH_REQUIRE_NODE=1
cd build
ctest --output-on-failure -j "$(nproc)"
