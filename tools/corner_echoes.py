#!/usr/bin/env python3
"""Where a static sonar's first echo lies near the corners of a box tank (docs/fidelity.md,
"Off-wall echoes"): for each corner, over the beams within --window degrees of its bearing, the
median range of the first echo a threshold detector finds (the mapper's: a moving average of
--smoothing bins, a run of --min-run bins at or above --threshold, from the manifest's
self_reflection_range_m on), how far that lies in front of the corner's vertical edge, the
median peak of the smoothed echo, and what each hypothesis predicts: a wall heard at normal
incidence (its perpendicular range) and the corner itself (a corner reflector returns at the
edge's range).

    python3 tools/corner_echoes.py DIR [DIR ...] --tank 4.36 4.48 --sonar 0.10 0.48
                                   [--threshold 110 --smoothing 5 --min-run 3 --window 4]

DIR is a dataset (`sonarbench import LOG.mat` or `sonarbench simulate SCENE`); the tank is
centred on the origin, its walls square to x and y; --sonar is the sonar's x y in that frame
(an imported .mat log's poses are the origin's, so it is given here). Standard library only.
"""
import argparse
import glob
import json
import math
import os
import statistics
import struct


def beams(directory):
    """(head angle [deg], intensities) of every beam of a dataset, in order; and the bin size."""
    out = []
    bin_size = None
    for path in sorted(glob.glob(os.path.join(directory, "beams", "sweep_*.bin"))):
        data = open(path, "rb").read()
        if data[:8] != b"SBBEAMS1":
            raise SystemExit(f"{path}: not a sonarbench beam file")
        count = struct.unpack_from("<I", data, 8)[0]
        at = 12
        for _ in range(count):
            _, head, bin_size, bins = struct.unpack_from("<dddI", data, at)
            at += 28
            out.append((math.degrees(head) % 360.0, data[at:at + bins]))
            at += bins
    return out, bin_size


def first_echo(row, first, threshold, smoothing, min_run):
    """(start bin, peak of the smoothed values) of the first run, or None: detection.cpp's rule."""
    n = len(row)
    half = smoothing // 2
    start, peak = -1, 0.0
    for k in range(first, n + 1):
        value = 0.0
        if k < n:
            lo, hi = max(first, k - half), min(n - 1, k + half)
            value = sum(row[lo:hi + 1]) / (hi - lo + 1)
        above = k < n and value >= threshold
        if above and start < 0:
            start, peak = k, 0.0
        if above:
            peak = max(peak, value)
        if not above and start >= 0:
            if k - start >= min_run:
                return start, peak
            start = -1
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dirs", nargs="+")
    parser.add_argument("--tank", nargs=2, type=float, required=True, metavar=("X", "Y"))
    parser.add_argument("--sonar", nargs=2, type=float, required=True, metavar=("X", "Y"))
    parser.add_argument("--threshold", type=float, default=110)
    parser.add_argument("--smoothing", type=int, default=5)
    parser.add_argument("--min-run", type=int, default=3)
    parser.add_argument("--window", type=float, default=4.0)
    args = parser.parse_args()
    hx, hy = args.tank[0] / 2, args.tank[1] / 2
    sx, sy = args.sonar
    print("dataset corner bearing_deg edge_m first_echo_m in_front_m peak walls_normal_m beams")
    for directory in args.dirs:
        manifest = json.load(open(os.path.join(directory, "manifest.json")))
        all_beams, bin_size = beams(directory)
        first_bin = math.ceil(manifest["sensor"]["self_reflection_range_m"] / bin_size - 1e-9)
        for name, cx, cy in (("NE", hx, hy), ("NW", -hx, hy), ("SW", -hx, -hy), ("SE", hx, -hy)):
            dx, dy = cx - sx, cy - sy
            bearing = math.degrees(math.atan2(dy, dx)) % 360.0
            edge = math.hypot(dx, dy)
            ranges, peaks, total = [], [], 0
            for head, row in all_beams:
                if abs((head - bearing + 180.0) % 360.0 - 180.0) > args.window:
                    continue
                total += 1
                echo = first_echo(row, first_bin, args.threshold, args.smoothing, args.min_run)
                if echo:
                    ranges.append((echo[0] + 0.5) * bin_size)
                    peaks.append(echo[1])
            if not ranges:
                print(f"{directory} {name} {bearing:.1f} {edge:.3f} - - - - 0/{total}")
                continue
            r = statistics.median(ranges)
            print(f"{directory} {name} {bearing:.1f} {edge:.3f} {r:.3f} {edge - r:.3f} "
                  f"{statistics.median(peaks):.0f} {abs(dx):.2f}/{abs(dy):.2f} "
                  f"{len(ranges)}/{total}")


if __name__ == "__main__":
    main()
