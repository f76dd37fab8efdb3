#!/usr/bin/env python3
"""Feeds sonarbench what a hostile user would, and checks it loses no data and never runs away.

    python3 tools/hostile.py build/sim/sonarbench [--sanitized] [--keep DIR]

Outputs: an import over another command's dataset, a symlinked or hard-linked lock file, an
edited marker, files named like sonarbench's temporary files, a rerun that cannot write (a file
size limit in place of a full disk), --out /. Inputs: FIFOs, devices and directories where files
go, an extends chain 2000 deep, and inputs that would exhaust memory (/dev/zero, a 16 MB scene,
100000 sweeps, a .mat and an MCAP whose compressed parts inflate past the budget, a mesh of more
triangles than --max-triangles), then every file of fuzz/corpus/ through its command. Each of
these runs under a 2 GB address-space limit (`ulimit -v 2000000`) and must exit 0, 1 or 2, never 3;
each refusal within 2 s at a peak of at most 512 MB (--sanitized: no limit, no time or peak
asserted, as AddressSanitizer reserves its shadow memory; and no corpus group: ci/test-sanitizers.sh
replays the corpus through the fuzz harnesses). Each group of cases stops at its first broken
promise; exits 1 when any group found one.
"""
import argparse
import hashlib
import json
import os
import resource
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import zlib
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
LOG = REPO / "data/cras-tank-static/dataset_static.mat"
TANK = REPO / "scenes/cras-tank.yaml"
ADDRESS_SPACE = 2_000_000 * 1024  # ulimit -v 2000000
PEAK_MB = 512
REFUSAL_S = 2.0


class Broken(Exception):
    pass


def check(condition, message):
    if not condition:
        raise Broken(message)


def sha256(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


class Runner:
    def __init__(self, sonarbench, sanitized):
        self.sonarbench = sonarbench
        self.sanitized = sanitized

    def __call__(self, *args, limit=True, file_size=None, timeout=60):
        """(exit code, stdout + stderr, seconds, peak resident MB) of one sonarbench command."""
        def limits():
            if limit and not self.sanitized:
                resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE, ADDRESS_SPACE))
            if file_size is not None:
                signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write fails with EFBIG instead
                resource.setrlimit(resource.RLIMIT_FSIZE, (file_size, file_size))
        start = time.monotonic()
        process = subprocess.Popen([self.sonarbench, *map(str, args)], stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, preexec_fn=limits)
        try:
            output, _ = process.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            process.kill()
            process.communicate()
            raise Broken(f"{' '.join(map(str, args))}: still running after {timeout} s")
        seconds = time.monotonic() - start
        # The largest of this process's children so far: `measured` runs each in a probe of its
        # own.
        peak_mb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
        return process.returncode, output.decode(errors="replace"), seconds, peak_mb


def refused(sb, what, *args, expect="", limit=True):
    """Runs a command that must be refused: exit 2 with `expect` in its message, in time."""
    code, text, seconds, _ = sb(*args, limit=limit)
    check(code == 2, f"{what}: exit {code}, expected 2: {text[-400:]}")
    check(expect in text, f"{what}: the message does not say {expect!r}: {text[-400:]}")
    return text, seconds


def measured(sb, what, *args, expect=""):
    """A refusal in its own process, so its peak is its own: exit 2, <= 2 s, <= 512 MB."""
    # RUSAGE_CHILDREN's peak is the largest of any child so far: measure in a fresh interpreter.
    probe = subprocess.run(
        [sys.executable, __file__, "--probe", *(["--sanitized"] if sb.sanitized else []),
         sb.sonarbench, "--", *map(str, args)],
        capture_output=True, text=True, timeout=120)
    check(probe.returncode == 0, f"{what}: the probe failed: {probe.stderr[-400:]}")
    result = json.loads(probe.stdout)
    code, text, seconds, peak = result["code"], result["text"], result["seconds"], result["peak"]
    check(code == 2, f"{what}: exit {code}, expected 2: {text[-400:]}")
    check(expect in text, f"{what}: the message does not say {expect!r}: {text[-400:]}")
    if not sb.sanitized:
        check(seconds <= REFUSAL_S, f"{what}: refused after {seconds:.2f} s (more than 2 s)")
        check(peak <= PEAK_MB, f"{what}: peak {peak:.0f} MB (more than {PEAK_MB} MB)")
    return seconds, peak


def short_scene(work, sweeps=1):
    scene = work / f"short-{sweeps}.yaml"
    scene.write_text(f"extends: {TANK}\nname: tank-short\nsweeps: {sweeps}\n")
    return scene


def import_over_simulate(sb, work):
    """A resume continues only the same command's same configuration."""
    scene = short_scene(work, 2)
    ds7, bag, d = work / "ds7", work / "b7.mcap", work / "D"
    for args in (("simulate", scene, "--out", ds7), ("export", ds7, "--out", bag),
                 ("simulate", scene, "--seed", 8, "--out", d)):
        code, text, _, _ = sb(*args)
        check(code == 0, f"{args[0]}: exit {code}: {text}")
    before = sha256(d / "beams/sweep_0000.bin")
    refused(sb, "import over simulate's dataset", "import", bag, "--out", d,
            expect="holds sonarbench simulate outputs that import would write")
    check(sha256(d / "beams/sweep_0000.bin") == before, "import over simulate changed its beams")
    check(json.loads((d / "manifest.json").read_text())["source"] == "simulate",
          "import over simulate changed its manifest")
    code, text, _, _ = sb("import", bag, "--out", d, "--force")
    check(code == 0, f"import --force over simulate: exit {code}: {text}")
    manifest = json.loads((d / "manifest.json").read_text())
    check(manifest["source"] == "import", "import --force did not replace the dataset")
    check(not (d / "truth").exists() or not any((d / "truth").iterdir()),
          "import --force left simulate's truth behind")
    fresh = work / "D-fresh"
    code, text, _, _ = sb("import", bag, "--out", fresh)
    check(code == 0, f"import: exit {code}: {text}")
    check(sha256(d / "beams/sweep_0000.bin") == sha256(fresh / "beams/sweep_0000.bin"),
          "import --force kept beams it did not write")
    refused(sb, "simulate over import's dataset", "simulate", scene, "--out", d,
            expect="holds sonarbench import outputs that simulate would write")
    print("import over simulate, simulate over import: refused by name, --force replaces whole")


def linked_locks(sb, work):
    """A lock file that is a link is refused: the file it names is never written."""
    scene = short_scene(work)
    run = work / "lock-run"
    code, text, _, _ = sb("run", scene, "--out", run)
    check(code in (0, 1), f"run: exit {code}: {text}")
    commands = {
        "simulate": lambda o: ("simulate", scene, "--out", o),
        "run": lambda o: ("run", scene, "--out", o),
        "import": lambda o: ("import", LOG, "--out", o),
        "sweep": lambda o: ("sweep", scene, "--out", o, "--sweeps", 1, "--coverage-beams", 2),
        "score": lambda o: ("score", run / "map.bt", "--scene", scene, "--out", o),
        "map": lambda o: ("map", LOG, "--out", o),
        "fidelity": lambda o: ("fidelity", scene, LOG, "--out", o),
    }
    for name, args in commands.items():
        for kind in ("symlink", "hard link", "dangling symlink"):
            out = work / f"lock-{name}-{kind.replace(' ', '-')}"
            out.mkdir()
            precious = work / f"precious-{name}-{kind.replace(' ', '-')}.txt"
            if kind == "dangling symlink":
                os.symlink(precious, out / ".sonarbench.lock")
            else:
                precious.write_text("precious\n")
                (os.symlink if kind == "symlink" else os.link)(precious, out / ".sonarbench.lock")
            refused(sb, f"{name} with a {kind} as its lock", *args(out),
                    expect="symlink" if "symlink" in kind else "hard link")
            if kind == "dangling symlink":
                check(not precious.exists(), f"{name}: a dangling lock link made its target")
            else:
                check(precious.read_text() == "precious\n", f"{name}: the {kind}'s file changed")
    print(f"linked lock files: {len(commands)} commands x symlink, hard link, dangling symlink "
          "refused, the files they name untouched")


def special_files(sb, work):
    """FIFOs, devices and directories where a file goes: refused by type, never waited on."""
    fifo = work / "fifo"
    os.mkfifo(fifo)
    folder = work / "a-folder"
    folder.mkdir()
    scene = short_scene(work)

    def scene_with(text, name):
        path = work / f"{name}.yaml"
        path.write_text(text)
        return path

    tank = TANK.read_text().replace("sensor_model: ../sensor-models/shad-micron.yaml",
                                    f"sensor_model: {fifo}")
    check(str(fifo) in tank, "scenes/cras-tank.yaml names its sensor model otherwise")
    sensor = scene_with(tank, "fifo-sensor")
    extends = scene_with(f"extends: {fifo}\nname: e\n", "fifo-extends")
    cases = [("a FIFO as the scene", ("simulate", fifo, "--out", work / "f1"), "is a FIFO"),
             ("a FIFO as the sensor model", ("simulate", sensor, "--out", work / "f2"), "is a FIFO"),
             ("a FIFO as extends", ("simulate", extends, "--out", work / "f3"), "is a FIFO"),
             ("a FIFO to import", ("import", fifo, "--out", work / "f4"), "is a FIFO"),
             ("a FIFO to map", ("map", fifo, "--out", work / "f5"), "is a FIFO"),
             ("a FIFO as --mapping", ("map", LOG, "--sensor", REPO / "sensor-models/shad-micron.yaml",
                                      "--mapping", fifo, "--out", work / "f6"), "is a FIFO"),
             ("a FIFO as import's --sensor", ("import", LOG, "--sensor", fifo, "--out", work / "f7"),
              "is a FIFO"),
             ("/dev/zero as the scene", ("simulate", "/dev/zero", "--out", work / "f8"),
              "is a character device"),
             ("a FIFO to score", ("score", fifo, "--scene", TANK, "--out", work / "f9"),
              "is a FIFO")]
    for what, path, expect in (("a FIFO", fifo, "is a FIFO"), ("a directory", folder,
                                                               "is a directory"),
                               ("/dev/zero", "/dev/zero", "is a character device")):
        mesh = scene_with(f"extends: {scene}\nname: m\nmeshes:\n  - {{name: rock, type: file, "
                          f"file: {path}, material: tank_wall}}\n", f"mesh-{len(cases)}")
        cases.append((f"{what} as a mesh file", ("simulate", mesh, "--out", work / f"m{len(cases)}"),
                      expect))
    for what, args, expect in cases:
        text, _ = refused(sb, what, *args, expect=expect)
        check("no such mesh file" not in text, f"{what}: reported as missing: {text}")
    # A dataset whose poses file is a FIFO (the manifest lists it not): refused, never waited on.
    dataset = work / "fifo-dataset"
    code, text, _, _ = sb("simulate", scene, "--out", dataset)
    check(code == 0, f"simulate: {text}")
    manifest = json.loads((dataset / "manifest.json").read_text())
    manifest["files"] = [f for f in manifest["files"] if f["path"] != "poses/sonar.tum"]
    (dataset / "manifest.json").write_text(json.dumps(manifest))
    (dataset / "poses/sonar.tum").unlink()
    os.mkfifo(dataset / "poses/sonar.tum")
    refused(sb, "a FIFO as a dataset's poses", "map", dataset, "--out", work / "f10",
            expect="is a FIFO")
    # A chain of extends deeper than any scene needs says so.
    chain = work / "chain"
    chain.mkdir()
    (chain / "s1999.yaml").write_text(f"extends: {scene}\nname: s1999\n")
    for i in range(1998, -1, -1):
        (chain / f"s{i}.yaml").write_text(f"extends: s{i + 1}.yaml\nname: s{i}\n")
    refused(sb, "an extends chain 2000 deep", "simulate", chain / "s0.yaml", "--out", work / "c",
            expect="expected at most 8 scenes extending one another")
    refused(sb, "--out /", "simulate", scene, "--out", "/", expect="is the file system's root")
    print(f"special files: {len(cases)} FIFOs, devices and folders refused by type; an extends "
          "chain 2000 deep and --out / refused by name")


def mat_bomb(path, inflated):
    """A MAT v5 file of one compressed element that inflates to `inflated` zero bytes."""
    header = b"MATLAB 5.0 MAT-file, hostile".ljust(116, b" ") + b"\0" * 8 + b"\x00\x01IM"
    packer = zlib.compressobj(9)
    chunk = b"\0" * (1 << 20)
    body = b"".join(packer.compress(chunk) for _ in range(inflated >> 20)) + packer.flush()
    path.write_bytes(header + struct.pack("<II", 15, len(body)) + body)


def mcap_bomb(path, declared):
    """An MCAP file whose one zstd chunk says it holds `declared` bytes uncompressed."""
    def record(op, body):
        return bytes([op]) + struct.pack("<Q", len(body)) + body

    def string(text):
        return struct.pack("<I", len(text)) + text
    magic = b"\x89MCAP0\r\n"
    payload = b"\x28\xb5\x2f\xfd" + b"\0" * 64
    chunk = (struct.pack("<QQQI", 0, 0, declared, 0) + string(b"zstd") +
             struct.pack("<Q", len(payload)) + payload)
    footer = struct.pack("<QQI", 0, 0, 0)
    path.write_bytes(magic + record(1, string(b"") + string(b"hostile")) + record(6, chunk) +
                     record(2, footer) + magic)


def memory_bombs(sb, work):
    """Inputs that would exhaust the machine: refused before the allocation."""
    def scene_with(text, name):
        path = work / f"{name}.yaml"
        path.write_text(text)
        return path
    big = work / "big.yaml"
    with big.open("w") as out:
        out.write(f"extends: {TANK}\nname: big\n")
        line = "# " + "x" * 77 + "\n"
        out.write(line * (16 * 1024 * 1024 // len(line)))
    obj = work / "many.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n" + "f 1 2 3\n" * 500_000)
    mat_bomb(work / "bomb.mat", 512 << 20)
    mcap_bomb(work / "bomb.mcap", 3 << 30)
    sensor = REPO / "sensor-models/shad-micron.yaml"
    cases = [
        ("extends: /dev/zero", ("simulate", scene_with("extends: /dev/zero\nname: z\n", "zero"),
                                "--out", work / "b1"), "is a character device"),
        ("the scene /dev/urandom", ("simulate", "/dev/urandom", "--out", work / "b2"),
         "is a character device"),
        ("the sensor model /dev/zero", ("import", LOG, "--sensor", "/dev/zero", "--out",
                                        work / "b3"), "is a character device"),
        ("--mapping /dev/zero", ("map", LOG, "--sensor", sensor, "--mapping", "/dev/zero", "--out",
                                 work / "b4"), "is a character device"),
        ("a 16 MB scene", ("simulate", big, "--out", work / "b5"), "more than the 2 MiB"),
        ("sweeps: 100000", ("run", scene_with(f"extends: {TANK}\nname: s\nsweeps: 100000\n",
                                               "sweeps"), "--out", work / "b6"), "--max-beams"),
        (".mat inflating to 512 MiB", ("import", work / "bomb.mat", "--out", work / "b7"),
         "inflate to more than"),
        ("MCAP chunk of 3 GiB", ("import", work / "bomb.mcap", "--out", work / "b8"),
         "3 GiB uncompressed"),
        ("500k triangles, --max-triangles 1e5",
         ("simulate", scene_with(f"extends: {TANK}\nname: o\nmeshes:\n  - {{name: many, type: "
                                 f"file, file: {obj}, material: tank_wall}}\n", "many"),
          "--max-triangles", "1e5", "--out", work / "b9"), "more than the 1e+05"),
    ]
    worst = (0.0, 0.0)
    for what, args, expect in cases:
        seconds, peak = measured(sb, what, *args, expect=expect)
        worst = (max(worst[0], seconds), max(worst[1], peak))
        for out in work.glob("b[0-9]"):
            # A run that broke leaves its junit.xml holding the error, and nothing else.
            left = sorted(p.name for p in out.iterdir() if not p.name.startswith(".sonarbench"))
            check(args[0] == "run" and left == ["junit.xml"], f"{what}: left {out} behind")
            shutil.rmtree(out)
    print(f"memory: {len(cases)} inputs that would exhaust the machine refused under ulimit -v "
          f"2000000, the slowest in {worst[0]:.2f} s, the largest peak {worst[1]:.0f} MB")


def corpus(sb, work):
    """Every fuzz corpus input through its command: never exit 3."""
    scenes = work / "corpus-scenes"
    shutil.copytree(REPO / "scenes", scenes / "scenes")
    shutil.copytree(REPO / "sensor-models", scenes / "sensor-models")
    run = work / "corpus-map"
    code, text, _, _ = sb("run", short_scene(work), "--out", run)
    check(code in (0, 1), f"run: {text}")
    count = 0
    for path in sorted((REPO / "fuzz/corpus").glob("*/*")):
        kind = path.parent.name
        out = work / f"corpus-out-{count}"
        if kind in ("scene", "criteria"):
            copy = scenes / "scenes" / f"fuzzed-{count}.yaml"
            shutil.copy(path, copy)
            args = ("simulate", copy, "--max-beams", 400, "--out", out)
        elif kind == "sensor_model":
            args = ("import", LOG, "--sensor", path, "--out", out)
        elif kind in ("mat_log", "rosbag"):
            args = ("import", path, "--out", out)
        elif kind == "mesh":
            mesh = scenes / f"mesh-{count}{path.suffix}"
            shutil.copy(path, mesh)
            scene = scenes / f"mesh-{count}.yaml"
            scene.write_text(f"extends: {TANK}\nname: m\nsweeps: 1\nmeshes:\n  - {{name: x, "
                             f"type: file, file: {mesh}, material: tank_wall}}\n")
            args = ("simulate", scene, "--out", out)
        elif kind == "octomap":
            args = ("score", path, "--scene", TANK, "--out", out)
        elif kind in ("labels", "mapper"):
            continue  # no command reads these alone: their harnesses replay them (CI)
        else:  # dataset: the harness's sections, laid out as a folder
            folder = work / f"corpus-dataset-{count}"
            lay_out_dataset(path.read_bytes(), folder)
            args = ("map", folder, "--out", out)
        code, text, _, _ = sb(*args)
        check(code in (0, 1, 2), f"{path.relative_to(REPO)}: exit {code}: {text[-400:]}")
        if code == 2:
            measured(sb, str(path.relative_to(REPO)), *args)
        count += 1
    print(f"corpus: {count} inputs of fuzz/corpus/ through their commands under ulimit -v "
          "2000000: none exits 3, each refusal within 2 s and 512 MB")


def lay_out_dataset(data, folder):
    """fuzz/fuzz_dataset.cpp's layout: manifest.json, then '\\n@@NAME\\n' and each file."""
    names = {"manifest.json", "beams/sweep_0000.bin", "beams/sweep_0001.bin", "poses/sonar.tum"}
    folder.mkdir(parents=True)
    name, rest = "manifest.json", data
    while True:
        marker = rest.find(b"\n@@")
        part = rest if marker < 0 else rest[:marker]
        if name in names:
            (folder / name).parent.mkdir(parents=True, exist_ok=True)
            (folder / name).write_bytes(part)
        if marker < 0:
            return
        rest = rest[marker + 3:]
        eol = rest.find(b"\n")
        eol = len(rest) if eol < 0 else eol
        name, rest = rest[:eol].decode(errors="replace"), rest[eol + 1:]


def failed_rerun_keeps_the_last_result(sb, work):
    """A rerun that cannot write (as on a full disk) leaves the last complete result whole."""
    scene = short_scene(work)
    out = work / "rerun"
    code, text, _, _ = sb("run", scene, "--out", out)
    check(code in (0, 1), f"run: {text}")
    before = {p.name: sha256(p) for p in out.iterdir() if p.is_file()}
    report = json.loads((out / "report.json").read_text())
    code, text, _, _ = sb("run", scene, "--seed", 8, "--out", out, file_size=20_000)
    check(code == 2, f"run that cannot write: exit {code}: {text[-400:]}")
    after = {p.name: sha256(p) for p in out.iterdir() if p.is_file()}
    check(after == before, f"a failed rerun changed the last result: {set(after) ^ set(before)}")
    for name, digest in report["files_sha256"].items():
        check(sha256(out / name) == digest, f"{name} is not the file report.json covers")
    check(not (out / ".sonarbench-stage").exists(), "a failed rerun left its stage")
    fresh = work / "rerun-fresh"
    code, text, _, _ = sb("run", scene, "--out", fresh, file_size=20_000)
    check(code == 2, f"a first run that cannot write: exit {code}")
    check(sorted(p.name for p in fresh.iterdir() if not p.name.startswith(".sonarbench")) ==
          ["junit.xml"], "a first run that cannot write left more than its junit.xml")
    # Files named as sonarbench names its temporary files, of no sonarbench writer, stay.
    (out / "report.json.tmp.99").write_text("the user's")
    (out / "map.bt.tmp.4242").write_text("the user's too")
    code, text, _, _ = sb("run", scene, "--out", out)
    check(code in (0, 1), f"run: {text}")
    check((out / "report.json.tmp.99").read_text() == "the user's" and
          (out / "map.bt.tmp.4242").read_text() == "the user's too",
          "a run removed files of the user's named like its temporary files")
    print("a rerun that cannot write leaves the last complete result byte for byte; a first one "
          "leaves only junit.xml; files named like temporaries of no writer stay")


def probe(sonarbench, sanitized, args):
    code, text, seconds, peak = Runner(sonarbench, sanitized)(*args)
    print(json.dumps({"code": code, "text": text, "seconds": seconds, "peak": peak}))
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sonarbench")
    parser.add_argument("--sanitized", action="store_true")
    parser.add_argument("--keep", help="work in this directory and keep it")
    parser.add_argument("--probe", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("args", nargs="*")
    args = parser.parse_args()
    if args.probe:
        return probe(args.sonarbench, args.sanitized, args.args)
    cases = [import_over_simulate, linked_locks, special_files, memory_bombs,
             failed_rerun_keeps_the_last_result]
    if not args.sanitized:
        cases.append(corpus)
    return run_groups("hostile", cases, args)


def run_groups(name, cases, args):
    """Runs each group of cases in a work folder (--keep's, or a temporary one): exit 1 when any
    found a broken promise, each named on stderr."""
    sb = Runner(args.sonarbench, args.sanitized)
    work = Path(args.keep or tempfile.mkdtemp(prefix=f"sonarbench-{name.replace(' ', '-')}-"))
    work.mkdir(parents=True, exist_ok=True)
    broken = 0
    try:
        for case in cases:
            try:
                case(sb, work)
            except Broken as why:
                print(f"BROKEN: {case.__name__}: {why}", file=sys.stderr)
                broken += 1
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    if broken:
        return 1
    print(f"{name}: every check held")
    return 0


if __name__ == "__main__":
    sys.exit(main())
