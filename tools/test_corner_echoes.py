#!/usr/bin/env python3
"""ctest for corner_echoes.py: a tank whose beams towards one corner echo 0.5 m before its edge,
and elsewhere at the walls, gives that corner's first echo, its distance in front of the edge and
its peak, and every other corner at its walls; each wall's echo, 6 bins at 180 after a ramp at 60
from 0.15 m in front of it, starts 0.15 m in front and runs 6 bins above every threshold."""
import math
import os
import subprocess
import sys
import tempfile

from test_dataset_stats import BIN_M, BINS, write_beams

RAMP_M = 0.15
TOOL = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corner_echoes.py")


def main():
    half_x, half_y = 2.0, 1.5  # a 4 × 3 m tank, the sonar at its centre
    ne = math.degrees(math.atan2(half_y, half_x))
    edge = math.hypot(half_x, half_y)  # 2.5 m
    beams, angles = [], []
    for step in range(200):
        angle = step * 1.8
        u = (math.cos(math.radians(angle)), math.sin(math.radians(angle)))
        wall = min(h / abs(c) for h, c in ((half_x, u[0]), (half_y, u[1])) if abs(c) > 1e-9)
        echo = edge - 0.5 if abs((angle - ne + 180) % 360 - 180) <= 6 else wall
        beam = [10] * BINS
        first = int(echo / BIN_M)
        for k in range(int((echo - RAMP_M) / BIN_M), first):
            beam[k] = 60
        for k in range(first, first + 6):
            beam[k] = 180
        beams.append(beam)
        angles.append(math.radians(angle))
    with tempfile.TemporaryDirectory() as tmp:
        os.makedirs(os.path.join(tmp, "beams"))
        write_beams(os.path.join(tmp, "beams", "sweep_0000.bin"), beams, angles)
        result = subprocess.run([sys.executable, TOOL, tmp, "--tank", "4", "3", "--sonar", "0",
                                 "0", "--walls"], capture_output=True, text=True)
        assert result.returncode == 0, result.stderr
        lines = result.stdout.splitlines()
        rows = {line.split()[1]: line.split() for line in lines[1:5]}
        assert set(rows) == {"NE", "NW", "SW", "SE"}, result.stdout
        # The 5-bin mean first reaches 110 two bins before the echo's first bin (3 of 5 at 180);
        # the range reported is that bin's centre: within two bins of the echo.
        in_front = float(rows["NE"][5])
        assert abs(in_front - 0.5) <= 2.5 * BIN_M, result.stdout
        assert rows["NE"][6] == "180", result.stdout
        # The other corners echo at their walls, which within 4° of a corner's bearing lie less
        # than 0.1 m nearer than its edge here, and never beyond it.
        for corner in ("NW", "SW", "SE"):
            assert -2.5 * BIN_M <= float(rows[corner][5]) <= 0.1, result.stdout
        # Each wall: the ramp's first bin, within the bin the ramp starts in and the half bin the
        # tool reports at, and the 4° window's spread of the wall's range (under a bin here).
        walls = {line.split()[1]: line.split() for line in lines[6:]}
        assert set(walls) == {"E", "N", "W", "S"}, result.stdout
        for wall, normal in (("E", half_x), ("N", half_y), ("W", half_x), ("S", half_y)):
            assert float(walls[wall][3]) == normal, result.stdout
            assert abs(float(walls[wall][5]) - RAMP_M) <= 2 * BIN_M, result.stdout
            assert walls[wall][6] == "6/6/6", result.stdout
    print("ok")


if __name__ == "__main__":
    main()
