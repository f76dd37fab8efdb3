#!/usr/bin/env bash
# Installs into DIR (default build/npm) the npm packages that read sonarbench's ROS 2 bags in the
# tests (ci/npm/package.json, versions locked), and Node.js from Debian when it is missing.
set -euo pipefail
cd "$(dirname "$0")/.."
dir="${1:-build/npm}"
if ! command -v npm > /dev/null; then
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  echo "ci/install-npm.sh: installing nodejs npm"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -q
  $sudo apt-get install -y -q --no-install-recommends nodejs npm
fi
mkdir -p "$dir"
cp ci/npm/package.json ci/npm/package-lock.json "$dir/"
(cd "$dir" && npm ci --no-audit --no-fund --loglevel=error)
