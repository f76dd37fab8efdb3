#!/usr/bin/env bash
# Runs the shell block of docs/scene-format.md's walkthrough, as written, in a fresh folder:
# the template scene must copy, run, change and pass as the page says.
#   tests/docs/test_scene_walkthrough.sh SOURCE_DIR SONARBENCH_BINARY
set -euo pipefail
SB="$(cd "$1" && pwd)"
SONARBENCH="$(realpath "$2")"
export SB SONARBENCH
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# The ```sh block after the walkthrough marker.
awk '/<!-- walkthrough:/ {on = 1; next} on && /^```sh/ {inside = 1; next}
     inside && /^```/ {exit} inside {print}' "$SB/docs/scene-format.md" > "$work/walkthrough.sh"
test -s "$work/walkthrough.sh" || { echo "no walkthrough block in docs/scene-format.md" >&2; exit 1; }
cd "$work"
bash -euo pipefail walkthrough.sh
grep -q '^name: my-tank' my-tank.yaml
grep -q 'size_m: \[6.0, 4.0, 2.0\]' my-tank.yaml
test -s out/my-tank/report.json
echo "walkthrough ran: $(grep -c . walkthrough.sh) lines"
