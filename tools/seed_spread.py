#!/usr/bin/env python3
"""Runs scenes at several seeds and reports each criterion's seed-to-seed spread.

    tools/seed_spread.py --sonarbench build/sim/sonarbench --seeds 201-208 --out DIR SCENE...

For each scene and seed it runs `sonarbench run SCENE --seed N --out DIR/NAME/N` and reads the
criteria from report.json. It prints, per scene and metric, the seeds' mean, standard deviation,
range, the scene's bound, the bound's distance from the mean in standard deviations, and the bound
--margin-sd (3) standard deviations beyond the mean (or beyond the worst seed, if further),
rounded outward to 0.01. With --verdicts it prints instead how many of each scene's runs passed
(exit 0; a must-fail scene passes when a required criterion fails) and failed (exit 1). With
--reuse it reads the reports a previous call left in --out instead of running. Only the
standard library.
"""

import argparse
import json
import math
import os
import statistics
import subprocess
import sys


def parse_seeds(text):
    """'201-208' or '1,5,9' or a mix: the seeds, in order."""
    seeds = []
    for part in text.split(","):
        if "-" in part:
            lo, hi = part.split("-")
            seeds.extend(range(int(lo), int(hi) + 1))
        else:
            seeds.append(int(part))
    return seeds


def run_scene(binary, scene, seed, out, threads, reuse):
    """One run's exit status and its report.json (None when it wrote none)."""
    path = os.path.join(out, "report.json")
    if reuse and os.path.exists(path):
        with open(path, encoding="utf-8") as f:
            report = json.load(f)
        return (0 if report["verdict"]["passed"] else 1), report
    os.makedirs(out, exist_ok=True)
    status = subprocess.run(
        [binary, "run", scene, "--seed", str(seed), "--out", out, "--no-progress", "-j", str(threads)],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False).returncode
    if not os.path.exists(path):
        return status, None
    with open(path, encoding="utf-8") as f:
        return status, json.load(f)


def suggested(lower, values, k):
    """The bound k sd beyond the mean (or beyond the worst seed), rounded outward to 0.01."""
    mean = statistics.fmean(values)
    sd = statistics.stdev(values) if len(values) > 1 else 0.0
    if lower:
        return math.floor(100.0 * min(mean - k * sd, min(values)) + 1e-9) / 100.0
    return math.ceil(100.0 * max(mean + k * sd, max(values)) - 1e-9) / 100.0


def spread_table(name, reports, k):
    """Markdown rows: one per criterion of the scene's reports."""
    rows = []
    criteria = reports[0]["criteria"]["results"]
    for i, c in enumerate(criteria):
        values = [r["criteria"]["results"][i]["actual"] for r in reports]
        values = [v for v in values if v is not None]
        if not values:
            continue
        mean = statistics.fmean(values)
        sd = statistics.stdev(values) if len(values) > 1 else 0.0
        # The bound a run fails past: the acceptable one where the criterion has a band.
        lower = c.get("acceptable_min") if c.get("acceptable_min") is not None else c.get("min")
        upper = c.get("acceptable_max") if c.get("acceptable_max") is not None else c.get("max")
        bound = lower if lower is not None else upper
        distance = abs(mean - bound) / sd if bound is not None and sd > 0 else float("inf")
        rows.append(f"| {name} | {c['metric']} | {mean:.4f} | {sd:.4f} | {min(values):.4f}-"
                    f"{max(values):.4f} | {'min' if lower is not None else 'max'} "
                    f"{bound} | {distance:.1f} | {suggested(lower is not None, values, k)} |")
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sonarbench", required=True)
    parser.add_argument("--seeds", required=True, help="e.g. 201-208 or 1,5,9")
    parser.add_argument("--out", required=True)
    parser.add_argument("--threads", type=int, default=0)
    parser.add_argument("--margin-sd", type=float, default=3.0,
                        help="the suggested bound's distance from the mean [sd]")
    parser.add_argument("--verdicts", action="store_true", help="count passes and failures only")
    parser.add_argument("--reuse", action="store_true", help="read the reports already in --out")
    parser.add_argument("scenes", nargs="+")
    args = parser.parse_args()
    seeds = parse_seeds(args.seeds)
    if args.verdicts:
        print("| scene | expects | seeds | passed | failed | as expected |")
        print("| --- | --- | --- | --- | --- | --- |")
    else:
        print(f"| scene | metric | mean | sd | range | bound | bound − mean [sd] | "
              f"{args.margin_sd:g} sd bound |")
        print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    all_expected = True
    for scene in args.scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        reports, passed, failed = [], 0, 0
        for seed in seeds:
            status, report = run_scene(args.sonarbench, scene, seed,
                                       os.path.join(args.out, name, str(seed)), args.threads,
                                       args.reuse)
            if report is None or status not in (0, 1):
                print(f"{scene} seed {seed}: exit {status}, no verdict", file=sys.stderr)
                all_expected = False
                continue
            reports.append(report)
            passed += status == 0
            failed += status == 1
        if not reports:
            continue
        expects = reports[0]["criteria"]["expect"]
        if args.verdicts:
            ok = failed == 0
            all_expected = all_expected and ok
            print(f"| {name} | {expects} | {args.seeds} | {passed} | {failed} | "
                  f"{'yes' if ok else 'no'} |")
        else:
            print("\n".join(spread_table(name, reports, args.margin_sd)))
        sys.stdout.flush()
    return 0 if all_expected else 1


if __name__ == "__main__":
    sys.exit(main())
