"""Shared fixtures of the Python module's tests: the source tree, the command line, small scenes.
Run by ctest (tests/CMakeLists.txt) with PYTHONPATH at the built module."""

import os
import pathlib
import struct
import subprocess

import numpy as np
import pytest

SOURCE = pathlib.Path(os.environ.get("SONARBENCH_SOURCE_DIR", pathlib.Path(__file__).parents[2]))
CLI = os.environ.get("SONARBENCH_CLI", str(SOURCE / "build/sim/sonarbench"))


def run_cli(*args, expect=(0,)):
    """Runs the sonarbench command line; returns its stdout, asserting its exit status is one of
    `expect`."""
    done = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    assert done.returncode in expect, done.stdout + done.stderr
    return done.stdout


def read_beam_file(path):
    """A dataset beam file (docs/dataset-format.md) as a list of (time, head, bin size, bytes)."""
    data = pathlib.Path(path).read_bytes()
    assert data[:8] == b"SBBEAMS1"
    (count,) = struct.unpack_from("<I", data, 8)
    at, beams = 12, []
    for _ in range(count):
        t, h, size, bins = struct.unpack_from("<dddI", data, at)
        at += 28
        beams.append((t, h, size, data[at:at + bins]))
        at += bins
    assert at == len(data)
    return beams


@pytest.fixture(scope="session")
def tank2(tmp_path_factory):
    """The tank scene, two sweeps."""
    path = tmp_path_factory.mktemp("scenes") / "tank2.yaml"
    path.write_text(f"extends: {SOURCE / 'scenes/cras-tank.yaml'}\nname: tank-two-sweeps\n"
                    "sweeps: 2\n")
    return path


@pytest.fixture(scope="session")
def tank2_dataset(tank2, tmp_path_factory):
    """`sonarbench simulate` of tank2, with labels."""
    out = tmp_path_factory.mktemp("datasets") / "tank2"
    run_cli("simulate", tank2, "--out", out)
    return out


def wall_sweep(range_m=2.0, beams=40, bins=399, bin_size_m=0.0125, intensity=200):
    """A static sonar at the origin facing a wall: every beam one echo centred at `range_m`,
    five bins long (as long as the shipped detector's smoothing window)."""
    inten = np.zeros((beams, bins), np.uint8)
    echo = int(range_m / bin_size_m)
    inten[:, echo - 2:echo + 3] = intensity
    heads = np.linspace(-0.35, 0.35, beams)
    poses = np.repeat(np.eye(4)[None], beams, axis=0)
    return inten, heads, poses, bin_size_m
