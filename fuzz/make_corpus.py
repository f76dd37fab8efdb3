#!/usr/bin/env python3
"""Writes the harnesses' seed corpora and YAML dictionaries from the shipped files.

Usage: fuzz/make_corpus.py [DATASET]   (run from anywhere; writes fuzz/corpus/ and fuzz/dict/)

The OctoMap seeds are small trees written in both formats here, byte for byte as OctoMap would;
the ROS 2 bag seeds are small MCAP files written here record by record (docs/ros2.md); the
label file seed is written here and compressed by the zstd command.
DATASET is a folder `sonarbench simulate` wrote; its manifest, first beams and poses seed the
dataset harness, cut to a few beams. The .mat seeds (the real log's first beams) are written by
libmatio and kept as they are. Files a harness found are kept in the corpus beside these.
"""
import hashlib
import json
import math
import pathlib
import re
import struct
import subprocess
import sys
import zlib

import yaml

ROOT = pathlib.Path(__file__).resolve().parent.parent
CORPUS = ROOT / "fuzz" / "corpus"
DICT = ROOT / "fuzz" / "dict"


def write(path, data):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(data if isinstance(data, bytes) else data.encode())


def yaml_keys(paths):
    keys = set()
    for path in paths:
        for line in path.read_text().splitlines():
            m = re.match(r"^\s*(?:-\s+)?([A-Za-z_][A-Za-z0-9_.]*):", line)
            if m:
                keys.add(m.group(1))
    return sorted(keys)


def scenes():
    files = sorted((ROOT / "scenes").glob("*.yaml"))
    for f in files:
        write(CORPUS / "scene" / f.name, f.read_bytes())
    for f in sorted((ROOT / "sensor-models").glob("*.yaml")):
        write(CORPUS / "sensor_model" / f.name, f.read_bytes())
    for f in files:
        criteria = yaml.safe_load(f.read_text()).get("criteria")
        if criteria:
            write(CORPUS / "criteria" / f.name, yaml.safe_dump(criteria, sort_keys=False))
    yamls = files + sorted((ROOT / "sensor-models").glob("*.yaml"))
    words = yaml_keys(yamls) + ["extends", "file", "pass", "fail", "min", "max", "optional",
                                "acceptable_min", "acceptable_max", "true", "false", "null",
                                "~", "[]", "{}", "&a", "*a", "<<", "!!str", ".nan", ".inf"]
    text = "".join('"%s"\n' % w.replace("\\", "\\\\").replace('"', '\\"') for w in words)
    write(DICT / "yaml.dict", text)


def meshes():
    prefixes = {".ply": 0, ".dae": 1, ".obj": 2, ".stl": 3}
    for f in sorted((ROOT / "scenes" / "meshes").iterdir()):
        if f.suffix in prefixes:
            write(CORPUS / "mesh" / f.name, bytes([prefixes[f.suffix]]) + f.read_bytes())


def beam_file(beams):
    out = b"SBBEAMS1" + struct.pack("<I", len(beams))
    for time_s, angle, bin_size, data in beams:
        out += struct.pack("<dddI", time_s, angle, bin_size, len(data)) + bytes(data)
    return out


def dataset(folder):
    folder = pathlib.Path(folder)
    manifest = json.loads((folder / "manifest.json").read_text())
    raw = (folder / "beams" / "sweep_0000.bin").read_bytes()
    count = struct.unpack_from("<I", raw, 8)[0]
    beams, at = [], 12
    for _ in range(min(count, 3)):
        time_s, angle, bin_size, n = struct.unpack_from("<dddI", raw, at)
        at += 28
        beams.append((time_s, angle, bin_size, raw[at:at + n]))
        at += n
    bins = beam_file(beams)
    poses = "".join((folder / "poses" / "sonar.tum").read_text().splitlines(True)[:len(beams)])
    manifest["scene"]["file"] = "scenes/" + pathlib.Path(manifest["scene"]["file"]).name
    manifest["sweeps"] = 1
    manifest["beams"] = len(beams)
    listed = dict(manifest, files=[
        {"path": "beams/sweep_0000.bin", "bytes": len(bins),
         "sha256": hashlib.sha256(bins).hexdigest()},
        {"path": "poses/sonar.tum", "bytes": len(poses),
         "sha256": hashlib.sha256(poses.encode()).hexdigest()}])
    for name, m in (("listed", listed), ("unlisted", dict(manifest, files=[]))):
        text = json.dumps(m, indent=1).encode()
        write(CORPUS / "dataset" / name,
              text + b"\n@@beams/sweep_0000.bin\n" + bins + b"\n@@poses/sonar.tum\n" +
              poses.encode())


def octree_files(leaves, resolution="0.05"):
    """.bt and .ot bytes of an OcTree whose depth-16 leaves are `leaves` {(x, y, z): occupied}."""
    def child(key, depth):
        bit = 15 - depth
        return ((key[0] >> bit) & 1) | (((key[1] >> bit) & 1) << 1) | (((key[2] >> bit) & 1) << 2)

    def build(keys, depth):  # a node: None for a leaf, else {child index: node}
        if depth == 16:
            return None
        groups = {}
        for k in keys:
            groups.setdefault(child(k, depth), []).append(k)
        return {i: build(g, depth + 1) for i, g in sorted(groups.items())}

    def occupied(keys):
        return any(leaves[k] for k in keys)

    def binary(node, keys, depth):
        codes, inner = [0] * 8, []
        for i, sub in node.items():
            mine = [k for k in keys if child(k, depth) == i]
            codes[i] = 3 if sub is not None else (2 if leaves[mine[0]] else 1)  # 2 occupied, 1 free
            if sub is not None:
                inner.append((sub, mine))
        out = bytes([sum(codes[i] << (2 * i) for i in range(4)),
                     sum(codes[4 + i] << (2 * i) for i in range(4))])
        for sub, mine in inner:
            out += binary(sub, mine, depth + 1)
        return out

    def full(node, keys, depth):
        value = 0.85 if occupied(keys) else -0.4
        if node is None:
            return struct.pack("<fB", value, 0)
        out = struct.pack("<fB", value, sum(1 << i for i in node))
        for i, sub in node.items():
            out += full(sub, [k for k in keys if child(k, depth) == i], depth + 1)
        return out

    def count(node):
        return 1 + (sum(count(n) for n in node.values()) if node else 0)

    keys = sorted(leaves)
    root = build(keys, 0)
    head = "id OcTree\nsize %d\nres %s\ndata\n" % (count(root), resolution)
    return (b"# Octomap OcTree binary file\n" + head.encode() + binary(root, keys, 0),
            b"# Octomap OcTree file\n" + head.encode() + full(root, keys, 0))


def octrees():
    c = 32768
    wall = {(c + 40, c + y, c + z): True for y in range(-3, 3) for z in range(-2, 2)}
    wall.update({(c + x, c + y, c + z): False for x in range(36, 40) for y in (0, 1) for z in (0,)})
    for name, leaves in (("wall", wall), ("one_cell", {(c, c, c): True})):
        bt, ot = octree_files(leaves)
        write(CORPUS / "octomap" / (name + ".bt"), bt)
        write(CORPUS / "octomap" / (name + ".ot"), ot)


def cdr(*fields):
    """CDR little-endian bytes of (format, value) fields, each aligned to its size."""
    out = bytearray(b"\x00\x01\x00\x00")
    for fmt, value in fields:
        if fmt == "s":
            data = value.encode() + b"\x00"
            fields_out = struct.pack("<I", len(data)) + data
            size = 4
        elif fmt == "B*":
            fields_out = struct.pack("<I", len(value)) + bytes(value)
            size = 4
        else:
            fields_out = struct.pack("<" + fmt, value)
            size = struct.calcsize(fmt)
        while (len(out) - 4) % size:
            out += b"\x00"
        out += fields_out
    return bytes(out)


def header(sec, frame):
    return [("i", sec), ("I", 0), ("s", frame)]


def sonar_image(sec, angle, bins):
    fields = header(sec, "sonar") + [("f", 0.0), ("f", 1500.0), ("I", 1), ("f", 35 * math.pi / 180),
                                     ("I", 1), ("f", 3 * math.pi / 180), ("I", 1),
                                     ("d", math.cos(angle)), ("d", math.sin(angle)), ("d", 0.0),
                                     ("I", len(bins))]
    fields += [("f", (k + 0.5) * 0.012531) for k in range(len(bins))]
    return cdr(*fields, ("B", 0), ("I", 0), ("I", 1), ("B*", bins))


def tf_message(sec, parent, child, x):
    return cdr(("I", 1), *header(sec, parent), ("s", child), ("d", x), ("d", 0.0), ("d", 0.0),
               ("d", 0.0), ("d", 0.0), ("d", 0.0), ("d", 1.0))


def mcap(records_of_data, chunked):
    """An MCAP file: header, schemas and channels, messages (in one chunk or not), a summary."""
    def record(op, body):
        return struct.pack("<BQ", op, len(body)) + body

    def string(text):
        data = text.encode() if isinstance(text, str) else text
        return struct.pack("<I", len(data)) + data

    schemas = [(1, "marine_acoustic_msgs/msg/ProjectedSonarImage"), (2, "tf2_msgs/msg/TFMessage")]
    channels = [(1, 1, "/sonar/image"), (2, 2, "/tf"), (3, 2, "/tf_static")]
    head = b"\x89MCAP0\r\n" + record(1, string("ros2") + string("make_corpus.py"))
    meta = b"".join(record(3, struct.pack("<H", i) + string(n) + string("ros2msg") + string(""))
                    for i, n in schemas)
    meta += b"".join(record(4, struct.pack("<HH", i, s) + string(t) + string("cdr") + string(b""))
                     for i, s, t in channels)
    messages = b"".join(record(5, struct.pack("<HIQQ", ch, 0, t, t) + data)
                        for ch, t, data in records_of_data)
    if chunked:
        times = [t for _, t, _ in records_of_data]
        body = struct.pack("<QQQI", min(times), max(times), len(messages), zlib.crc32(messages))
        messages = record(6, body + string("") + struct.pack("<Q", len(messages)) + messages)
    data = head + meta + messages + record(15, struct.pack("<I", 0))
    summary_start = len(data)
    summary = meta + record(11, struct.pack("<QHIIIIQQ", len(records_of_data), 2, 3, 0, 0,
                                            int(chunked), 0, 0) + string(b""))
    footer = struct.pack("<BQQQ", 2, 20, summary_start, 0)
    crc = zlib.crc32(summary + footer)
    return data + summary + footer + struct.pack("<I", crc) + b"\x89MCAP0\r\n"


def bags():
    second = 1000000000
    messages = [(3, 0, tf_message(0, "base_link", "sonar", 0.2))]
    for b in range(3):
        messages.append((2, b * second, tf_message(b, "map", "base_link", 0.1 * b)))
        messages.append((1, b * second, sonar_image(b, 0.9 * b, [(b * 40 + k * 9) % 256
                                                                for k in range(12)])))
    write(CORPUS / "rosbag" / "chunked.mcap", mcap(messages, True))
    write(CORPUS / "rosbag" / "flat.mcap", mcap(messages, False))


def label_beam(bins, meshes):
    """One beam of a label file (docs/dataset-format.md): shares, meshes, points."""
    shares = [[200 if k % 6 == p else 0 for k in range(bins)] for p in range(6)]
    points = [k for k, m in enumerate(meshes) if m != 0xFFFF]
    out = struct.pack("<I", bins) + b"".join(bytes(row) for row in shares)
    out += b"".join(struct.pack("<H", m) for m in meshes)
    out += struct.pack("<I", len(points)) + b"".join(struct.pack("<I", k) for k in points)
    for axis in range(3):
        out += b"".join(struct.pack("<f", 0.1 * k + axis) for k in points)
    return out


def labels():
    """A label file of two beams, compressed by the zstd command (Debian's zstd package); the
    seabed's first sweep beside it is one the simulator wrote, kept as it is."""
    raw = b"SBLABEL1" + struct.pack("<II", 2, 7)
    raw += label_beam(12, [0xFFFF] * 4 + [0, 0, 1, 1] + [0xFFFF] * 4) + label_beam(0, [])
    frame = subprocess.run(["zstd", "-19", "-c"], input=raw, capture_output=True, check=True)
    write(CORPUS / "labels" / "two_beams.bin", frame.stdout)


def mapper():
    """Seeds for the mapper's harness: the bins first, then what FuzzedDataProvider draws from
    the end (resolution, detection, threshold, the beam count, each beam's geometry)."""
    bins = bytes(min(255, 40 + 200 * (k % 97 == 60)) for k in range(399))
    for name, tail in (("zeros", bytes(96)), ("ones", b"\x01" * 96), ("ramp", bytes(range(96)))):
        write(CORPUS / "mapper" / name, bins + tail)


if __name__ == "__main__":
    scenes()
    mapper()
    meshes()
    octrees()
    bags()
    labels()
    if len(sys.argv) > 1:
        dataset(sys.argv[1])
