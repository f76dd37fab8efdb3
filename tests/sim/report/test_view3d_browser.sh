#!/usr/bin/env bash
# report.html's 3D view in a real browser (check_view3d.cjs: Debian's chromium, headless, through
# Playwright): the main job's report (build/scenarios/cras-tank/, the scenario tests' output), the
# real log's map scored against the tank and the log's map alone. Saves the main job's canvas as
# SCREENSHOT. Usage: test_view3d_browser.sh SONARBENCH NODE_MODULES SCENARIOS_DIR SCREENSHOT.
# Exit 77 (skipped) when Node.js, Playwright, chromium or three.js in the build are missing, unless
# SONARBENCH_REQUIRE_NODE=1 (CI), where that fails.
set -euo pipefail
sonarbench="$1"
export NODE_PATH="$2"
scenarios="$3"
screenshot="$4"
here="$(cd "$(dirname "$0")" && pwd)"
root="$here/../../.."
skip() {
  echo "$1"
  if [ "${SONARBENCH_REQUIRE_NODE:-0}" = 1 ]; then exit 1; fi
  exit 77
}
if ! command -v node > /dev/null || [ ! -d "$NODE_PATH/playwright-core" ]; then
  skip "Node.js or playwright-core are missing from $NODE_PATH (bash ci/install-npm.sh installs them)"
fi
[ -x /usr/bin/chromium ] || skip "Debian's chromium is missing (bash ci/install-deps.sh installs it)"
if grep -q "No 3D view" "$scenarios/cras-tank/report.html"; then
  skip "this build embeds no three.js (bash ci/install-three.sh, then build again)"
fi
node "$here/check_view3d.cjs" "$scenarios/cras-tank/report.html" "$screenshot"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
# The real log against the tank: exit 1 when it misses the simulated tank's criteria, which it may.
status=0
"$sonarbench" map "$root/data/cras-tank-static/dataset_static.mat" --scene "$root/scenes/cras-tank.yaml" \
  --score --out "$tmp/log" > /dev/null || status=$?
[ "$status" -le 1 ] || { echo "sonarbench map --score exited $status"; exit 1; }
node "$here/check_view3d.cjs" "$tmp/log/report.html" "$tmp/log-3d.png"
# A map of the log alone: its cells all of one class.
"$sonarbench" map "$root/data/cras-tank-static/dataset_static.mat" --out "$tmp/alone" > /dev/null
node "$here/check_view3d.cjs" "$tmp/alone/report.html" "$tmp/alone-3d.png"
