#!/usr/bin/env python3
"""Kills sonarbench at random points while it writes, and checks what a reader would trust.

    python3 tools/torture.py build/sim/sonarbench [--trials N] [--seed S] [--keep DIR]

For `run`, `simulate`, `import` and `sweep`, each trial starts the command (into an empty
directory, or over a complete output of another seed; `import --force` over a simulated
dataset), kills it with SIGKILL at a random moment,
then checks that the record a reader trusts (report.json, manifest.json, study.json) is either
absent or whole: every file it names has the sha256 it states. For `simulate` and `import`, every
trial that resumes then truncates one of the sweeps' files the kill left. A rerun must then finish
(resuming or replacing) with the bytes of an uninterrupted run. Then: two `simulate` runs of different seeds
started at once into one directory (one configuration wins; the other exits 2 naming it), and,
where this machine lets us mount a tmpfs, a full disk and a read-only one (exit 2 with the OS's
reason, nothing trusted left behind; a rerun that fills the disk leaves the last result whole). Exits 1 on the first broken promise, 0 otherwise.
"""
import argparse
import hashlib
import json
import os
import random
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
LOG = REPO / "data/cras-tank-static/dataset_static.mat"


class Broken(Exception):
    pass


def sha256(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def check(condition, message):
    if not condition:
        raise Broken(message)


def verify_record(kind, out):
    """The record's state: None when absent, else its JSON after checking what it covers."""
    record = out / {"run": "report.json", "simulate": "manifest.json",
                    "import": "manifest.json", "sweep": "study.json"}[kind]
    if not record.exists():
        return None
    data = json.loads(record.read_text())  # a torn record fails here
    if kind == "run":
        for name, digest in data["files_sha256"].items():
            check(sha256(out / name) == digest, f"{out}/{name} is not the file report.json covers")
    elif kind in ("simulate", "import"):
        for entry in data["files"]:
            check(sha256(out / entry["path"]) == entry["sha256"],
                  f"{out}/{entry['path']} is not the file manifest.json lists")
    else:
        for item in data["items"]:
            check(item["config_sha256"] == data["config_sha256"], f"{out}: study of mixed items")
        check((out / "divisions.csv").exists(), f"{out}: study.json without divisions.csv")
    return data


def fingerprint(kind, out):
    """What must be identical between an interrupted-then-resumed run and an uninterrupted one."""
    data = verify_record(kind, out)
    check(data is not None, f"{out}: no record after a complete run")
    if kind == "run":
        return sha256(out / "map.bt"), json.dumps(data["metrics"], sort_keys=True)
    if kind == "sweep":
        # Times differ run to run; what was measured does not.
        return [(i["rays_horizontal"], i["rays_vertical"], i["map_recall"], i["beam_coverage"])
                for i in data["items"]]
    return sorted((e["path"], e["sha256"]) for e in data["files"])


def command(sonarbench, kind, scene, out, seed, force=False):
    args = {"run": ["run", scene],
            "simulate": ["simulate", scene],
            "import": ["import", str(LOG)],
            "sweep": ["sweep", scene, "--sweeps", "1", "--coverage-beams", "2"]}[kind]
    args = [sonarbench] + args + ["--out", str(out)]
    if kind != "import":
        args += ["--seed", str(seed)]
    if force and kind != "run":
        args.append("--force")
    return args


def run(args, timeout=300):
    done = subprocess.run(args, capture_output=True, text=True, timeout=timeout)
    return done.returncode, done.stdout + done.stderr


def kill_trials(sonarbench, kind, scene, work, trials, rng):
    reference = work / f"{kind}-reference"
    start = time.monotonic()
    code, text = run(command(sonarbench, kind, scene, reference, 1))
    full = time.monotonic() - start
    check(code in (0, 1), f"{kind}: the reference run failed ({code}): {text}")
    expected = fingerprint(kind, reference)
    for trial in range(trials):
        out = work / f"{kind}-{trial}"
        over_old = trial % 2 == 1
        if over_old:
            # An import replaces another command's dataset (with --force) and keeps none of it.
            old = "simulate" if kind == "import" else kind
            code, text = run(command(sonarbench, old, scene, out, 2))
            check(code in (0, 1), f"{kind}: the {old} of seed 2 failed: {text}")
        process = subprocess.Popen(command(sonarbench, kind, scene, out, 1, force=over_old),
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(rng.uniform(0.0, 1.1 * full))
        process.kill()
        process.wait()
        verify_record(kind, out)  # raises if a trusted record covers torn files
        damaged = damage_a_sweep(kind, out, rng) if not over_old else None
        code, text = run(command(sonarbench, kind, scene, out, 1, force=over_old))
        check(code in (0, 1), f"{kind} trial {trial}: the rerun failed ({code}): {text}")
        check(fingerprint(kind, out) == expected,
              f"{kind} trial {trial}: the rerun's output differs from an uninterrupted run's"
              + (f" (after {damaged} was truncated)" if damaged else ""))
    damage = (", a sweep's file truncated after each resumed kill"
              if kind in ("simulate", "import") else "")
    print(f"{kind}: {trials} kills at random points (a full run takes {full:.1f} s){damage}: "
          "every trusted record whole, every rerun identical to an uninterrupted run")


def damage_a_sweep(kind, out, rng):
    """A dataset's resume must not keep a file it cannot vouch for: one of the sweeps' files the
    killed run left, truncated to 10 bytes (its name, or None when there is none)."""
    if kind not in ("simulate", "import"):
        return None
    files = sorted(p for folder in ("beams", "images") for p in (out / folder).glob("*")
                   if p.is_file() and ".tmp." not in p.name)
    if not files:
        return None
    victim = rng.choice(files)
    os.truncate(victim, 10)
    return victim.relative_to(out)


def concurrent_writers(sonarbench, scene, work, trials):
    references = {}
    for seed in (1, 2):
        out = work / f"concurrent-reference-{seed}"
        code, text = run(command(sonarbench, "simulate", scene, out, seed))
        check(code == 0, f"simulate seed {seed} failed: {text}")
        references[seed] = fingerprint("simulate", out)
    refused = 0
    for trial in range(trials):
        out = work / f"concurrent-{trial}"
        processes = [subprocess.Popen(command(sonarbench, "simulate", scene, out, seed),
                                      stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
                     for seed in (1, 2)]
        results = [(p.wait(), p.stdout.read()) for p in processes]
        codes = sorted(code for code, _ in results)
        check(codes in ([0, 0], [0, 2]), f"concurrent trial {trial}: exit codes {codes}: {results}")
        if codes == [0, 2]:
            refused += 1
            message = next(text for code, text in results if code == 2)
            check("another sonarbench is writing here" in message or
                  "another configuration" in message, f"concurrent: unclear refusal: {message}")
        manifest = verify_record("simulate", out)
        check(manifest is not None, f"concurrent trial {trial}: no dataset")
        check(fingerprint("simulate", out) == references[manifest["seed"]],
              f"concurrent trial {trial}: the dataset is not seed {manifest['seed']}'s alone")
    print(f"concurrent: {trials} pairs of simulate with seeds 1 and 2 into one directory: "
          f"{refused} refused the second writer by name, every dataset one seed's alone")


def mount_tmpfs(path, options):
    path.mkdir(parents=True, exist_ok=True)
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(path)],
                          capture_output=True, text=True)
    return done.returncode == 0, done.stderr.strip()


def rerun_on_a_full_disk(sonarbench, scene, work):
    """A rerun that fills the disk: the last complete result stays, byte for byte."""
    reference = work / "run-reference"
    size = sum(p.stat().st_size for p in reference.rglob("*") if p.is_file())
    disk = work / "rerun-disk"
    ok, why = mount_tmpfs(disk, f"size={size * 3 // 2 // 1024 + 64}k")
    if not ok:
        print(f"rerun on a full disk: skipped: cannot mount a tmpfs here ({why})")
        return
    try:
        out = disk / "run"
        code, text = run(command(sonarbench, "run", scene, out, 1))
        check(code in (0, 1), f"run on a disk of 1.5 results: exit {code}: {text}")
        before = fingerprint("run", out)
        files = {p.name: sha256(p) for p in out.iterdir() if p.is_file()}
        code, text = run(command(sonarbench, "run", scene, out, 8))
        check(code == 2 and "No space left on device" in text,
              f"a rerun on a full disk: exit {code}: {text}")
        check(fingerprint("run", out) == before and
              {p.name: sha256(p) for p in out.iterdir() if p.is_file()} == files,
              "a rerun that filled the disk changed the last complete result")
        check(not (out / ".sonarbench-stage").exists(), "a rerun on a full disk left its stage")
        print("rerun on a full disk: exit 2 with the OS's reason, the last result byte for byte")
    finally:
        subprocess.run(["umount", str(disk)], capture_output=True)


def full_and_read_only_disks(sonarbench, scene, work):
    disk = work / "disk"
    ok, why = mount_tmpfs(disk, "size=64k")
    if not ok:
        print(f"full disk, read-only disk: skipped: cannot mount a tmpfs here ({why})")
        return
    try:
        for kind in ("simulate", "run"):
            out = disk / kind
            code, text = run(command(sonarbench, kind, scene, out, 1))
            check(code == 2 and "No space left on device" in text,
                  f"{kind} on a full disk: exit {code}: {text}")
            check(verify_record(kind, out) is None, f"{kind} on a full disk left a record")
        (disk / "existing").mkdir()
        subprocess.run(["mount", "-o", "remount,ro", str(disk)], check=True)
        start = time.monotonic()
        for out in (disk / "new", disk / "existing"):
            code, text = run(command(sonarbench, "run", scene, out, 1))
            check(code == 2 and "Read-only file system" in text,
                  f"run into {out} on a read-only disk: exit {code}: {text}")
        print(f"full disk: simulate and run exit 2 with the OS's reason and leave no record; "
              f"read-only disk: run exits 2 with the OS's reason in {time.monotonic() - start:.2f} s")
    finally:
        subprocess.run(["umount", str(disk)], capture_output=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sonarbench")
    parser.add_argument("--trials", type=int, default=4)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--keep", help="work in this directory and keep it")
    parser.add_argument("--only", nargs="*", help="run, simulate, import, sweep, concurrent, disk")
    args = parser.parse_args()
    rng = random.Random(args.seed)
    work = Path(args.keep or tempfile.mkdtemp(prefix="sonarbench-torture-"))
    work.mkdir(parents=True, exist_ok=True)
    scene = work / "short.yaml"
    scene.write_text(f"extends: {REPO / 'scenes/cras-tank.yaml'}\nname: cras-tank-short\n"
                     "sweeps: 2\n")
    try:
        for kind in ("run", "simulate", "import", "sweep"):
            if args.only and kind not in args.only:
                continue
            kill_trials(args.sonarbench, kind, str(scene), work,
                        max(2, args.trials // 2) if kind == "sweep" else args.trials, rng)
        if not args.only or "concurrent" in args.only:
            concurrent_writers(args.sonarbench, str(scene), work, args.trials * 2)
        if not args.only or "disk" in args.only:
            full_and_read_only_disks(args.sonarbench, str(scene), work)
            if (work / "run-reference").exists():
                rerun_on_a_full_disk(args.sonarbench, str(scene), work)
    except Broken as broken:
        print(f"BROKEN: {broken}", file=sys.stderr)
        return 1
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    print("torture: every check held")
    return 0


if __name__ == "__main__":
    sys.exit(main())
