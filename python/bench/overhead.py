"""The Python module's overhead: a scene's run simulated sweep by sweep and mapped, through
`sonarbench` and through the same C++ calls (python_overhead_baseline), alternating, in one run.

Usage (from the source tree, after `bash ci/build.sh`):
  PYTHONPATH=build/python /usr/bin/python3 python/bench/overhead.py \
      [--scene scenes/cras-tank.yaml] [--repeats 5] [--threads 0] [--baseline PATH]
Prints each pair of times (C++ then Python, back to back) and the median of the pairs' ratios
(Python / C++), which drifts in the machine's speed cancel; checks that both wrote the same map.
"""
import argparse
import json
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import sonarbench

SOURCE = pathlib.Path(__file__).resolve().parents[2]


def python_run(scene_path, seed, threads, map_path):
    start = time.perf_counter()
    scene = sonarbench.load_scene(scene_path)
    simulator = sonarbench.Simulator(scene, seed=seed, threads=threads)
    mapper = sonarbench.Mapper(scene=scene, threads=threads)
    for sweep in simulator.sweeps(labels=False):
        mapper.integrate(sweep)
    seconds = time.perf_counter() - start
    mapper.write_bt(map_path, overwrite=True)
    return seconds


def cpp_run(baseline, scene_path, seed, threads, map_path):
    out = subprocess.run([baseline, str(scene_path), str(seed), str(threads), str(map_path)],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out)["seconds"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default=SOURCE / "scenes" / "cras-tank.yaml")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--threads", type=int, default=0)
    parser.add_argument("--baseline", default=SOURCE / "build" / "python" /
                        "python_overhead_baseline")
    args = parser.parse_args()
    seed = sonarbench.load_scene(args.scene).seed
    cpp, py = [], []
    with tempfile.TemporaryDirectory() as tmp:
        cpp_map, py_map = pathlib.Path(tmp, "cpp.bt"), pathlib.Path(tmp, "python.bt")
        for r in range(args.repeats):
            cpp.append(cpp_run(args.baseline, args.scene, seed, args.threads, cpp_map))
            py.append(python_run(args.scene, seed, args.threads, py_map))
            print(f"repeat {r}: C++ {cpp[-1]:.3f} s, Python {py[-1]:.3f} s", flush=True)
        same = cpp_map.read_bytes() == py_map.read_bytes()
    ratios = sorted(p / c for p, c in zip(py, cpp))
    print(f"median: C++ {statistics.median(cpp):.3f} s, Python {statistics.median(py):.3f} s; "
          f"Python / C++ per pair: median {statistics.median(ratios):.3f} "
          f"(range {ratios[0]:.3f}-{ratios[-1]:.3f}); maps {'identical' if same else 'DIFFER'}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
