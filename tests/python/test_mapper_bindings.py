"""python/src/mapper_bindings.cpp: the production mapper from Python, against `sonarbench map`."""

import _thread
import threading

import numpy as np
import pytest

import sonarbench as sb
from conftest import run_cli, wall_sweep


def test_a_wall_maps_where_its_echo_is():
    # One echo per beam at 2 m, the sonar static at the origin: the occupied cells lie on the
    # arc of 2 m, within half a cell's diagonal plus one bin of it, and in front of the sonar.
    mapper = sb.Mapper(resolution_m=0.1)
    stats = mapper.integrate(sb.Sweep(*wall_sweep(range_m=2.0)))
    assert stats["beams"] == 40 and stats["beams_with_obstacle"] == 40
    cells = mapper.occupied()
    assert len(cells) > 0 and cells.shape[1] == 3
    ranges = np.linalg.norm(cells, axis=1)
    assert np.abs(ranges - 2.0).max() <= 0.1 * np.sqrt(3) / 2 + 0.0125
    assert (cells[:, 0] > 0).all()
    free = mapper.free()
    assert len(free) > 0 and np.linalg.norm(free, axis=1).max() < 2.0 + 0.1 * np.sqrt(3)


def test_keyword_arguments_are_the_yaml_keys():
    coarse = sb.Mapper(resolution_m=0.2)
    assert coarse.resolution_m == 0.2
    with pytest.raises(sb.InputError, match="resolution_m"):
        sb.Mapper(resolution_m="fine")
    with pytest.raises(sb.InputError, match="no_such_key"):
        sb.Mapper(no_such_key=1)
    with pytest.raises(sb.InputError, match="method"):
        sb.Mapper(detection={"method": "guess"})
    with pytest.raises(ValueError):
        sb.Mapper(resolution_m=-1.0)


def test_a_map_from_python_is_the_clis(tank2, tank2_dataset, tmp_path):
    run_cli("map", tank2_dataset, "--scene", tank2, "--out", tmp_path / "cli")
    log = sb.read_dataset(tank2_dataset)
    for threads in (1, 2):
        mapper = sb.Mapper(scene=sb.load_scene(tank2), sensor=log.sensor, threads=threads)
        mapper.integrate_sweeps(log.sweeps)
        mapper.write_bt(tmp_path / f"python-{threads}.bt")
        assert (tmp_path / f"python-{threads}.bt").read_bytes() == \
            (tmp_path / "cli/map.bt").read_bytes()
    with pytest.raises(sb.InputError, match="overwrite=True"):
        mapper.write_bt(tmp_path / "python-2.bt")
    mapper.write_bt(tmp_path / "python-2.bt", overwrite=True)
    mapper.write_ot(tmp_path / "python.ot")
    assert (tmp_path / "python.ot").read_bytes().startswith(b"# Octomap OcTree file")


def test_two_detectors_give_two_maps(tank2):
    sweep = sb.Simulator(sb.load_scene(tank2)).sweep(0, labels=False)
    low = sb.Mapper(scene=sb.load_scene(tank2), detection={"method": "threshold", "threshold": 60})
    high = sb.Mapper(scene=sb.load_scene(tank2), detection={"method": "threshold", "threshold": 200})
    low.integrate(sweep)
    high.integrate(sweep)
    assert len(low.occupied()) > len(high.occupied())


def test_a_map_past_its_budget_is_refused_before_it_grows():
    # One static sweep of 5 m beams at 0.1 m: the 35° zone of a 5 m sphere, 1.6e5 cells.
    small = sb.Mapper(resolution_m=0.1, max_cells=1e5)
    with pytest.raises(sb.InputError, match="--max-cells"):
        small.integrate(sb.Sweep(*wall_sweep()))
    assert len(small.occupied()) == 0
    # The budget counts the sweeps before: a second sweep 400 m away stretches that zone 41-fold
    # along x (6.5e6 cells), past a budget the first sweep alone keeps within.
    mapper = sb.Mapper(resolution_m=0.1, max_cells=1e6)
    inten, heads, poses, size = wall_sweep()
    mapper.integrate(sb.Sweep(inten, heads, poses, size))
    poses[:, 0, 3] = 400.0
    with pytest.raises(sb.InputError, match="--max-cells"):
        mapper.integrate(sb.Sweep(inten, heads, poses, size))
    poses[:, 0, 3] = 1e4  # past the ±3276.8 m that 16-bit keys address at 0.1 m
    with pytest.raises(sb.InputError, match="16-bit keys"):
        sb.Mapper(resolution_m=0.1).integrate(sb.Sweep(inten, heads, poses, size))


def test_ctrl_c_stops_integrate_sweeps_between_sweeps():
    # Sweep k is the wall seen from x = k m; a simulated Ctrl-C (interrupt_main) 0.2 s in stops
    # the loop at the next sweep, so the map ends short of the last sweep's wall.
    inten, heads, poses, size = wall_sweep()
    sweeps = []
    for k in range(3000):
        poses[:, 0, 3] = float(k)
        sweeps.append(sb.Sweep(inten, heads, poses.copy(), size))
    mapper = sb.Mapper(resolution_m=0.1)
    timer = threading.Timer(0.2, _thread.interrupt_main)
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        mapper.integrate_sweeps(sweeps)
    timer.join()
    reached = mapper.occupied()[:, 0].max()
    assert 0.0 < reached < 2999.0
