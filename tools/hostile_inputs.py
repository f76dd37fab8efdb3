#!/usr/bin/env python3
"""What a hostile user feeds sonarbench beside its outputs, and sizes no reader may trust.

    python3 tools/hostile_inputs.py build/sim/sonarbench [--sanitized] [--keep DIR]

Inputs under an output's name (a sensor model, an `extends`, a mesh, `--mapping`, `--sensor`,
a log, a map, by their own path, through a symlink, through `..` and as a hard link) are refused
by every command before anything is written, and the file stays byte for byte. A resume keeps
only what its record vouches for: a truncated beam file, or a bag in an image's place, is
written again. Hostile sizes (a beam 1 m a bin, 400 000 bins, a matrix of bins, a polygon of
30 000 corners, 100 000 bins in a sensor model, a label frame claiming 1 GB) are refused within
2 s at a peak of at most 512 MB under `ulimit -v 2000000`; names that are not UTF-8 are exit 2
with nothing written; a killed export's temporary file goes with the next export; option
values are refused in words. Exits 1 when any group found a broken promise (the checks of
tools/hostile.py: `--sanitized` asserts no time or peak).
"""
import argparse
import hashlib
import json
import os
import shutil
import struct
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from hostile import LOG, REPO, TANK, check, measured, refused, run_groups  # noqa: E402

SEABED = REPO / "scenes/seabed.yaml"
SENSOR = REPO / "sensor-models/shad-micron.yaml"


def sha256(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def small_scene(work, name="small", sweeps=2):
    scene = work / f"{name}.yaml"
    scene.write_text(f"{{name: {name}, extends: {SEABED}, sweeps: {sweeps}}}\n")
    return scene


def inputs_under_outputs(sb, work):
    """Every file a command reads, named as one of its outputs: refused, the file untouched."""
    scene = small_scene(work)
    r1 = work / "r1"
    code, text, _, _ = sb("run", scene, "--out", r1)
    check(code in (0, 1), f"run: exit {code}: {text[-300:]}")
    mapped = work / "mapped"
    code, text, _, _ = sb("map", LOG, "--out", mapped)
    check(code == 0, f"map: exit {code}: {text[-300:]}")
    obj = work / "rock.obj"
    obj.write_text("v 0 0 0\nv 0.2 0 0\nv 0 0.2 0\nv 0 0 0.2\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n")
    count = 0

    def case(what, place, content, make_scene, command):
        """`content` copied to `place` (an output of r1); the command refused; `place` intact."""
        nonlocal count
        count += 1
        shutil.copy(content, place)
        before = sha256(place)
        args = command(make_scene(place) if make_scene else place)
        refused(sb, what, *args, expect="is the input")
        check(sha256(place) == before, f"{what}: the input {place} changed")

    def with_sensor(path):
        text = TANK.read_text().replace("sensor_model: ../sensor-models/shad-micron.yaml",
                                        f"sensor_model: {path}")
        s = work / f"sensor-{count}.yaml"
        s.write_text(text.replace("extends:", "# extends:"))
        return s

    def with_extends(path):
        s = work / f"extends-{count}.yaml"
        s.write_text(f"{{name: e, extends: {path}}}\n")
        return s

    def with_mesh(path):
        s = work / f"mesh-{count}.yaml"
        s.write_text(f"extends: {scene}\nname: m\nmeshes:\n  - {{name: rock, type: file, file: "
                     f"{path}, material: rock}}\n")
        return s

    # The same file named through a symlink, through '..' and as a hard link.
    (work / "link").symlink_to(r1)
    for what, place, via in (("by its path", r1 / "polar.png", None),
                             ("through a symlink", r1 / "fan.png", work / "link/fan.png"),
                             ("through '..'", r1 / "map_top.png", r1 / "../r1/map_top.png")):
        case(f"run: the sensor model {what}", place, SENSOR,
             lambda p, via=via: with_sensor(via or p), lambda s: ("run", s, "--out", r1))
    case("run: extends", r1 / "map_side.png", scene, with_extends,
         lambda s: ("run", s, "--out", r1))
    case("run: a mesh file", r1 / "polar.png", obj, with_mesh, lambda s: ("run", s, "--out", r1))
    case("score: the scene's mesh", r1 / "polar.png", obj, with_mesh,
         lambda s: ("score", r1 / "map.bt", "--scene", s, "--out", r1))
    case("map --scene: its sensor model", mapped / "polar.png", SENSOR, with_sensor,
         lambda s: ("map", LOG, "--scene", s, "--out", mapped))
    mapping = work / "mapping.yaml"
    mapping.write_text("resolution_m: 0.05\n")
    case("map --mapping", mapped / "fan.png", mapping, None,
         lambda p: ("map", LOG, "--sensor", SENSOR, "--mapping", p, "--out", mapped))
    case("map --sensor", mapped / "map_top.png", SENSOR, None,
         lambda p: ("map", LOG, "--sensor", p, "--out", mapped))
    case("map: the log", mapped / "certainty.png", LOG, None,
         lambda p: ("map", p, "--out", mapped))
    case("score: the map", r1 / "report.html", r1 / "map.bt", None,
         lambda p: ("score", p, "--scene", scene, "--out", r1))
    # A hard link: another name for the same inode.
    count += 1
    hard = work / "hard-sensor.yaml"
    shutil.copy(SENSOR, hard)
    os.unlink(r1 / "polar.png")
    os.link(hard, r1 / "polar.png")
    refused(sb, "run: the sensor model as a hard link", "run", with_sensor(hard), "--out", r1,
            expect="is the input")
    check(hard.read_bytes() == SENSOR.read_bytes(), "a hard-linked sensor model changed")
    # import: its --sensor inside the dataset it writes.
    d = work / "imported"
    code, text, _, _ = sb("import", LOG, "--out", d)
    check(code == 0, f"import: {text[-300:]}")
    shutil.copy(SENSOR, d / "images/sweep_0000.png")
    refused(sb, "import --sensor", "import", LOG, "--sensor", d / "images/sweep_0000.png",
            "--out", d, "--force", expect="is the input")
    print(f"inputs under outputs: {count + 1} inputs of run, score, map and import refused by "
          "path, symlink, '..' and hard link; each file untouched")


def resumes_by_hash(sb, work):
    """A resume keeps a file only when its record lists it with the hash it still has."""
    scene = small_scene(work, "resume")
    whole, d = work / "whole", work / "d"
    for out in (whole, d):
        code, text, _, _ = sb("simulate", scene, "--out", out)
        check(code == 0, f"simulate: {text[-300:]}")
    bag = work / "any.mcap"
    code, text, _, _ = sb("export", whole, "--out", bag)
    check(code == 0, f"export: {text[-300:]}")
    for what, damage in (("a truncated beam file", lambda: os.truncate(d / "beams/sweep_0001.bin", 10)),
                         ("a bag in an image's place",
                          lambda: shutil.copy(bag, d / "images/sweep_0000.png")),
                         ("a YAML in a label file's place",
                          lambda: shutil.copy(SENSOR, d / "truth/labels_0001.bin"))):
        (d / "manifest.json").unlink()
        damage()
        code, text, _, _ = sb("simulate", scene, "--out", d)
        check(code == 0, f"simulate over {what}: exit {code}: {text[-300:]}")
        check("skipped 2" not in text, f"simulate over {what} kept it: {text[-300:]}")
        for f in whole.rglob("*"):
            if f.is_file() and not f.name.startswith(".sonarbench"):
                rel = f.relative_to(whole)
                check(sha256(d / rel) == sha256(f), f"after {what}: {rel} differs from a whole run")
        code, text, _, _ = sb("map", d, "--out", work / f"map-{len(what)}")
        check(code == 0, f"map after {what}: exit {code}: {text[-300:]}")
    # Under a whole manifest too: the damaged file is found and written again.
    os.truncate(d / "beams/sweep_0000.bin", 10)
    code, text, _, _ = sb("simulate", scene, "--out", d)
    check(code == 0 and "nothing to do" not in text,
          f"simulate over a damaged whole dataset: {text}")
    check(sha256(d / "beams/sweep_0000.bin") == sha256(whole / "beams/sweep_0000.bin"),
          "a damaged file under a whole manifest was kept")
    # import the same way.
    i1, i2 = work / "i1", work / "i2"
    for out in (i1, i2):
        code, text, _, _ = sb("import", LOG, "--out", out)
        check(code == 0, f"import: {text[-300:]}")
    (i2 / "manifest.json").unlink()
    os.truncate(i2 / "beams/sweep_0000.bin", 10)
    code, text, _, _ = sb("import", LOG, "--out", i2)
    check(code == 0, f"import over a truncated beam file: {text[-300:]}")
    check(sha256(i2 / "beams/sweep_0000.bin") == sha256(i1 / "beams/sweep_0000.bin"),
          "import kept a truncated beam file")
    print("resumes: a truncated beam file, a bag in an image's place, a YAML in a label file's, "
          "a damaged file under a whole manifest and an import's: written again, bytes of a whole run")


def mat_log(path, beams):
    """A MAT v5 log with `beams` (step_dist, intensities as a uint8 array of shape (r, c))."""
    def element(data_type, payload):
        pad = (-len(payload)) % 8
        return struct.pack("<II", data_type, len(payload)) + payload + b"\0" * pad

    def array(name, array_class, dims, data_type, values):
        flags = element(6, struct.pack("<II", array_class, 0))
        return (flags + element(5, struct.pack(f"<{len(dims)}i", *dims)) +
                element(1, name.encode()) + element(data_type, values))
    fields = ["time", "angle", "step_dist", "intensities"]
    body = b""
    for i, (step, shape) in enumerate(beams):
        for field in fields:
            if field == "intensities":
                n = shape[0] * shape[1]
                body += element(14, array("", 9, list(shape), 2, bytes([40] * n)))
            else:
                value = {"time": i * 0.05, "angle": i * 1.8, "step_dist": step}[field]
                body += element(14, array("", 6, [1, 1], 9, struct.pack("<d", value)))
    names = b"".join(f.encode().ljust(32, b"\0") for f in fields)
    struct_array = (element(6, struct.pack("<II", 2, 0)) +
                    element(5, struct.pack("<2i", 1, len(beams))) + element(1, b"parsedData") +
                    element(5, struct.pack("<i", 32)) + element(1, names) + body)
    header = b"MATLAB 5.0 MAT-file, hostile".ljust(116, b" ") + b"\0" * 8 + b"\x00\x01IM"
    path.write_bytes(header + element(14, struct_array))


def hostile_sizes(sb, work):
    """Sizes a reader would allocate from: refused before the allocation, in time."""
    usual = [(0.01, (1, 399))] * 200
    cases = []

    def add(what, args, expect):
        cases.append((what, args, expect))
    mat_log(work / "step.mat", usual[:100] + [(1.0, (1, 399))] + usual[101:])
    add("a .mat beam 1 m a bin", ("map", work / "step.mat", "--out", work / "s1"), "--max-cells")
    mat_log(work / "far.mat", usual[:100] + [(1e30, (1, 399))] + usual[101:])
    add("a .mat beam 1e30 m a bin", ("map", work / "far.mat", "--out", work / "s2"),
        "OctoMap's 16-bit keys")
    mat_log(work / "tenth.mat", [(0.1, (1, 399))] * 200)
    add("every bin 0.1 m", ("map", work / "tenth.mat", "--out", work / "s3"), "--max-cells")
    mat_log(work / "long.mat", usual[:5] + [(0.01, (1, 400_000))])
    add("a beam of 400 000 bins", ("import", work / "long.mat", "--out", work / "s4"),
        "expected at most 16384")
    mat_log(work / "matrix.mat", usual[:5] + [(0.01, (10, 399))])
    add("a matrix of bins", ("import", work / "matrix.mat", "--out", work / "s5"),
        "expected one row or column")
    obj = work / "polygon.obj"
    corners = 30_000
    obj.write_text("".join(f"v {i} {i % 7} 0\n" for i in range(corners)) +
                   "f " + " ".join(str(i + 1) for i in range(corners)) + "\n")
    scene = work / "polygon.yaml"
    scene.write_text(f"extends: {TANK}\nname: p\nmeshes:\n  - {{name: p, type: file, file: {obj}, "
                     "material: tank_wall}\n")
    add("an OBJ polygon of 30 000 corners", ("simulate", scene, "--out", work / "s6"),
        "expected at most 1024")
    sensor = work / "bins.yaml"
    sensor.write_text(SENSOR.read_text().replace("num_bins: 399", "num_bins: 100000"))
    check("100000" in sensor.read_text(), "the shipped sensor model names num_bins otherwise")
    add("num_bins: 100000", ("import", LOG, "--sensor", sensor, "--out", work / "s7"),
        "num_bins")
    # A dataset whose label frame claims 1 GB.
    d = work / "labels-ds"
    code, text, _, _ = sb("simulate", small_scene(work, "lab", 1), "--out", d)
    check(code == 0, f"simulate: {text[-300:]}")
    label = d / "truth/labels_0000.bin"
    # A zstd frame: the magic, a descriptor (one segment, an 8-byte content size), the size it
    # claims, then one empty raw block.
    label.write_bytes(b"\x28\xb5\x2f\xfd\xe0" + struct.pack("<Q", 1 << 30) + b"\x01\x00\x00")
    manifest = json.loads((d / "manifest.json").read_text())
    for f in manifest["files"]:
        if f["path"] == "truth/labels_0000.bin":
            f["sha256"], f["bytes"] = sha256(label), label.stat().st_size
    (d / "manifest.json").write_text(json.dumps(manifest))
    add("a label frame claiming 1 GB", ("export", d, "--out", work / "s8.npz"),
        "for the beams it labels")
    worst = (0.0, 0.0)
    for what, args, expect in cases:
        seconds, peak = measured(sb, what, *args, expect=expect)
        worst = (max(worst[0], seconds), max(worst[1], peak))
    print(f"sizes: {len(cases)} hostile sizes refused under ulimit -v 2000000, the slowest in "
          f"{worst[0]:.2f} s, the largest peak {worst[1]:.0f} MB")


def names_and_options(sb, work):
    """Names that are not UTF-8, and option values, refused in words before anything is written."""
    bad = work / "bad-name.yaml"
    bad.write_bytes(b"extends: " + bytes(SEABED) + b"\nname: caf\xff\nsweeps: 1\n")
    mesh_name = work / "bad-mesh.yaml"
    mesh_name.write_bytes(b"extends: " + bytes(SEABED) + b"\nname: m\nsweeps: 1\nmeshes:\n"
                          b"  - {name: r\xffck, type: box, size_m: [1, 1, 1], material: tank_wall}\n")
    file_name = work / os.fsdecode(b"scene-\xff.yaml")
    try:
        file_name.write_text(f"{{name: f, extends: {SEABED}, sweeps: 1}}\n")
    except (UnicodeEncodeError, OSError):
        file_name = None
    cases = [("\\xff in a scene's name", ("simulate", bad, "--out", work / "u1"), "is not UTF-8"),
             ("\\xff in a mesh's name", ("simulate", mesh_name, "--out", work / "u2"),
              "is not UTF-8")]
    if file_name is not None:
        cases.append(("\\xff in a file's name", ("simulate", file_name, "--out", work / "u3"),
                      "not UTF-8"))
    scene = small_scene(work, "opts", 1)
    cases += [
        ("--max-cells nan", ("run", scene, "--max-cells", "nan", "--out", work / "o1"),
         "expected a number above 0"),
        ("--max-beams 0", ("run", scene, "--max-beams", "0", "--out", work / "o2"),
         "expected a number above 0"),
        ("--threads abc", ("run", scene, "--threads", "abc", "--out", work / "o3"),
         "expected a whole number of threads"),
    ]
    far = work / "far.yaml"
    far.write_text(f"extends: {TANK}\nname: far\ntrajectory:\n  type: waypoints\n  waypoints:\n"
                   "    - {time_s: 0, position_m: [0, 0, 1]}\n"
                   "    - {time_s: 10, position_m: [1e308, 0, 1]}\n")
    cases.append(("a waypoint at 1e308", ("simulate", far, "--out", work / "o4"), "position_m"))
    for what, args, expect in cases:
        text, _ = refused(sb, what, *args, expect=expect)
        check(len(max(text.split(), key=len)) < 120, f"{what}: a word of over 120 characters: {text}")
        check("179769" not in text and "internal error" not in text, f"{what}: {text}")
        out = Path(args[-1])
        check(not out.exists() or all(p.name.startswith(".sonarbench") or p.name == "junit.xml"
                                      for p in out.iterdir()), f"{what}: left outputs behind")
    print(f"names and options: {len(cases)} refused in words, nothing written")


def killed_exports(sb, work):
    """A killed export's temporary file goes with the next export; a user's file so named stays."""
    d = work / "export-ds"
    code, text, _, _ = sb("simulate", small_scene(work, "exp", 1), "--out", d)
    check(code == 0, f"simulate: {text[-300:]}")
    for suffix in ("mcap", "npz"):
        out = work / f"e.{suffix}"
        process = subprocess.Popen([sb.sonarbench, "export", str(d), "--out", str(out)])
        process.wait()
        dead = [subprocess.Popen(["true"]) for _ in range(2)]
        for process in dead:
            process.wait()
        # A temporary of a writer that died: the head of a whole export under a dead pid.
        stale = work / f"e.{suffix}.tmp.{dead[0].pid}"
        stale.write_bytes(out.read_bytes()[:4096])
        users = work / f"e.{suffix}.tmp.{dead[1].pid}"
        users.write_text("the user's")
        code, text, _, _ = sb("export", d, "--out", out, "--force")
        check(code == 0, f"export --force: {text[-300:]}")
        check(not stale.exists(), f"a killed export's {stale.name} stayed")
        check(users.read_text() == "the user's", f"the user's {users.name} was touched")
    print("killed exports: their temporary files go with the next export (.mcap, .npz); the "
          "user's files so named stay")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sonarbench")
    parser.add_argument("--sanitized", action="store_true")
    parser.add_argument("--keep", help="work in this directory and keep it")
    return run_groups("hostile inputs", [inputs_under_outputs, resumes_by_hash, hostile_sizes,
                                         names_and_options, killed_exports],
                      parser.parse_args())


if __name__ == "__main__":
    sys.exit(main())
