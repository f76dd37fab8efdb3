#!/usr/bin/env bash
# Exports a simulated dataset whose sonar moves and the real log as ROS 2 bags and reads them with
# the MCAP project's TypeScript reader and Foxglove's ROS 2 deserialiser (check_rosbag.cjs).
# Usage: test_rosbag_readers.sh SONARBENCH NODE_MODULES. Exit 77 (skipped) when Node.js or the
# packages are missing, unless SONARBENCH_REQUIRE_NODE=1 (CI), where that fails.
set -euo pipefail
sonarbench="$1"
export NODE_PATH="$2"
here="$(cd "$(dirname "$0")" && pwd)"
root="$here/../.."
if ! command -v node > /dev/null || [ ! -d "$NODE_PATH/@mcap/core" ]; then
  echo "Node.js or the npm packages are missing from $NODE_PATH (bash ci/install-npm.sh installs them)"
  if [ "${SONARBENCH_REQUIRE_NODE:-0}" = 1 ]; then exit 1; fi
  exit 77
fi
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
"$sonarbench" simulate "$root/scenes/harbour-wall.yaml" --out "$tmp/sim" > /dev/null
"$sonarbench" export "$tmp/sim" --out "$tmp/sim.mcap" > /dev/null
node "$here/check_rosbag.cjs" "$tmp/sim.mcap" "$tmp/sim"
"$sonarbench" import "$root/data/cras-tank-static/dataset_static.mat" --out "$tmp/real" > /dev/null
"$sonarbench" export "$tmp/real" --out "$tmp/real.mcap" > /dev/null
node "$here/check_rosbag.cjs" "$tmp/real.mcap" "$tmp/real"
