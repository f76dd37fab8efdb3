#!/usr/bin/env bash
# The main job: installs what is missing, builds, runs the default tank scenario end to end and
# writes its report to out/cras-tank/ (report.json, junit.xml, report.html, map.bt, images). Exits 1
# when the scene's criteria fail.
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/build.sh --target sonarbench
echo "ci/run-tank.sh: running scenes/cras-tank.yaml"
./build/sim/sonarbench run scenes/cras-tank.yaml --out "${1:-out/cras-tank}"
