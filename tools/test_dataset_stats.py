#!/usr/bin/env python3
"""ctest for dataset_stats.py: a dataset of known intensities gives the shares and tail it must,
and a truncated beams file is refused, naming the file."""
import os
import struct
import subprocess
import sys
import tempfile

TOOL = os.path.join(os.path.dirname(os.path.abspath(__file__)), "dataset_stats.py")
BIN_M = 0.0125
BINS = 399


def write_beams(path, beams, angles=None):
    with open(path, "wb") as f:
        f.write(b"SBBEAMS1" + struct.pack("<I", len(beams)))
        for i, intensities in enumerate(beams):
            angle = angles[i] if angles else 0.0
            f.write(struct.pack("<dddI", 0.0, angle, BIN_M, len(intensities)) + bytes(intensities))


def run(directory):
    return subprocess.run([sys.executable, TOOL, directory], capture_output=True, text=True)


def main():
    with tempfile.TemporaryDirectory() as tmp:
        os.makedirs(os.path.join(tmp, "ds", "beams"))
        # Every fourth bin 0, the rest 200: each band holds 25% zeros and 75% at 150 or more;
        # every 5-bin window holds one or two zeros, so the tail's largest mean is 4 · 200 / 5.
        beam = [0 if k % 4 == 0 else 200 for k in range(BINS)]
        write_beams(os.path.join(tmp, "ds", "beams", "sweep_0000.bin"), [beam] * 10)
        result = run(os.path.join(tmp, "ds"))
        assert result.returncode == 0, result.stderr
        out = result.stdout
        assert ": 10 beams" in out, out
        # 3.0-4.0 m holds bins 240-319: 80 bins, 20 of them at 0, mean 150.
        assert "3.0-4.0 m: mean 150.0, at 0 25.0%, at 150 or more 75.00%" in out, out
        assert "median 160, p90 160, p99 160, max 160; 100.0% of beams reach 60" in out, out
        # Ten identical beams at one angle: no spread from sweep to sweep.
        assert "at 150 or more 75.00%, sweep-to-sweep spread 0.0" in out, out

        # Two head angles, each seen by beams alternating 100 and 110 (three of each): per bin
        # the standard deviation of 100, 110, 100, 110, 100, 110 is sqrt(30), 5.5; a third angle
        # seen once counts for nothing, whatever it holds.
        os.makedirs(os.path.join(tmp, "spread", "beams"))
        beams, angles = [], []
        for sweep in range(6):
            for angle in (0.0, 0.0314159):
                beams.append([100 + 10 * (sweep % 2)] * BINS)
                angles.append(angle)
        beams.append([255] * BINS)
        angles.append(1.0)
        write_beams(os.path.join(tmp, "spread", "beams", "sweep_0000.bin"), beams, angles)
        result = run(os.path.join(tmp, "spread"))
        assert result.returncode == 0, result.stderr
        assert "3.0-4.0 m: mean 116.5, at 0 0.0%, at 150 or more 7.69%, sweep-to-sweep spread 5.5" \
            in result.stdout, result.stdout

        os.makedirs(os.path.join(tmp, "bad", "beams"))
        path = os.path.join(tmp, "bad", "beams", "sweep_0000.bin")
        write_beams(path, [beam])
        with open(path, "r+b") as f:
            f.truncate(100)
        result = run(os.path.join(tmp, "bad"))
        assert result.returncode != 0, "a truncated file was accepted"
        assert "sweep_0000.bin: beam 0 truncated" in result.stderr, result.stderr
    print("dataset_stats.py: shares, tail and a truncated file as expected")


if __name__ == "__main__":
    main()
