#!/usr/bin/env bash
# Simulates a one-sweep tank, exports it as .npz and runs docs/dataset-format.md's Python example
# on it as written; then checks the arrays against the dataset's own files.
#   tests/docs/test_npz_example.sh SOURCE_DIR SONARBENCH_BINARY
set -euo pipefail
SB="$(cd "$1" && pwd)"
SONARBENCH="$(realpath "$2")"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# Debian's python3 (python3-numpy, python3-matplotlib), or any python3 that has them.
python=""
for p in python3 /usr/bin/python3; do
  if "$p" -c 'import numpy, matplotlib' 2>/dev/null; then python="$p"; break; fi
done
test -n "$python" || { echo "no python3 with numpy and matplotlib (ci/install-deps.sh)" >&2; exit 1; }
awk '/<!-- npz-example:/ {on = 1; next} on && /^```python/ {inside = 1; next}
     inside && /^```/ {exit} inside {print}' "$SB/docs/dataset-format.md" > "$work/example.py"
test -s "$work/example.py" || { echo "no npz example in docs/dataset-format.md" >&2; exit 1; }
cd "$work"
printf 'name: tank\nextends: %s\nsweeps: 1\n' "$SB/scenes/cras-tank.yaml" > tank.yaml
"$SONARBENCH" simulate tank.yaml --out ds --no-progress > /dev/null
"$SONARBENCH" export ds --out tank.npz > /dev/null
"$python" example.py | tee example.out
test -s labels.png
grep -q "direct: dominates" example.out
"$python" - <<'PY'
import json, struct
import numpy as np
d = np.load("tank.npz")
manifest = json.load(open("ds/manifest.json"))
raw = open("ds/beams/sweep_0000.bin", "rb").read()
count, = struct.unpack_from("<I", raw, 8)
at = 12
for b in range(count):
    t, head, _, bins = struct.unpack_from("<dddI", raw, at)
    at += 28
    assert bytes(d["intensities"][0, b, :bins]) == raw[at:at + bins], b
    assert d["time_s"][0, b] == t and d["head_angle_rad"][0, b] == head, b
    at += bins
shares, mesh, point = d["label_shares"], d["label_mesh"], d["label_point_sonar_m"]
assert (shares.sum(axis=-1, dtype=int) == 255).all()
assert list(d["mesh_names"]) == manifest["meshes"]
assert list(d["label_paths"]) == manifest["truth"]["paths"]
has = mesh != 65535
assert (mesh[has] < len(manifest["meshes"])).all()
assert np.isnan(point[~has]).all() and np.isfinite(point[has]).all()
pose = np.loadtxt("ds/poses/sonar.tum")
assert np.allclose(d["sonar_pose"][0], pose[:, 1:], atol=1e-6)
print(f"npz agrees with the dataset: {count} beams, {has.sum()} direct bins")
PY
