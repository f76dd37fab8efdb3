"""python/src/score_bindings.cpp: scores from Python equal `sonarbench score`'s report.json."""

import json

import pytest

import sonarbench as sb
from conftest import run_cli, wall_sweep


def test_a_score_is_the_clis(tank2, tank2_dataset, tmp_path):
    run_cli("map", tank2_dataset, "--scene", tank2, "--out", tmp_path / "map")
    bt = tmp_path / "map/map.bt"
    run_cli("score", bt, "--scene", tank2, "--out", tmp_path / "score", expect=(0, 1))
    report = json.loads((tmp_path / "score/report.json").read_text())
    scene = sb.load_scene(tank2)
    from_file = sb.score(scene, bt)
    assert from_file["metrics"] == report["metrics"]
    assert from_file["criteria"] == report["criteria"]
    assert from_file["verdict"] == report["verdict"]
    log = sb.read_dataset(tank2_dataset)
    mapper = sb.Mapper(scene=scene, sensor=log.sensor)
    mapper.integrate_sweeps(log.sweeps)
    assert sb.score(scene, mapper)["metrics"] == report["metrics"]


def test_a_map_in_another_frame_is_refused(tank2, tmp_path):
    far = sb.Mapper(scene=sb.load_scene(tank2))
    inten, heads, poses, size = wall_sweep()
    poses[:, :3, 3] = [500.0, 0.0, 0.0]
    far.integrate(sb.Sweep(inten, heads, poses, size))
    with pytest.raises(sb.InputError, match="another frame"):
        sb.score(sb.load_scene(tank2), far)
    with pytest.raises(sb.InputError, match="nothing.bt"):
        sb.score(sb.load_scene(tank2), tmp_path / "nothing.bt")
