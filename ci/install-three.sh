#!/usr/bin/env bash
# Installs into DIR (default build/three) the npm package three at the version and sha512 that
# ci/npm/package-lock.json locks, straight from the npm registry (curl; no Node.js needed), for
# the build to embed in report.html's 3D view. Cheap when it is there already. Without a network
# it warns and leaves the 3D view out of the build (the page then says so).
set -euo pipefail
cd "$(dirname "$0")/.."
dir="${1:-build/three}"
lock=ci/npm/package-lock.json
entry=$(grep -A3 '"node_modules/three": {' "$lock")
version=$(sed -n 's/.*"version": "\([^"]*\)".*/\1/p' <<< "$entry")
integrity=$(sed -n 's/.*"integrity": "sha512-\([^"]*\)".*/\1/p' <<< "$entry")
if [ -z "$version" ] || [ -z "$integrity" ]; then
  echo "ci/install-three.sh: $lock locks no version and sha512 of three" >&2
  exit 2
fi
if [ -f "$dir/package/package.json" ] && grep -q "\"version\": \"$version\"" "$dir/package/package.json"; then
  exit 0
fi
if ! command -v curl > /dev/null; then bash ci/install-deps.sh curl; fi
registry=$(npm config get registry 2> /dev/null || echo https://registry.npmjs.org/)
url="${registry%/}/three/-/three-$version.tgz"
echo "ci/install-three.sh: fetching three $version for report.html's 3D view"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
if ! curl -fsS --retry 3 -o "$tmp/three.tgz" "$url"; then
  echo "ci/install-three.sh: warning: could not fetch $url; report.html will have no 3D view" >&2
  exit 0
fi
got=$(sha512sum "$tmp/three.tgz" | cut -d' ' -f1 | tr a-f A-F | basenc --base16 -d | base64 -w0)
if [ "$got" != "$integrity" ]; then
  echo "ci/install-three.sh: $url: sha512 $got, but $lock locks $integrity" >&2
  exit 1
fi
mkdir -p "$tmp/x"
tar -xzf "$tmp/three.tgz" -C "$tmp/x" package/package.json package/LICENSE \
  package/build/three.core.min.js package/build/three.module.min.js \
  package/examples/jsm/controls/OrbitControls.js
rm -rf "$dir"
mkdir -p "$(dirname "$dir")"
mv "$tmp/x" "$dir"
