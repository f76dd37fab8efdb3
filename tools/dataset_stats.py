#!/usr/bin/env python3
"""Intensity statistics of a sonarbench dataset (docs/dataset-format.md), for comparing a
simulated run with a real log bin by bin where `sonarbench fidelity` gives only summaries.

    python3 tools/dataset_stats.py DIR [DIR ...] [--crossing T --from R] [--bins FIRST LAST]
                                   [--lit FIRST LAST] [--arc HEAD_DEG BIN]
                                   [--behind-walls FIRST LAST] [--profile HEAD_DEG FIRST LAST]
                                   [--sectors FIRST LAST] [--heads FROM TO]

DIR is what `sonarbench simulate SCENE --out DIR` or `sonarbench import LOG.mat --out DIR`
wrote. For each, per range band: the mean intensity, the share of bins at 0 and at 150 or
more, and the sweep-to-sweep spread (per head angle, to 0.1°, and bin, the standard deviation
over the beams at that angle, averaged over the band's cells seen twice or more: a static
sonar's echoes repeat, noise does not); that spread's median over the cells from bin 32 whose
mean lies in 30-69, 70-99 and 100-255 (bright cells show a receiver's own noise, which the
background noise cannot reach there), and how the deviations from their cells' means of bins
1, 2 and 3 apart correlate, pooled over the pairs of cells of mean 60 or more; and the ringing
tail: each beam's largest 5-bin moving average over bins 30-63 (0.38-0.79 m, past the
self-reflection the mapper drops), as percentiles over beams and the
share of beams whose tail reaches 60; and the fine texture, as `sonarbench fidelity` measures
it (FidelityReport, its own implementation here): over the far half of the bins past the
manifest's self_reflection_range_m, each bin less its beam's mean over the bins within 15 of it,
the correlation of those 1, 2 and 3 bins apart along a beam and 1, 2 and 3 head steps apart
across beams (the beams that many apart in time order, at consecutive head steps), and their
contrast (root mean square over the mean intensity). With --crossing T --from R, where a threshold detector
meets the first echo along each side (the walls of a tank): for the beams within 20° of head
angle 0°, 90°, 180° and 270°, the first bin from R metres on whose 5-bin mean (the mapper's
smoothing) reaches T, its centre's range times the cosine of the beam's angle off the side's
(the wall's distance, for a wall square to the side), median over the beams. With --bins
FIRST LAST, bin by bin from FIRST to LAST: over every beam that long, the mean intensity, the
share at 0 and the 10th percentile (what lies under every direction at that range: the floor,
or the sonar's own). With --lit FIRST LAST, where an echo heard under every head angle (a
floor's or a water surface's, where the fan's edge meets it) begins: the first bin after FIRST,
up to LAST, at which the share of beams at 0 falls to half or less, interpolated linearly from
the bin before (so 122.5 is halfway between bins 122 and 123), over all beams and per octant of
head angle ([0°, 45°), [45°, 90°), ...): a level sonar's ring begins at one range all round, a
tilted one's earlier on one side and later on the other. With --arc HEAD_DEG BIN, how a point
echo at bin BIN (a tank's corner) is heard across head angles: for the head steps within ±12 of
HEAD_DEG (the manifest's step), each beam's largest intensity within 2 bins of BIN, averaged
over the beams at that head angle: a beam hears the point at its own range wherever its pattern
reaches it, so the arc's width is the pattern's, not the beam's nominal width; then the arc's
peak (the nearest the centre among equals), the contiguous head steps around it within 20
units of it, and the arc at ±6 and ±12 steps. With --behind-walls FIRST LAST, what a tank's
beams hear behind its walls against how squarely they meet them: per head angle (to 0.1°) the
mean of its beams per bin, its peak in bins FIRST to LAST (the wall), and the means over the
bins 10-29, 30-69 and 70-129 past that peak; averaged per 5° band of head angle off the nearest
side's normal (0°, 90°, 180°, 270°: a tank square to the sonar's axes). With --profile HEAD_DEG
FIRST LAST, what the beams pointing one way hear against range: the mean intensity of the beams
within 6° of head angle HEAD_DEG, per group of 4 bins from FIRST to LAST (the last group may be
shorter; bins past a beam's end left out). With --sectors FIRST LAST, where a vehicle's parts
echo: per 9° of head angle from 0° (five head steps), the mean intensity per group of 6 bins from
FIRST to LAST (bins past a beam's end left out; sectors without beams left out). With --heads
FROM TO, only the beams whose head angle lies in [FROM, TO) degrees: fit on one half of a sweep,
check on the other. Standard library only.
"""
import argparse
import glob
import json
import math
import os
import struct
import sys

BANDS_M = [(0.4, 1.5), (1.5, 2.0), (2.0, 2.5), (2.5, 3.0), (3.0, 4.0), (4.0, 5.0)]
TAIL_BINS = (30, 64)  # centres of the 5-bin windows
SPREAD_BY_MEAN = [(30, 70), (70, 100), (100, 256)]  # bands of a cell's mean intensity
FIRST_SPREAD_BIN = 32  # past the self-reflection's bright bins
CORRELATED_MEAN = 60


HEADS = None  # --heads FROM TO: only the beams whose head angle [deg, 0-360) lies in [FROM, TO)


def load_beams(directory, with_angles=False):
    """(bin_size_m, intensities) of every beam, sweep by sweep (those HEADS keeps); with_angles:
    (head_angle_rad, bin_size_m, intensities)."""
    files = sorted(glob.glob(os.path.join(directory, "beams", "sweep_*.bin")))
    if not files:
        sys.exit(f"{directory}: no beams/sweep_*.bin (not a sonarbench dataset?)")
    beams = []
    for path in files:
        with open(path, "rb") as f:
            data = f.read()
        if data[:8] != b"SBBEAMS1":
            sys.exit(f"{path}: expected the magic SBBEAMS1")
        (count,) = struct.unpack_from("<I", data, 8)
        offset = 12
        for beam in range(count):
            if offset + 28 > len(data):
                sys.exit(f"{path}: beam {beam} truncated")
            _, angle, bin_size, bins = struct.unpack_from("<dddI", data, offset)
            offset += 28
            if offset + bins > len(data):
                sys.exit(f"{path}: beam {beam} truncated")
            intensities = data[offset:offset + bins]
            offset += bins
            if HEADS and not HEADS[0] <= math.degrees(angle) % 360.0 < HEADS[1]:
                continue
            beams.append((angle, bin_size, intensities) if with_angles else (bin_size, intensities))
    return beams


def head_cell(angle):
    """A head angle [rad] as the cell it belongs to: degrees in [0, 360), to 0.1 degree."""
    return round(math.degrees(angle) % 360.0, 1) % 360.0


def off_side(degrees, side):
    """How far [deg, 0-180] a head angle lies from a side's bearing."""
    return abs((degrees - side + 180.0) % 360.0 - 180.0)


def percentile(sorted_values, q):
    return sorted_values[min(len(sorted_values) - 1, int(q * len(sorted_values)))]


def sweep_spreads(beams):
    """Per bin: [sum of the standard deviations over head angles, their count]."""
    spreads = {}
    for size, means, deviations in cell_deviations(beams, first=0):
        for k in range(len(means)):
            sd = math.sqrt(sum(d[k] ** 2 for d in deviations) / (len(deviations) - 1))
            cell = spreads.setdefault((size, k), [0.0, 0])
            cell[0] += sd
            cell[1] += 1
    return spreads


def cell_deviations(with_angles, first=FIRST_SPREAD_BIN):
    """Per head angle (to 0.1 degree) seen twice or more, from bin `first` to the shortest
    beam's end: (the bin size, the cells' means, each beam's deviations from them)."""
    by_angle = {}
    for angle, size, b in with_angles:
        by_angle.setdefault(head_cell(angle), []).append((size, b))
    for group in by_angle.values():
        if len(group) < 2:
            continue
        bins = range(first, min(len(b) for _, b in group))
        means = [sum(b[k] for _, b in group) / len(group) for k in bins]
        yield group[0][0], means, [[b[k] - m for k, m in zip(bins, means)] for _, b in group]


DEVIATION_LAGS = (1, 2, 3)  # bins apart


def spread_by_mean(with_angles):
    """The median sweep-to-sweep spread of the cells in each SPREAD_BY_MEAN band of their mean
    ({band: median or None}), and per DEVIATION_LAGS lag the correlation of the deviations
    from their cells' means of bins that far apart, over the pairs of cells both of mean
    CORRELATED_MEAN or more ([correlation or None])."""
    spreads = {band: [] for band in SPREAD_BY_MEAN}
    sums = {lag: [0.0, 0.0, 0.0] for lag in DEVIATION_LAGS}  # products, squares of each
    for _, means, deviations in cell_deviations(with_angles):
        for k, mean in enumerate(means):
            sd = math.sqrt(sum(d[k] ** 2 for d in deviations) / (len(deviations) - 1))
            for band in SPREAD_BY_MEAN:
                if band[0] <= mean < band[1]:
                    spreads[band].append(sd)
            for lag, s in sums.items():
                if k + lag < len(means) and min(mean, means[k + lag]) >= CORRELATED_MEAN:
                    s[0] += sum(d[k] * d[k + lag] for d in deviations)
                    s[1] += sum(d[k] ** 2 for d in deviations)
                    s[2] += sum(d[k + lag] ** 2 for d in deviations)
    medians = {band: sorted(v)[len(v) // 2] if v else None for band, v in spreads.items()}
    correlations = [s[0] / math.sqrt(s[1] * s[2]) if s[1] > 0 and s[2] > 0 else None
                    for s in sums.values()]
    return medians, correlations


def side_crossings(with_angles, threshold, from_m):
    """Per side (0, 90, 180, 270 degrees): the median over its beams of the range at which the
    5-bin mean first reaches `threshold` from `from_m` on, projected on the side's axis."""
    sides = {side: [] for side in (0, 90, 180, 270)}
    for angle, size, b in with_angles:
        degrees = math.degrees(angle) % 360.0
        for side, ranges in sides.items():
            off = off_side(degrees, side)
            if off > 20.0:
                continue
            for k in range(max(0, math.ceil(from_m / size - 0.5)), len(b)):
                window = b[max(0, k - 2):k + 3]
                if sum(window) / len(window) >= threshold:
                    ranges.append((k + 0.5) * size * math.cos(math.radians(off)))
                    break
    return {side: sorted(r)[len(r) // 2] if r else None for side, r in sides.items()}


def bin_rows(beams, first, last):
    """Per bin k in [first, last] held by some beam: (k, its centre's range, mean, share at 0,
    10th percentile) over the beams that hold it."""
    rows = []
    for k in range(first, last + 1):
        values = sorted(b[k] for _, b in beams if len(b) > k)
        if not values:
            continue
        size = next(size for size, b in beams if len(b) > k)
        rows.append((k, (k + 0.5) * size, sum(values) / len(values),
                     sum(v == 0 for v in values) / len(values), percentile(values, 0.1)))
    return rows


def half_lit_bin(beams, first, last):
    """The first k in (first, last] whose share of `beams` (intensity lists) at 0 is 0.5 or less
    while bin k - 1's is more, interpolated between the two; None if there is none."""
    def share_at_zero(k):
        values = [b[k] for b in beams if len(b) > k]
        return sum(v == 0 for v in values) / len(values) if values else None
    before = share_at_zero(first)
    for k in range(first + 1, last + 1):
        share = share_at_zero(k)
        if before is not None and share is not None and before > 0.5 >= share:
            return k - 1 + (before - 0.5) / (before - share)
        before = share
    return None


def lit_rows(with_angles, first, last):
    """[("all", bin or None)] and then, per octant of head angle holding beams, (its first
    degree, bin or None)."""
    octants = {}
    for angle, _, b in with_angles:
        octants.setdefault(int(math.degrees(angle) % 360.0 // 45.0) % 8, []).append(b)
    rows = [("all", half_lit_bin([b for _, _, b in with_angles], first, last))]
    rows += [(45 * o, half_lit_bin(octants[o], first, last)) for o in sorted(octants)]
    return rows


def arc_row(with_angles, head_deg, bin_index, step_rad, steps=12, reach=2):
    """[(offset [deg], mean or None)] for the head steps -steps..steps around head_deg: over the
    beams within half a step of that head angle, the mean of each one's largest intensity within
    `reach` bins of bin_index (bins past a beam's end left out)."""
    step_deg = math.degrees(step_rad)
    rows = []
    for offset in range(-steps, steps + 1):
        centre = head_deg + offset * step_deg
        peaks = []
        for angle, _, b in with_angles:
            off = (math.degrees(angle) - centre + 180.0) % 360.0 - 180.0
            window = b[max(0, bin_index - reach):bin_index + reach + 1]
            if abs(off) < 0.5 * step_deg and window:
                peaks.append(max(window))
        rows.append((offset * step_deg, sum(peaks) / len(peaks) if peaks else None))
    return rows


def arc_summary(rows, drop=20):
    """(peak, its offset, (first, last) offsets of the contiguous head steps around the peak
    within `drop` of it, {offset: mean} at ±6 and ±12 steps) of arc_row's rows; the peak the
    largest mean, the nearest to the centre among equals; None if no step has beams."""
    heard = [(off, m) for off, m in rows if m is not None]
    if not heard:
        return None
    peak_off, peak = max(heard, key=lambda r: (r[1], -abs(r[0])))
    means = [m for _, m in rows]
    i = [off for off, _ in rows].index(peak_off)
    first = last = i
    while first > 0 and means[first - 1] is not None and means[first - 1] >= peak - drop:
        first -= 1
    while last + 1 < len(rows) and means[last + 1] is not None and means[last + 1] >= peak - drop:
        last += 1
    centre = len(rows) // 2
    flanks = {rows[centre + k][0]: rows[centre + k][1] for k in (-12, -6, 6, 12)
              if 0 <= centre + k < len(rows)}
    return peak, peak_off, (rows[first][0], rows[last][0]), flanks


def fine_texture(with_angles, first, step_rad, reach=15, lags=3):
    """([correlation along range at 1..lags bins], [across 1..lags head steps], contrast) of the
    beams' bins from `first` on, each less its beam's mean over the bins within `reach` of it."""
    rows = []
    for _, _, b in with_angles:
        prefix = [0]
        for v in b:
            prefix.append(prefix[-1] + v)
        rows.append([b[k] - (prefix[min(len(b), k + reach + 1)] - prefix[max(0, k - reach)]) /
                     (min(len(b), k + reach + 1) - max(0, k - reach)) for k in range(first, len(b))])
    covariance = [0.0] * (lags + 1)
    for row in rows:
        if len(row) <= 8:  # as FidelityReport::kTextureLags
            continue
        for m in range(lags + 1):
            covariance[m] += sum(row[k] * row[k + m] for k in range(len(row) - m)) / (len(row) - m)
    along = [c / covariance[0] for c in covariance[1:]] if covariance[0] > 0 else [0.0] * lags
    steps = round(2 * math.pi / step_rad)
    index = [round(angle / step_rad) % steps for angle, _, _ in with_angles]
    across = []
    for m in range(1, lags + 1):
        products = spread = 0.0
        for i in range(len(rows) - m):
            if (index[i] + m) % steps != index[i + m]:
                continue
            a, b = rows[i], rows[i + m]
            n = min(len(a), len(b))
            products += sum(a[k] * b[k] for k in range(n))
            spread += math.sqrt(sum(x * x for x in a[:n]) * sum(x * x for x in b[:n]))
        across.append(products / spread if spread > 0 else 0.0)
    count = sum(len(r) for r in rows)
    intensity = sum(sum(b[first:]) for _, _, b in with_angles)
    squares = sum(x * x for r in rows for x in r)
    contrast = math.sqrt(squares / count) / (intensity / count) if count and intensity else 0.0
    return along, across, contrast


def manifest_sensor(directory):
    """(the first usable bin's far half start, the head step [rad]) from the manifest's sensor."""
    path = os.path.join(directory, "manifest.json")
    try:
        with open(path) as f:
            sensor = json.load(f)["sensor"]
        size = float(sensor["bin_size_m"])
        usable = math.ceil(float(sensor["self_reflection_range_m"]) / size - 1e-9)
        return (usable + int(sensor["num_bins"])) // 2, math.radians(float(sensor["step_angle_deg"]))
    except OSError as e:
        sys.exit(f"{path}: cannot read it ({e.strerror})")
    except json.JSONDecodeError as e:
        sys.exit(f"{path}: not JSON (line {e.lineno}: {e.msg})")
    except (KeyError, TypeError, ValueError, ZeroDivisionError):
        sys.exit(f"{path}: expected sensor.bin_size_m (> 0), .self_reflection_range_m, .num_bins "
                 "and .step_angle_deg as numbers")


BEHIND_BANDS_DEG = (0, 5, 10, 15, 20, 25, 30, 35, 40, 45)
BEHIND_WINDOWS = ((10, 30), (30, 70), (70, 130))


def behind_walls(with_angles, first, last):
    """Per band of head angle off the nearest side's normal (0, 90, 180 and 270 degrees; bands
    BEHIND_BANDS_DEG, the last closed): (low, high, cells, mean peak, [mean over each of
    BEHIND_WINDOWS]) over the band's cells. A cell is a head angle (to 0.1°) and its beams' mean
    per bin (over the beams long enough); its peak the largest of those in bins first..last, and
    each window the mean over the bins that many past the peak (those past the beams' end left
    out; a cell none of whose window's bins exist does not count for that window)."""
    cells = {}
    for angle, _, b in with_angles:
        cells.setdefault(head_cell(angle), []).append(b)
    bands = [[low, high, 0, 0.0, [[0.0, 0] for _ in BEHIND_WINDOWS]]
             for low, high in zip(BEHIND_BANDS_DEG[:-1], BEHIND_BANDS_DEG[1:])]
    for degrees, beams in cells.items():
        length = max(len(b) for b in beams)
        if first >= length:
            continue
        means = []
        for k in range(length):
            values = [b[k] for b in beams if len(b) > k]
            means.append(sum(values) / len(values))
        top = min(last, length - 1)
        peak_bin = max(range(first, top + 1), key=lambda k: (means[k], -k))
        off = min(off_side(degrees, side) for side in (0, 90, 180, 270))
        band = next(b for b in bands if b[0] <= off < b[1] or (off == b[1] == BEHIND_BANDS_DEG[-1]))
        band[2] += 1
        band[3] += means[peak_bin]
        for (start, end), total in zip(BEHIND_WINDOWS, band[4]):
            window = means[peak_bin + start:peak_bin + end]
            if window:
                total[0] += sum(window) / len(window)
                total[1] += 1
    return [(low, high, n, peak / n, [t / c if c else None for t, c in windows])
            for low, high, n, peak, windows in bands if n]


PROFILE_HALF_DEG = 6.0
PROFILE_GROUP_BINS = 4
SECTOR_DEG = 9.0  # five head steps of 1.8°
SECTOR_GROUP_BINS = 6


def group_means(beams, first, last, size):
    """[(group's first bin, mean or None)]: the mean intensity of beams per group of `size` bins
    from first to last (the last group may be shorter), each group's bins pooled over the beams
    long enough to hold them."""
    rows = []
    for start in range(first, last + 1, size):
        end = min(start + size, last + 1)
        values = [b[k] for b in beams for k in range(start, min(end, len(b)))]
        rows.append((start, sum(values) / len(values) if values else None))
    return rows


def head_profile(with_angles, head_deg, first, last):
    """(beams, [(group's first bin, mean or None)]): the mean intensity of the beams within
    PROFILE_HALF_DEG of head angle head_deg, per group of PROFILE_GROUP_BINS bins from first to
    last, each group's bins pooled over the beams long enough to hold them."""
    chosen = [b for angle, _, b in with_angles
              if off_side(head_cell(angle), head_deg) <= PROFILE_HALF_DEG]
    return len(chosen), group_means(chosen, first, last, PROFILE_GROUP_BINS)


def sector_rows(with_angles, first, last):
    """[(sector's first degree, [mean or None per group])]: per SECTOR_DEG of head angle from 0°,
    the mean intensity per group of SECTOR_GROUP_BINS bins from first to last, each group's bins
    pooled over the sector's beams long enough to hold them; sectors without beams left out."""
    sectors = {}
    for angle, _, b in with_angles:
        sectors.setdefault(int(head_cell(angle) // SECTOR_DEG), []).append(b)
    return [(sector * SECTOR_DEG,
             [m for _, m in group_means(sectors[sector], first, last, SECTOR_GROUP_BINS)])
            for sector in sorted(sectors)]


def report(directory, crossing=None, from_m=None, bins=None, lit=None, arc=None, behind=None,
           profile=None, sectors=None):
    far_half, step_rad = manifest_sensor(directory)
    with_angles = load_beams(directory, with_angles=True)
    beams = [(size, b) for _, size, b in with_angles]
    spreads = sweep_spreads(with_angles)
    print(f"{directory}: {len(beams)} beams")
    for low, high in BANDS_M:
        values = [v for size, b in beams for k, v in enumerate(b) if low <= k * size < high]
        if not values:
            continue
        n = len(values)
        line = (f"  {low:.1f}-{high:.1f} m: mean {sum(values) / n:.1f}, "
                f"at 0 {100 * sum(v == 0 for v in values) / n:.1f}%, "
                f"at 150 or more {100 * sum(v >= 150 for v in values) / n:.2f}%")
        cells = [c for (size, k), c in spreads.items() if low <= k * size < high]
        if cells:
            line += (f", sweep-to-sweep spread {sum(c[0] for c in cells) / sum(c[1] for c in cells):.1f}")
        print(line)
    medians, correlations = spread_by_mean(with_angles)
    if any(m is not None for m in medians.values()):
        print(f"  sweep-to-sweep spread by the cell's mean, median over cells from bin "
              f"{FIRST_SPREAD_BIN}: " +
              ", ".join(f"{low}-{high - 1} " + (f"{m:.2f}" if m is not None else "none")
                        for (low, high), m in medians.items()) +
              "; the deviations of bins " + " / ".join(map(str, DEVIATION_LAGS)) +
              f" apart (cells of mean {CORRELATED_MEAN} or more) correlate by " +
              " / ".join(f"{c:.2f}" if c is not None else "none" for c in correlations))
    tails = []
    for _, b in beams:
        if len(b) < TAIL_BINS[1] + 2:
            continue
        tails.append(max(sum(b[i - 2:i + 3]) / 5 for i in range(*TAIL_BINS)))
    if tails:
        tails.sort()
        print("  ringing tail (largest 5-bin mean over bins 30-63): "
              f"median {percentile(tails, 0.5):.0f}, p90 {percentile(tails, 0.9):.0f}, "
              f"p99 {percentile(tails, 0.99):.0f}, max {tails[-1]:.0f}; "
              f"{100 * sum(t >= 60 for t in tails) / len(tails):.1f}% of beams reach 60")
    along, across, contrast = fine_texture(with_angles, far_half, step_rad)
    print(f"  fine texture (bins {far_half}-, less each bin's mean over +-15 bins): along range "
          + " / ".join(f"{c:.3f}" for c in along) + ", across head steps "
          + " / ".join(f"{c:.3f}" for c in across) + f", contrast {contrast:.3f}")
    if crossing is not None:
        sides = side_crossings(with_angles, crossing, from_m)
        print(f"  first 5-bin mean at {crossing:g} or more from {from_m:g} m, median per side: " +
              ", ".join(f"{side}° " + (f"{r:.2f} m" if r is not None else "none")
                        for side, r in sides.items()))
    if bins is not None:
        for k, range_m, mean, zeros, p10 in bin_rows(beams, *bins):
            print(f"  bin {k} ({range_m:.3f} m): mean {mean:.1f}, at 0 {100 * zeros:.1f}%, "
                  f"p10 {p10}")
    if lit is not None:
        rows = lit_rows(with_angles, *lit)
        print(f"  half the beams lit from bin (searched {lit[0]}-{lit[1]}): " +
              ", ".join(f"{name}{'' if name == 'all' else '°'} " +
                        (f"{k:.2f}" if k is not None else "none") for name, k in rows))
    if arc is not None:
        rows = arc_row(with_angles, arc[0], int(arc[1]), step_rad)
        print(f"  arc at bin {int(arc[1])} around {arc[0]:g}° (head offset [deg]: mean of the "
              "largest within 2 bins): " +
              ", ".join(f"{off:+.1f} " + (f"{m:.0f}" if m is not None else "none")
                        for off, m in rows))
        summary = arc_summary(rows)
        if summary is not None:
            peak, peak_off, (first, last), flanks = summary
            print(f"  its peak {peak:.0f} at {peak_off:+.1f}°; within 20 of it from {first:+.1f}° "
                  f"to {last:+.1f}°; " +
                  ", ".join(f"at {off:+.1f}° " + (f"{m:.0f}" if m is not None else "none")
                            for off, m in sorted(flanks.items())))

    if behind is not None:
        print(f"  behind the walls (cells' peak in bins {behind[0]}-{behind[1]}, then the mean "
              "over the bins " + ", ".join(f"{a}-{b - 1}" for a, b in BEHIND_WINDOWS) +
              " past it), by head angle off the nearest side's normal:")
        for low, high, n, peak, windows in behind_walls(with_angles, *behind):
            print(f"    {low:2d}-{high:2d}°: {n} cells, peak {peak:.1f}, " +
                  " / ".join(f"{w:.1f}" if w is not None else "none" for w in windows))
    if profile is not None:
        head_deg, first, last = profile[0], int(profile[1]), int(profile[2])
        n, rows = head_profile(with_angles, head_deg, first, last)
        print(f"  profile of the {n} beams within {PROFILE_HALF_DEG:g}° of {head_deg:g}° "
              f"(first bin of each {PROFILE_GROUP_BINS}: their mean): " +
              ", ".join(f"{k} " + (f"{m:.1f}" if m is not None else "none") for k, m in rows))
    if sectors is not None:
        first, last = sectors
        print(f"  by {SECTOR_DEG:g}° of head angle, the mean per {SECTOR_GROUP_BINS} bins from bin "
              f"{first} (" + " ".join(str(k) for k in range(first, last + 1, SECTOR_GROUP_BINS)) +
              "):")
        for low, means in sector_rows(with_angles, first, last):
            print(f"    {low:5.1f}°: " +
                  " ".join(f"{m:5.1f}" if m is not None else " none" for m in means))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("directories", nargs="+", metavar="DIR")
    parser.add_argument("--crossing", type=float, metavar="T",
                        help="also report where the 5-bin mean first reaches T, per side")
    parser.add_argument("--from", dest="from_m", type=float, metavar="R",
                        help="range [m] the crossing search starts at (with --crossing)")
    parser.add_argument("--bins", type=int, nargs=2, metavar=("FIRST", "LAST"),
                        help="also report bins FIRST to LAST one by one")
    parser.add_argument("--lit", type=int, nargs=2, metavar=("FIRST", "LAST"),
                        help="also report where half the beams are lit, from FIRST to LAST, "
                             "over all beams and per octant of head angle")
    parser.add_argument("--arc", type=float, nargs=2, metavar=("HEAD_DEG", "BIN"),
                        help="also report bin BIN across the head steps within 12 of HEAD_DEG")
    parser.add_argument("--behind-walls", type=int, nargs=2, metavar=("FIRST", "LAST"),
                        help="also report, per band of head angle off the sides' normals, each "
                             "head angle's mean peak in bins FIRST to LAST and the means past it")
    parser.add_argument("--profile", type=float, nargs=3, metavar=("HEAD_DEG", "FIRST", "LAST"),
                        help="also report the mean of the beams within 6 degrees of HEAD_DEG, "
                             "per 4 bins from FIRST to LAST")
    parser.add_argument("--sectors", type=int, nargs=2, metavar=("FIRST", "LAST"),
                        help="also report, per 9 degrees of head angle, the mean per 6 bins from "
                             "FIRST to LAST (where a vehicle's parts echo, bins 28-63)")
    parser.add_argument("--heads", type=float, nargs=2, metavar=("FROM", "TO"),
                        help="only the beams whose head angle [deg] lies in [FROM, TO): one half "
                             "of the sweep to fit on, the other to check")
    args = parser.parse_args()
    if args.heads is not None and not 0 <= args.heads[0] < args.heads[1] <= 360:
        parser.error(f"--heads {args.heads[0]:g} {args.heads[1]:g}: expected 0 <= FROM < TO <= 360")
    HEADS = args.heads
    if (args.crossing is None) != (args.from_m is None):
        parser.error("--crossing and --from go together")
    if args.bins is not None and not 0 <= args.bins[0] <= args.bins[1]:
        parser.error(f"--bins {args.bins[0]} {args.bins[1]}: expected 0 <= FIRST <= LAST")
    if args.lit is not None and not 0 <= args.lit[0] < args.lit[1]:
        parser.error(f"--lit {args.lit[0]} {args.lit[1]}: expected 0 <= FIRST < LAST")
    if args.arc is not None and (args.arc[1] < 0 or args.arc[1] != int(args.arc[1])):
        parser.error(f"--arc {args.arc[0]:g} {args.arc[1]:g}: expected BIN a whole number >= 0")
    if args.behind_walls is not None and not 0 <= args.behind_walls[0] <= args.behind_walls[1]:
        parser.error(f"--behind-walls {args.behind_walls[0]} {args.behind_walls[1]}: expected "
                     "0 <= FIRST <= LAST")
    if args.profile is not None and not (
            0 <= args.profile[1] <= args.profile[2]
            and all(v == int(v) for v in args.profile[1:])):
        parser.error(f"--profile {args.profile[0]:g} {args.profile[1]:g} {args.profile[2]:g}: "
                     "expected whole bins 0 <= FIRST <= LAST")
    if args.sectors is not None and not 0 <= args.sectors[0] <= args.sectors[1]:
        parser.error(f"--sectors {args.sectors[0]} {args.sectors[1]}: expected 0 <= FIRST <= LAST")
    for d in args.directories:
        report(d, args.crossing, args.from_m, args.bins, args.lit, args.arc, args.behind_walls,
               args.profile, args.sectors)
