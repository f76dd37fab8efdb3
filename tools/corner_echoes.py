#!/usr/bin/env python3
"""Where a static sonar's first echo lies near the corners of a box tank (docs/fidelity.md,
"Off-wall echoes"): for each corner, over the beams within --window degrees of its bearing, the
median range of the first echo a threshold detector finds (the mapper's: a moving average of
--smoothing bins, a run of --min-run bins at or above --threshold, from the manifest's
self_reflection_range_m on), how far that lies in front of the corner's vertical edge, the
median peak of the smoothed echo, and what each hypothesis predicts: a wall heard at normal
incidence (its perpendicular range) and the corner itself (a corner reflector returns at the
edge's range).

With --walls, also each wall at normal incidence, over the beams within --window degrees of its
normal: where the echo starts in front of the wall (walking back from the strongest bin of the
beams' mean while the mean stays at or above --ramp-level) and, beam by beam, the median number of
bins in the run around the strongest bin at or above 110, 130 and 150 (the detector's
thresholds): how long the wall's echo is, and what a step or fillet at its foot would add.

    python3 tools/corner_echoes.py DIR [DIR ...] --tank 4.36 4.48 --sonar 0.10 0.48
                                   [--threshold 110 --smoothing 5 --min-run 3 --window 4]
                                   [--walls --ramp-level 40]

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


def run_width(row, first, level):
    """Bins in the run at or above `level` around the row's strongest bin past `first`."""
    top = max(range(first, len(row)), key=lambda k: row[k])
    if row[top] < level:
        return 0
    lo, hi = top, top
    while lo > first and row[lo - 1] >= level:
        lo -= 1
    while hi + 1 < len(row) and row[hi + 1] >= level:
        hi += 1
    return hi - lo + 1


def walls(directory, all_beams, bin_size, first_bin, args, hx, hy):
    """Prints each wall's line (--walls)."""
    sx, sy = args.sonar
    for name, bearing, normal in (("E", 0.0, hx - sx), ("N", 90.0, hy - sy),
                                  ("W", 180.0, hx + sx), ("S", 270.0, hy + sy)):
        rows = [row for head, row in all_beams
                if abs((head - bearing + 180.0) % 360.0 - 180.0) <= args.window]
        if not rows:
            print(f"{directory} {name} {bearing:.0f} {normal:.3f} - - - 0")
            continue
        bins = min(len(row) for row in rows)
        mean = [sum(row[k] for row in rows) / len(rows) for k in range(bins)]
        k = max(range(first_bin, bins), key=lambda j: mean[j])
        while k > first_bin and mean[k - 1] >= args.ramp_level:
            k -= 1
        widths = "/".join(f"{statistics.median(run_width(row, first_bin, level) for row in rows):.0f}"
                          for level in (110, 130, 150))
        print(f"{directory} {name} {bearing:.0f} {normal:.3f} {(k + 0.5) * bin_size:.3f} "
              f"{normal - (k + 0.5) * bin_size:.3f} {widths} {len(rows)}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dirs", nargs="+")
    parser.add_argument("--tank", nargs=2, type=float, required=True, metavar=("X", "Y"))
    parser.add_argument("--sonar", nargs=2, type=float, required=True, metavar=("X", "Y"))
    parser.add_argument("--threshold", type=float, default=110)
    parser.add_argument("--smoothing", type=int, default=5)
    parser.add_argument("--min-run", type=int, default=3)
    parser.add_argument("--window", type=float, default=4.0)
    parser.add_argument("--walls", action="store_true")
    parser.add_argument("--ramp-level", type=float, default=40)
    args = parser.parse_args()
    hx, hy = args.tank[0] / 2, args.tank[1] / 2
    sx, sy = args.sonar
    print("dataset corner bearing_deg edge_m first_echo_m in_front_m peak walls_normal_m beams")
    datasets = []
    for directory in args.dirs:
        manifest = json.load(open(os.path.join(directory, "manifest.json")))
        all_beams, bin_size = beams(directory)
        first_bin = math.ceil(manifest["sensor"]["self_reflection_range_m"] / bin_size - 1e-9)
        datasets.append((directory, all_beams, bin_size, first_bin))
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
    if args.walls:
        print("dataset wall bearing_deg normal_m echo_starts_m in_front_m "
              "run_bins_110/130/150 beams")
        for directory, all_beams, bin_size, first_bin in datasets:
            walls(directory, all_beams, bin_size, first_bin, args, hx, hy)


if __name__ == "__main__":
    main()
