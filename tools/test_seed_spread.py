#!/usr/bin/env python3
"""ctest for seed_spread.py: with a stand-in for sonarbench whose recall is 0.5 + seed / 100 and
which fails seed 3, the table holds the seeds' mean, standard deviation and the bound k standard
deviations below the mean, and --verdicts counts the failure."""
import os
import statistics
import subprocess
import sys
import tempfile

TOOL = os.path.join(os.path.dirname(os.path.abspath(__file__)), "seed_spread.py")

FAKE = r'''#!/usr/bin/env python3
import json, os, sys
args = sys.argv[1:]
seed = int(args[args.index("--seed") + 1])
out = args[args.index("--out") + 1]
recall = 0.5 + seed / 100.0
result = {"metric": "occupied_recall", "actual": recall, "min": 0.52, "max": None,
          "acceptable_min": None, "acceptable_max": None}
with open(os.path.join(out, "report.json"), "w") as f:
    json.dump({"criteria": {"expect": "pass", "results": [result]},
               "verdict": {"passed": seed != 3}}, f)
sys.exit(1 if seed == 3 else 0)
'''


def run(*args):
    return subprocess.run([sys.executable, TOOL, *args], capture_output=True, text=True,
                          check=False)


def main():
    with tempfile.TemporaryDirectory() as tmp:
        fake = os.path.join(tmp, "sonarbench")
        with open(fake, "w") as f:
            f.write(FAKE)
        os.chmod(fake, 0o755)
        scene = os.path.join(tmp, "tank.yaml")
        open(scene, "w").close()
        out = os.path.join(tmp, "out")
        spread = run("--sonarbench", fake, "--seeds", "1-4,6", "--out", out, "--margin-sd", "2",
                     scene)
        assert spread.returncode == 0, spread.stderr
        values = [0.5 + s / 100.0 for s in (1, 2, 3, 4, 6)]
        mean, sd = statistics.fmean(values), statistics.stdev(values)
        row = [line for line in spread.stdout.splitlines() if "occupied_recall" in line]
        assert len(row) == 1, spread.stdout
        cells = [c.strip() for c in row[0].strip("|").split("|")]
        assert cells[0] == "tank" and float(cells[2]) == round(mean, 4), cells
        assert float(cells[3]) == round(sd, 4), cells
        assert cells[5] == "min 0.52", cells
        assert abs(float(cells[6]) - (mean - 0.52) / sd) < 0.06, cells
        # mean - 2 sd = 0.4936, under the worst seed (0.51): rounded down to 0.49.
        assert float(cells[7]) == 0.49, cells
        verdicts = run("--sonarbench", fake, "--seeds", "1-4,6", "--out", out, "--verdicts",
                       "--reuse", scene)
        assert verdicts.returncode == 1, verdicts.stdout
        assert "| tank | pass | 1-4,6 | 4 | 1 | no |" in verdicts.stdout, verdicts.stdout
    print("seed_spread: ok")


if __name__ == "__main__":
    main()
