"""The ghost split of a simulated run by the labels' direct echoes agrees with the geometric one.

Reads the scenario runs' report.json (ctest's scenario.* tests write them): for the tank scenes,
ghost_arc_share and ghost_echo_share, split by the ray-traced first hits, and the same split by
the bins the simulator labels direct (metrics.ghost_split_from_labels) differ by at most 0.02.
  test_labelled_ghost_split.py SCENARIOS_DIR
"""
import json
import sys
from pathlib import Path

TOLERANCE = 0.02
root = Path(sys.argv[1])
for scene in ("cras-tank", "tank-crate", "tank-survey"):
    metrics = json.loads((root / scene / "report.json").read_text())["metrics"]
    labelled = metrics["ghost_split_from_labels"]
    for key, geometric in (("arc_share", "ghost_arc_share"), ("echo_share", "ghost_echo_share")):
        difference = abs(labelled[key] - metrics[geometric])
        print(f"{scene}: {geometric} {metrics[geometric]:.4f}, from labels {labelled[key]:.4f}")
        if difference > TOLERANCE:
            sys.exit(f"{scene}: {geometric} differs from the labels' by {difference:.4f}")
