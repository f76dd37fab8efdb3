#!/usr/bin/env python3
"""ctest for dataset_stats.py: a dataset of known intensities gives the shares, tail and fine
texture it must, and a missing manifest or a truncated beams file is refused, naming the file."""
import json
import math
import os
import re
import struct
import subprocess
import sys
import tempfile

TOOL = os.path.join(os.path.dirname(os.path.abspath(__file__)), "dataset_stats.py")
BIN_M = 0.0125
BINS = 399


def write_beams(path, beams, angles=None):
    """Writes a beams file and, beside its beams/ folder, the manifest's sensor if none is there."""
    manifest = os.path.join(os.path.dirname(os.path.dirname(path)), "manifest.json")
    if not os.path.exists(manifest):
        with open(manifest, "w") as f:
            json.dump({"sensor": {"bin_size_m": BIN_M, "num_bins": BINS,
                                  "self_reflection_range_m": 0.35, "step_angle_deg": 1.8}}, f)
    with open(path, "wb") as f:
        f.write(b"SBBEAMS1" + struct.pack("<I", len(beams)))
        for i, intensities in enumerate(beams):
            angle = angles[i] if angles else 0.0
            f.write(struct.pack("<dddI", 0.0, angle, BIN_M, len(intensities)) + bytes(intensities))


def run(directory, *options):
    return subprocess.run([sys.executable, TOOL, directory, *options], capture_output=True,
                          text=True)


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
        # By the cell's mean: every cell from bin 32 has mean 105 and spread sqrt(30), and each
        # beam's deviations share one sign along it: correlation 1 at every lag. In the first
        # dataset no cell varies: spread 0, and no deviations to correlate.
        assert "median over cells from bin 32: 30-69 none, 70-99 none, 100-255 5.48; " \
            "the deviations of bins 1 / 2 / 3 apart (cells of mean 60 or more) correlate by " \
            "1.00 / 1.00 / 1.00" in result.stdout, result.stdout
        assert "30-69 none, 70-99 none, 100-255 0.00; the deviations of bins 1 / 2 / 3 apart " \
            "(cells of mean 60 or more) correlate by none / none / none" in out, out
        # --heads keeps the beams of one half of the sweep: the beam of 255 at 1 rad (57.3°) alone,
        # or the twelve of 0 and 1.8° without it.
        result = run(os.path.join(tmp, "spread"), "--heads", "50", "60")
        assert result.returncode == 0, result.stderr
        assert ": 1 beams" in result.stdout and "3.0-4.0 m: mean 255.0" in result.stdout, \
            result.stdout
        result = run(os.path.join(tmp, "spread"), "--heads", "0", "50")
        assert ": 12 beams" in result.stdout and "3.0-4.0 m: mean 105.0" in result.stdout, \
            result.stdout
        result = run(os.path.join(tmp, "spread"), "--heads", "180", "90")
        assert result.returncode == 2 and "expected 0 <= FROM < TO <= 360" in result.stderr, \
            result.stderr
        # A chequerboard at one angle (100 and 110 alternating along the beam and from beam to
        # beam): deviations of opposite sign in neighbouring bins, correlation -1, of the same
        # sign two bins apart, 1, and opposite again three apart, -1; at another
        # angle 40 and 50 alternating from beam to beam: cells of mean 45 in the 30-69 band.
        os.makedirs(os.path.join(tmp, "chequer", "beams"))
        beams, angles = [], []
        for sweep in range(6):
            beams.append([100 + 10 * ((sweep + k) % 2) for k in range(BINS)])
            angles.append(0.0)
            beams.append([40 + 10 * (sweep % 2)] * BINS)
            angles.append(1.0)
        write_beams(os.path.join(tmp, "chequer", "beams", "sweep_0000.bin"), beams, angles)
        result = run(os.path.join(tmp, "chequer"))
        assert result.returncode == 0, result.stderr
        assert "median over cells from bin 32: 30-69 5.48, 70-99 none, 100-255 5.48; " \
            "the deviations of bins 1 / 2 / 3 apart (cells of mean 60 or more) correlate by " \
            "-1.00 / 1.00 / -1.00" in result.stdout, result.stdout

        # Where a detector meets each side: beams at 0° (a floor-like 80 at bins 100-119, a wall
        # of 200 from bin 160), 10° (the wall from bin 170) and 90° (nothing); one at 45° belongs
        # to no side. From 1.5 m (bin 120) on, the 5-bin mean over bins k-2..k+2 first reaches
        # 100 at bin 160 (three bins of 200: 120; at 159 two, 80), 160.5 bins out; at 10°, bin
        # 170, 170.5 bins x cos 10°. The upper median of the two: 2.10 m.
        os.makedirs(os.path.join(tmp, "sides", "beams"))

        def wall_beam(first_wall_bin):
            return [80 if 100 <= k < 120 else (200 if k >= first_wall_bin else 0)
                    for k in range(BINS)]
        write_beams(os.path.join(tmp, "sides", "beams", "sweep_0000.bin"),
                    [wall_beam(160), wall_beam(170), [0] * BINS, wall_beam(100)],
                    [0.0, math.radians(10.0), math.radians(90.0), math.radians(45.0)])
        result = run(os.path.join(tmp, "sides"), "--crossing", "100", "--from", "1.5")
        assert result.returncode == 0, result.stderr
        assert ("first 5-bin mean at 100 or more from 1.5 m, median per side: 0° 2.10 m, "
                "90° none, 180° none, 270° none") in result.stdout, result.stdout
        # From 1.2 m (bin 96) at 80, the floor-like echo is met first: bin 102, whose window
        # (100-104) is all 80, 102.5 bins out at 0° and x cos 10° at 10°: 1.28 m.
        result = run(os.path.join(tmp, "sides"), "--crossing", "80", "--from", "1.2")
        assert "0° 1.28 m" in result.stdout, result.stdout
        result = run(os.path.join(tmp, "sides"), "--crossing", "100")
        assert result.returncode != 0 and "go together" in result.stderr, result.stderr

        # Bin by bin: in the first dataset bin 4 is 0 in every beam and bin 5 is 200; in the
        # second, bin 3 holds 100 six times, 110 six times and 255 once: the 10th percentile
        # (the second of 13 sorted) is 100, the mean 116.5.
        result = run(os.path.join(tmp, "ds"), "--bins", "4", "5")
        assert "  bin 4 (0.056 m): mean 0.0, at 0 100.0%, p10 0\n" \
            "  bin 5 (0.069 m): mean 200.0, at 0 0.0%, p10 200\n" in result.stdout, result.stdout
        result = run(os.path.join(tmp, "spread"), "--bins", "3", "3")
        assert "  bin 3 (0.044 m): mean 116.5, at 0 0.0%, p10 100\n" in result.stdout, \
            result.stdout
        result = run(os.path.join(tmp, "ds"), "--bins", "5", "4")
        assert result.returncode != 0 and "expected 0 <= FIRST <= LAST" in result.stderr, \
            result.stderr

        # Where half the beams are lit: of four beams at 0°, three are still 0 at bin 100
        # (share 0.75) and one at 101 (0.25): half at 100.5. Four at 90° are 0 up to bin 109
        # and lit from 110: 109.5. Two at 200° stay dark: none. All ten: 0.6 from bin 102 to
        # 109 and 0.2 at 110: 109.25.
        os.makedirs(os.path.join(tmp, "lit", "beams"))

        def ring_beam(first_lit_bin):
            return [0 if k < first_lit_bin else 30 for k in range(BINS)]
        lit_beams = [ring_beam(b) for b in (100, 101, 101, 102, 110, 110, 110, 110, BINS, BINS)]
        lit_angles = [0.0] * 4 + [math.radians(90.0)] * 4 + [math.radians(200.0)] * 2
        write_beams(os.path.join(tmp, "lit", "beams", "sweep_0000.bin"), lit_beams, lit_angles)
        result = run(os.path.join(tmp, "lit"), "--lit", "90", "130")
        assert result.returncode == 0, result.stderr
        assert "half the beams lit from bin (searched 90-130): all 109.25, 0° 100.50, " \
            "90° 109.50, 180° none\n" in result.stdout, result.stdout
        result = run(os.path.join(tmp, "lit"), "--lit", "130", "130")
        assert result.returncode != 0 and "expected 0 <= FIRST < LAST" in result.stderr, \
            result.stderr

        # A point echo's arc: beams at head steps 0-10 (1.8° apart), two sweeps; a point at bin
        # 150 heard at 200 by the beams within two steps of 9° (step 5), the second sweep's at bin
        # 152 (within the 2 bins searched) and at 100: their means 150. Steps 0-2 and 8-10 hear
        # nothing there (0; their bins 140 and 160 at 255 lie outside the 2 bins searched), and
        # there are no beams before step 0 or past step 10 (offsets past ±9°: none).
        os.makedirs(os.path.join(tmp, "arc", "beams"))

        def point_beam(step, sweep):
            b = [0] * BINS
            b[140] = b[160] = 255
            if abs(step - 5) <= 2:
                b[150 + 2 * sweep] = 200 if sweep == 0 else 100
            return b
        arc_beams = [point_beam(k, s) for s in (0, 1) for k in range(11)]
        arc_angles = [math.radians(1.8 * k) for s in (0, 1) for k in range(11)]
        write_beams(os.path.join(tmp, "arc", "beams", "sweep_0000.bin"), arc_beams, arc_angles)
        result = run(os.path.join(tmp, "arc"), "--arc", "9", "150")
        assert result.returncode == 0, result.stderr
        assert "arc at bin 150 around 9° (head offset [deg]: mean of the largest within 2 bins): " \
            "-21.6 none, " in result.stdout, result.stdout
        assert "-10.8 none, -9.0 0, -7.2 0, -5.4 0, -3.6 150, -1.8 150, +0.0 150, +1.8 150, " \
            "+3.6 150, +5.4 0, +7.2 0, +9.0 0, +10.8 none, " in result.stdout, result.stdout
        # Its summary: the peak, 150, at the steps -3.6..+3.6, the nearest the centre taken; the
        # steps within 20 of it those five; ±10.8° and ±21.6° have no beams.
        assert "its peak 150 at +0.0°; within 20 of it from -3.6° to +3.6°; at -21.6° none, " \
            "at -10.8° none, at +10.8° none, at +21.6° none" in result.stdout, result.stdout
        result = run(os.path.join(tmp, "arc"), "--arc", "9", "150.5")
        assert result.returncode != 0 and "expected BIN a whole number" in result.stderr, \
            result.stderr

        # Behind the walls: head angles 0° and 92° (0-5° off the sides' normals) and 40° and 41°
        # (40-45°). At 0° a peak of 200 at bin 100, then 50 over bins 110-129, 30 over 130-169
        # and 20 over 170-229; at 92° a peak of 220 and nothing after it; at 40° a peak of 180 at
        # bin 150, then 100, 80 and 60; at 41° a beam that ends 5 bins past its peak of 90, so it
        # counts for the peak alone. Each angle seen twice (the same beam: the mean is it).
        def wall_beam(length, peak_bin, peak, windows):
            b = [0] * length
            b[peak_bin] = peak
            for (start, end), value in zip(((10, 30), (30, 70), (70, 130)), windows):
                for k in range(peak_bin + start, min(peak_bin + end, length)):
                    b[k] = value
            return b
        walls = [(0.0, wall_beam(BINS, 100, 200, (50, 30, 20))),
                 (92.0, wall_beam(BINS, 100, 220, (0, 0, 0))),
                 (40.0, wall_beam(BINS, 150, 180, (100, 80, 60))),
                 (41.0, wall_beam(160, 155, 90, (0, 0, 0)))]
        os.makedirs(os.path.join(tmp, "walls", "beams"))
        write_beams(os.path.join(tmp, "walls", "beams", "sweep_0000.bin"),
                    [b for _, b in walls] * 2, [math.radians(a) for a, _ in walls] * 2)
        result = run(os.path.join(tmp, "walls"), "--behind-walls", "50", "300")
        assert result.returncode == 0, result.stderr
        assert "     0- 5°: 2 cells, peak 210.0, 25.0 / 15.0 / 10.0\n" in result.stdout, result.stdout
        assert "    40-45°: 2 cells, peak 135.0, 100.0 / 80.0 / 60.0\n" in result.stdout, \
            result.stdout
        assert " 5-10°" not in result.stdout, result.stdout  # bands without cells are left out
        result = run(os.path.join(tmp, "walls"), "--behind-walls", "300", "50")
        assert result.returncode != 0 and "expected 0 <= FIRST <= LAST" in result.stderr, \
            result.stderr

        # A head angle's profile: of the walls' beams above, those within 6° of 38° are the ones
        # at 40° and 41° (0° and 92° are not), two of each. Over bins 150-157 in groups of 4: bins
        # 150-153 hold 180 (bin 150 at 40°) and 0 at 40°, and at 41° all 0 but bin 155's 90, so
        # (180 · 2) / 16 = 22.5; bins 154-157 hold 0 at 40° and at 41° 90 at bin 155, then nothing
        # past bin 159: (90 · 2) / 16 = 11.25, printed 11.2 (round half to even).
        result = run(os.path.join(tmp, "walls"), "--profile", "38", "150", "157")
        assert result.returncode == 0, result.stderr
        assert "profile of the 4 beams within 6° of 38° (first bin of each 4: their mean): " \
            "150 22.5, 154 11.2\n" in result.stdout, result.stdout
        result = run(os.path.join(tmp, "walls"), "--profile", "38", "398", "402")
        assert result.returncode == 0 and "398 0.0, 402 none" in result.stdout, result.stdout
        result = run(os.path.join(tmp, "walls"), "--profile", "38", "157", "150")
        assert result.returncode != 0 and "expected whole bins" in result.stderr, result.stderr

        # By sector of head angle: the walls' beams at 0° (sector 0°), 40° and 41° (sector 36°)
        # and 92° (sector 90°), two of each. Over bins 150-161 in groups of 6: at 0° bins 130-169
        # hold 30, so 30.0 and 30.0; at 92° nothing past its peak at 100, 0.0; at 36°, bins
        # 150-155 hold 180 (bin 150 at 40°) and 90 (bin 155 at 41°), the rest 0: (180 + 90) · 2 /
        # 24 = 22.5; bins 156-161 hold 100 at bins 160-161 at 40° and nothing past the 160-bin
        # beam's end at 41°: 100 · 2 · 2 / (2 · 6 + 2 · 4) = 20.0.
        result = run(os.path.join(tmp, "walls"), "--sectors", "150", "161")
        assert result.returncode == 0, result.stderr
        assert "by 9° of head angle, the mean per 6 bins from bin 150 (150 156):\n" \
            "      0.0°:  30.0  30.0\n     36.0°:  22.5  20.0\n     90.0°:   0.0   0.0\n" \
            in result.stdout, result.stdout
        result = run(os.path.join(tmp, "walls"), "--sectors", "161", "150")
        assert result.returncode != 0 and "expected 0 <= FIRST <= LAST" in result.stderr, \
            result.stderr

        # The fine texture: ten beams at consecutive head steps, beam b's bin k 100 + 10 (-1)^(k+b).
        # Each bin less its mean over the 31 bins around it is ±(10 + 10/31) (the window's odd one
        # out has the neighbours' sign), ±10 or so near the beam's end where the window is cut: along range the signs alternate (lag 1 and 3 near
        # -1, lag 2 near +1; the per-lag normalisation, over n - m pairs, takes the magnitude a
        # little past 1), from beam to beam too; the contrast is their rms over the mean 100.
        # Bins from 213: the far half of those past 0.35 m (28 bins of 0.0125 m) in the manifest.
        os.makedirs(os.path.join(tmp, "fine", "beams"))
        write_beams(os.path.join(tmp, "fine", "beams", "sweep_0000.bin"),
                    [[100 + 10 * (-1) ** (k + b) for k in range(BINS)] for b in range(10)],
                    [b * math.radians(1.8) for b in range(10)])
        result = run(os.path.join(tmp, "fine"))
        assert result.returncode == 0, result.stderr
        match = re.search(r"fine texture \(bins 213-, [^)]*\): along range (\S+) / (\S+) / (\S+), "
                          r"across head steps (\S+) / (\S+) / (\S+), contrast (\S+)", result.stdout)
        assert match, result.stdout
        values = [float(v) for v in match.groups()]
        for value, expected in zip(values[:6], [-1, 1, -1, -1, 1, -1]):
            assert abs(value - expected) < 0.02, result.stdout
        assert 0.1 < values[6] < 0.1033, result.stdout

        # A dataset without its manifest, or whose manifest lacks the sensor, is refused.
        os.remove(os.path.join(tmp, "fine", "manifest.json"))
        result = run(os.path.join(tmp, "fine"))
        assert result.returncode != 0 and "manifest.json: cannot read it" in result.stderr, \
            result.stderr
        with open(os.path.join(tmp, "fine", "manifest.json"), "w") as f:
            json.dump({"sensor": {"bin_size_m": BIN_M}}, f)
        result = run(os.path.join(tmp, "fine"))
        assert result.returncode != 0 and "expected sensor.bin_size_m" in result.stderr, \
            result.stderr

        os.makedirs(os.path.join(tmp, "bad", "beams"))
        path = os.path.join(tmp, "bad", "beams", "sweep_0000.bin")
        write_beams(path, [beam])
        with open(path, "r+b") as f:
            f.truncate(100)
        result = run(os.path.join(tmp, "bad"))
        assert result.returncode != 0, "a truncated file was accepted"
        assert "sweep_0000.bin: beam 0 truncated" in result.stderr, result.stderr
    print("dataset_stats.py: shares, spreads, tail, arc, behind the walls, a head angle's profile, sectors, fine texture, a missing manifest and a "
          "truncated file as expected")


if __name__ == "__main__":
    main()
