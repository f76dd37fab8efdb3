#!/usr/bin/env python3
"""Mutation testing of the mapping library and the scoring: do the tests catch a wrong mapper?

Each mutant below is one operator or constant change to mapping/ (the OctoMap file reader in
io/ included) or sim/eval/src/score.cpp and ground_truth.cpp. The
tool copies the source tree to WORK, builds it once, then applies the mutants one at a time,
rebuilds and runs the suites that cover that code, fastest first, stopping at the first that
fails. A mutant is killed when a suite fails (or runs past its timeout), survives when all pass.
Tests that read the real log are left out (--gtest_filter): a mutant must be caught by tests
that need no recorded figure of it.

    python3 tools/mutation_test.py [--work DIR] [--only ID ...] [--jobs N]

Prints a line per mutant and the score; exits 1 if any mutant not judged equivalent survives.
Takes about a minute a mutant on 2 cores; not part of CI.
"""
import argparse
import os
import pathlib
import re
import shutil
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
NO_REAL_LOG = "-*RealLog*:*RealTank*:Fidelity.SimulatedTank*"
# The suites a mutant runs against, fastest first: (build target, executable under tests/).
SUITES = ["test_mapping", "test_mapping_io", "test_eval", "test_app"]

# (id, file, original text (unique in the file), replacement, equivalent: why, or None)
MUTANTS = [
    ("det-min-run", "mapping/src/detection.cpp",
     "k - run_start >= config.min_run_bins", "k - run_start > config.min_run_bins", None),
    ("det-threshold", "mapping/src/detection.cpp",
     "value >= config.threshold", "value > config.threshold", None),
    ("det-half-window", "mapping/src/detection.cpp",
     "config.smoothing_bins / 2;", "config.smoothing_bins / 2 + 1;", None),
    ("det-mean", "mapping/src/detection.cpp",
     "/ (hi - lo + 1);", "/ (hi - lo + 2);", None),
    ("det-window-start", "mapping/src/detection.cpp",
     "std::max(first, k - half)", "std::max(0, k - half)", None),
    ("det-strongest", "mapping/src/detection.cpp",
     "return a.peak > b.peak;", "return a.peak < b.peak;", None),
    ("det-max-echoes", "mapping/src/detection.cpp",
     "static_cast<int>(chosen.size()) < max_obstacles",
     "static_cast<int>(chosen.size()) <= max_obstacles", None),
    ("canny-rising", "mapping/src/detection.cpp",
     "gradient[k] <= 0", "gradient[k] < 0", None),
    ("canny-same-edge", "mapping/src/detection.cpp",
     "k - echoes.back().bin <= 1", "k - echoes.back().bin <= 3", None),
    ("canny-auto-low", "mapping/src/detection.cpp",
     "(1.0 - config.auto_canny_sigma) * median", "(0.5 - config.auto_canny_sigma) * median",
     None),
    ("det-method", "mapping/src/detection.cpp",
     "config.method != DetectionConfig::Method::kThreshold",
     "config.method == DetectionConfig::Method::kThreshold", None),
    ("first-bin-floor", "mapping/src/sensor_geometry.cpp",
     "std::ceil(self_reflection_range_m / bin_size_m - 1e-9)",
     "std::floor(self_reflection_range_m / bin_size_m - 1e-9)", None),
    ("beams-per-sweep", "mapping/src/sensor_geometry.cpp",
     "2.0 * std::numbers::pi / step_angle_rad", "std::numbers::pi / step_angle_rad", None),
    ("pose-roll-sign", "mapping/src/sensor_geometry.cpp",
     "Eigen::AngleAxisd(rpy_rad.x(),", "Eigen::AngleAxisd(-rpy_rad.x(),", None),
    ("ray-offset-edge", "mapping/src/beam_volume.cpp",
     "return -0.5 * width", "return -0.4 * width", None),
    ("ray-offset-spacing", "mapping/src/beam_volume.cpp",
     "static_cast<double>(count - 1);", "static_cast<double>(count);", None),
    ("clear-without-obstacle", "mapping/src/mapper.cpp",
     "!config.clear_without_obstacle ? 0.0", "config.clear_without_obstacle ? 0.0", None),
    ("prob-hit", "mapping/src/mapper.cpp",
     "tree.setProbHit(config.prob_hit);", "tree.setProbHit(config.prob_miss);", None),
    ("last-partial-sweep", "mapping/src/mapper.cpp",
     "(beams.size() + per_sweep - 1) / per_sweep", "beams.size() / per_sweep", None),
    ("free-wins", "mapping/src/integrate.hpp",
     "updates[kept - 1] = u;", "updates[kept - 1] = updates[kept - 1];", None),
    ("log-odds-swapped", "mapping/src/integrate.hpp",
     "{tree.getProbMissLog(), tree.getProbHitLog()}",
     "{tree.getProbHitLog(), tree.getProbMissLog()}", None),
    ("morton-y", "mapping/src/integrate.hpp",
     "(spread(key[1]) << 1)", "(spread(key[1]) << 0)", None),
    ("radix-skip", "mapping/src/integrate.hpp",
     "& (kBuckets - 1)) == 0) continue;", "& (kBuckets - 1)) != 0) continue;", None),
    ("obstacle-count", "mapping/src/integrate.hpp",
     "o.empty() ? 0 : 1", "o.empty() ? 1 : 0", None),
    ("walk-length", "mapping/src/ray_keys.hpp",
     "std::min(std::min(t_max[0], t_max[1]), t_max[2]) > walk.length",
     "std::min(std::min(t_max[0], t_max[1]), t_max[2]) > 2 * walk.length", None),
    ("walk-border", "mapping/src/ray_keys.hpp",
     "walk.step[i] * resolution * 0.5", "walk.step[i] * resolution * 0.4", None),
    ("walk-axis", "mapping/src/ray_keys.hpp",
     "(tx < tz ? 0u : 2u)", "(tx < tz ? 0u : 1u)", None),
    ("raster-border", "mapping/src/beam_raster.cpp",
     "static_cast<float>(1 * resolution * 0.5)", "static_cast<float>(1 * resolution * 0.4)",
     None),
    ("raster-box-edge", "mapping/src/beam_raster.cpp",
     "+ extent[i] > 0x10000", "+ extent[i] > 0x20000", None),
    ("probe-quadratic", "mapping/src/key_set.hpp",
     "(home + (i * i + i) / 2) & mask_", "(home + i * i) & mask_", None),
    ("score-ratio-empty", "sim/eval/src/score.cpp",
     "denominator == 0 ? 0.0 :", "denominator == 0 ? 1.0 :", None),
    ("score-p95", "sim/eval/src/score.cpp",
     "std::ceil(0.95 * d.size())", "std::ceil(0.90 * d.size())", None),
    ("score-f1", "sim/eval/src/score.cpp",
     "2.0 * precision * recall / sum", "precision * recall / sum", None),
    ("score-ring-stop", "sim/eval/src/score.cpp",
     "(ring - 1) * resolution > best", "ring * resolution > best", None),
    ("score-known", "sim/eval/src/score.cpp",
     "(cells.occupied.contains(key) || cells.free.contains(key))",
     "(cells.occupied.contains(key) && cells.free.contains(key))", None),
    ("score-within-k", "sim/eval/src/score.cpp",
     "for (int k = 1; k < 3; ++k)", "for (int k = 1; k < 2; ++k)", None),
    ("octomap-depth", "io/src/octomap_file.cpp",
     "if (depth > kTreeDepth) {", "if (depth > kTreeDepth + 1) {", None),
    ("octomap-trailing", "io/src/octomap_file.cpp",
     "if (in.peek() != std::char_traits<char>::eof()) {", "if (false) {", None),
    ("octomap-leaf-cells", "io/src/octomap_file.cpp",
     "3 * (kTreeDepth - depth)", "3 * (kTreeDepth - depth - 1)", None),
    ("octomap-inner-code", "io/src/octomap_file.cpp",
     "inner[i] = code == 3;", "inner[i] = code == 2;", None),
    ("mcap-chunk-crc", "io/src/mcap.cpp",
     "if (crc != 0 && Crc32(plain) != crc)", "if (false && Crc32(plain) != crc)", None),
    ("mcap-closing-magic", "io/src/mcap.cpp",
     "if (file_.size() - end != kMagicSize ||", "if (false &&", None),
    ("mcap-summary-crc", "io/src/mcap.cpp",
     "crc_end = offset + 1 + 8 + 8 + 8;", "crc_end = offset + 1 + 8 + 8;", None),
    ("rosbag-bins-equal", "io/src/rosbag.cpp",
     "> 1e-3 * d) {", "> 1e3 * d) {", None),
    ("rosbag-interpolate", "io/src/rosbag.cpp",
     "(1 - s) * a.translation()", "s * a.translation()", None),
    ("rosbag-head-angle", "io/src/rosbag.cpp",
     "if (a < 0.0) a += kTwoPi;", "if (a < -1.0) a += kTwoPi;", None),
    ("wedge-outer-cone", "mapping/src/beam_wedge.cpp",
     "std::tan(0.5 * sensor.beam_width_vertical_rad) / std::cos(a);",
     "std::tan(0.5 * sensor.beam_width_vertical_rad);", None),
    ("support-any-angle", "mapping/src/detection.cpp",
     "if (gap > window) continue;", "if (gap > 1e9) continue;", None),
    ("support-any-range", "mapping/src/detection.cpp",
     "std::abs(first_range[other] - range) <= config.support_range_m",
     "std::abs(first_range[other] - range) <= 1e9", None),
    ("share-no-pattern", "mapping/src/arc_evidence.cpp",
     "std::exp(-evidence.pattern_k * elevation * elevation) * occupancy",
     "occupancy", None),
    ("share-no-occupancy", "mapping/src/arc_evidence.cpp",
     "node != nullptr ? node->getOccupancy() : 0.5", "0.5", None),
    ("share-full-hit", "mapping/src/arc_evidence.cpp",
     "if (level >= kShareLevelMax) return hit_log_odds;", "return hit_log_odds;", None),
    ("block-merge-free", "mapping/src/integrate.hpp",
     "& 1 ? full : 0));", "& 1 ? 0 : 0));", None),
    ("leaf-path-origin", "mapping/src/map_tree.hpp",
     "CreatePath(KeyFromMortonCode(codes.front()))",
     "CreatePath(KeyFromMortonCode(codes.front() & ~std::uint64_t{511}))", None),
    ("leaf-no-clamp-min", "mapping/src/map_tree.hpp",
     "value < min ? min : (value > max ? max : value)", "value > max ? max : value", None),
    ("leaf-bt-kind", "mapping/src/map_tree.cpp", "threshold ? 2u : 1u", "threshold ? 1u : 2u",
     None),
    ("leaf-ot-inner", "mapping/src/map_tree.cpp", "max = std::max(max, FullNode(",
     "max = std::min(max, FullNode(", None),
    ("wedge-clear-near", "mapping/src/wedge_cell_tester.hpp",
     "const double lo = obstacles.empty() ? near_lo : far_lo;", "const double lo = far_lo;",
     None),
    ("wedge-plane-near", "mapping/src/wedge_cell_tester.hpp",
     "    if (f > 0.0) {", "    if (f > 1e9) {", None),
    ("direct-no-widen", "sim/eval/src/ground_truth.cpp",
     "const double widen = std::asin(std::min(1.0, cell_half_diagonal_m / range));",
     "const double widen = 0.0;", None),
    ("direct-no-bin", "sim/eval/src/ground_truth.cpp",
     "key_space.getResolution() + sensor.bin_size_m;", "key_space.getResolution();", None),
    ("direct-any-range", "sim/eval/src/ground_truth.cpp",
     "if (after != beam.ranges.begin() && range <= std::prev(after)->second) return true;",
     "if (!beam.ranges.empty()) return true;", None),
    ("ghost-split-swap", "sim/eval/src/score.cpp",
     "half_diagonal) ? 1 : 0;", "half_diagonal) ? 0 : 1;", None),
    ("wedge-two-cuts", "mapping/src/wedge_cell_tester.hpp",
     "if (cuts >= 2 && !Meets(centre)) continue;", "if (cuts >= 3 && !Meets(centre)) continue;",
     "the scan examines only cells that overlap a column's exact extent of the wedge's pyramid, "
     "and these meet the wedge (the column's part of it is convex); the check settles only cells "
     "touching it within the 1e-9 m slack (none of 5615 cut by two planes in "
     "ExactBeamCells.EveryCellIsMarkedAsItsClippedSpanDecides missed it)"),
]


def run(cmd, cwd, timeout=None):
    return subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True, timeout=timeout)


def copy_tree(work):
    src = work / "src"
    files = run(["git", "ls-files", "-co", "--exclude-standard"], ROOT).stdout.split("\n")
    for name in filter(None, files):
        if not (ROOT / name).is_file():
            continue
        target = src / name
        target.parent.mkdir(parents=True, exist_ok=True)
        if not target.exists() or target.read_bytes() != (ROOT / name).read_bytes():
            shutil.copy2(ROOT / name, target)
    return src


def suite_fails(build, suite, jobs, timeout=600):
    """Builds and runs one suite; returns why it failed, or None if it passed."""
    made = run(["cmake", "--build", str(build), "-j", str(jobs), "--target", suite], build)
    if made.returncode != 0:
        return "build error"
    try:
        ran = run([str(build / "tests" / suite), "--gtest_filter=" + NO_REAL_LOG,
                   "--gtest_brief=1"], build, timeout=timeout)
    except subprocess.TimeoutExpired:
        return suite + ": timed out"
    if ran.returncode == 0:
        return None
    failed = re.findall(r"^\[  FAILED  \] (\S+) \(", ran.stdout, re.MULTILINE)
    return suite + ": " + (failed[0] if failed else "exit %d" % ran.returncode)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--work", default="/tmp/sonarbench-mutants", type=pathlib.Path)
    parser.add_argument("--only", nargs="*", help="mutant ids to run (default: all)")
    parser.add_argument("--jobs", type=int, default=os.cpu_count())
    args = parser.parse_args()
    mutants = [m for m in MUTANTS if not args.only or m[0] in args.only]
    src = copy_tree(args.work)
    build = args.work / "build"
    build.mkdir(parents=True, exist_ok=True)
    configured = run(["cmake", "-S", str(src), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                      "-DSONARBENCH_BUILD_BENCHMARKS=OFF"], build)
    if configured.returncode != 0:
        sys.exit(configured.stdout)
    # A mutant that makes a suite run past 3 times its unchanged time (and 30 s) hangs: killed.
    timeouts = {}
    for suite in SUITES:
        run(["cmake", "--build", str(build), "-j", str(args.jobs), "--target", suite], build)
        start = time.monotonic()
        why = suite_fails(build, suite, args.jobs)
        if why:
            sys.exit("the unchanged tree fails: " + why)
        timeouts[suite] = 3 * (time.monotonic() - start) + 30
    killed, survivors, equivalent = 0, [], []
    for ident, name, old, new, reason in mutants:
        path = src / name
        original = path.read_text()
        if original.count(old) != 1:
            sys.exit("%s: %r occurs %d times in %s" % (ident, old, original.count(old), name))
        path.write_text(original.replace(old, new))
        start = time.monotonic()
        try:
            why = None
            for suite in SUITES:
                why = suite_fails(build, suite, args.jobs, timeouts[suite])
                if why:
                    break
        finally:
            path.write_text(original)
        seconds = time.monotonic() - start
        if why == "build error":
            sys.exit("%s: the mutant does not build" % ident)
        if why:
            killed += 1
            verdict = "killed by " + why
        elif reason:
            equivalent.append(ident)
            verdict = "survived, equivalent: " + reason
        else:
            survivors.append(ident)
            verdict = "SURVIVED"
        print("%-24s %5.0f s  %s" % (ident, seconds, verdict), flush=True)
    judged = len(mutants) - len(equivalent)
    print("score: %d of %d mutants killed (%.0f%%), %d judged equivalent, survivors: %s" %
          (killed, judged, 100.0 * killed / max(judged, 1), len(equivalent),
           ", ".join(survivors) or "none"))
    for suite in SUITES:  # leave the copy built as the source is
        suite_fails(build, suite, args.jobs)
    sys.exit(1 if survivors else 0)


if __name__ == "__main__":
    main()
