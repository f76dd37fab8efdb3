#!/usr/bin/env bash
# Installs into DIR (default build/npm) the npm packages that read sonarbench's ROS 2 bags in the
# tests (ci/npm/package.json, versions locked), and Node.js from Debian when it is missing.
set -euo pipefail
cd "$(dirname "$0")/.."
dir="${1:-build/npm}"
if ! command -v npm > /dev/null; then bash ci/install-deps.sh node; fi
mkdir -p "$dir"
cp ci/npm/package.json ci/npm/package-lock.json "$dir/"
(cd "$dir" && npm ci --no-audit --no-fund --loglevel=error)
