#!/usr/bin/env python3
"""The README's scene, saved in a folder of its own as a user would, runs and passes.

    python3 tests/docs/test_readme_scene.py README.md build/sim/sonarbench

Its rock rests on the tank's floor (z = 0): the lowest vertex of the OBJ it names, placed at its
position_m, lies within half a map cell (2.5 cm) of it. Exits 1 saying what failed.
"""
import re
import subprocess
import sys
import tempfile
from pathlib import Path


def main():
    readme, sonarbench = Path(sys.argv[1]).resolve(), str(Path(sys.argv[2]).resolve())
    section = readme.read_text().split("## A scene", 1)[1]
    scene = re.search(r"```yaml\n(.*?)```", section, re.S).group(1)
    rock = re.search(r"\{name: rock, type: file, file: ([^,]+), position_m: \[([^\]]+)\]", scene)
    if not rock:
        print("the README's scene has no rock of a mesh file", file=sys.stderr)
        return 1
    mesh = readme.parent / rock.group(1)
    lowest = min(float(line.split()[3]) for line in mesh.read_text().splitlines()
                 if line.startswith("v "))
    bottom = float(rock.group(2).split(",")[2]) + lowest
    if abs(bottom) > 0.025:
        print(f"the rock's bottom is at z = {bottom:.3f} m, not on the floor", file=sys.stderr)
        return 1
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "my-tank.yaml"
        path.write_text(scene)
        done = subprocess.run([sonarbench, "run", str(path), "--out", str(Path(folder) / "out")],
                              capture_output=True, text=True, cwd=folder)
        if done.returncode != 0 or "PASS my-tank" not in done.stdout:
            print(f"run exited {done.returncode}: {done.stdout}{done.stderr}", file=sys.stderr)
            return 1
    print(f"the README's scene runs from {folder} and passes; the rock's bottom at "
          f"z = {bottom:.3f} m")
    return 0


if __name__ == "__main__":
    sys.exit(main())
