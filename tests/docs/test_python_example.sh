#!/usr/bin/env bash
# Runs docs/python.md's two examples (the worked example, the data loader) as written, as if from
# the source tree (a scratch folder whose scenes/ and sensor-models/ are the tree's) with PYTHONPATH at the built
# module, and checks each prints what the doc shows below it.
#   tests/docs/test_python_example.sh SOURCE_DIR PYTHON MODULE_DIR
set -euo pipefail
SB="$(cd "$1" && pwd)"
python="$2"
export PYTHONPATH="$(cd "$3" && pwd)" PYTHONDONTWRITEBYTECODE=1
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
ln -s "$SB/scenes" "$SB/sensor-models" "$work/"
# The fenced block after the marker line `<!-- NAME` (code) or `<!-- NAME-output` (its output).
block() {
  awk -v m="<!-- $1" 'index($0, m) == 1 && (substr($0, length(m) + 1, 1) ~ /[: ]/) {on = 1; next}
       on && /^```/ && !inside {inside = 1; next}
       inside && /^```/ {exit} inside {print}' "$SB/docs/python.md"
}
for name in python-example python-loader; do
  block "$name" > "$work/$name.py"
  block "$name-output" > "$work/$name.expected"
  test -s "$work/$name.py" || { echo "docs/python.md: no '$name' block" >&2; exit 1; }
  (cd "$work" && "$python" "$name.py") > "$work/$name.out"
  diff -u "$work/$name.expected" "$work/$name.out" || {
    echo "docs/python.md: '$name' prints something else than the doc shows (diff above)" >&2
    exit 1; }
done
test -s "$work/sweep_and_labels.png"
