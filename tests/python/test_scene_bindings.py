"""python/src/scene_bindings.cpp: scenes and the simulator, against `sonarbench simulate`."""

import numpy as np
import pytest

import sonarbench as sb
from conftest import SOURCE, read_beam_file


def test_a_simulated_sweep_is_the_beam_file_simulate_writes(tank2, tank2_dataset):
    scene = sb.load_scene(tank2)
    assert scene.name == "tank-two-sweeps" and scene.sweeps == 2
    sim = sb.Simulator(scene)
    assert len(sim) == sim.sweep_count == 2 and sim.seed == scene.seed
    for k, sweep in enumerate(sim.sweeps(labels=False)):
        beams = read_beam_file(tank2_dataset / f"beams/sweep_{k:04d}.bin")
        assert sweep.index == k and sweep.beam_count == len(beams)
        for b, (t, head, size, data) in enumerate(beams):
            assert (sweep.times_s[b], sweep.head_angles_rad[b], sweep.bin_sizes_m[b]) == \
                (t, head, size)
            assert sweep.intensities[b, :sweep.bin_counts[b]].tobytes() == data


def test_labels_are_the_datasets(tank2, tank2_dataset):
    sweep = sb.Simulator(sb.load_scene(tank2)).sweep(1)
    written = sb.read_dataset(tank2_dataset).sweeps[1]
    assert sweep.labelled and written.labelled
    np.testing.assert_array_equal(sweep.path_shares, written.path_shares)
    np.testing.assert_array_equal(sweep.mesh, written.mesh)
    np.testing.assert_array_equal(sweep.points_sonar_m, written.points_sonar_m)
    np.testing.assert_array_equal(sweep.poses, written.poses)
    # Shares are 255ths of each bin's power; a bin's mesh has its direct return's point.
    assert (sweep.path_shares.sum(axis=2, dtype=int) == 255).all()
    direct = sweep.mesh != sb.NO_MESH
    assert direct.any()
    assert np.isfinite(sweep.points_sonar_m[direct]).all()
    assert np.isnan(sweep.points_sonar_m[~direct]).all()
    assert sweep.mesh[direct].max() < len(sb.load_scene(tank2).mesh_names)


def test_the_thread_count_does_not_change_a_bit(tank2):
    scene = sb.load_scene(tank2)
    one = sb.Simulator(scene, threads=1, seed=7).sweep(0)
    two = sb.Simulator(scene, threads=2, seed=7).sweep(0)
    other = sb.Simulator(scene, threads=2, seed=8).sweep(0)
    assert one.intensities.tobytes() == two.intensities.tobytes()
    assert one.path_shares.tobytes() == two.path_shares.tobytes()
    assert one.intensities.tobytes() != other.intensities.tobytes()


def test_bad_scenes_raise_the_clis_message(tmp_path, tank2):
    with pytest.raises(sb.InputError, match="missing.yaml"):
        sb.load_scene(tmp_path / "missing.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text(f"extends: {SOURCE / 'scenes/cras-tank.yaml'}\nname: bad\nsweeps: -3\n")
    with pytest.raises(sb.InputError, match="sweeps"):
        sb.load_scene(bad)
    with pytest.raises(sb.InputError, match="--max-beams"):
        sb.load_scene(tank2, max_beams=10)
    with pytest.raises(IndexError):
        sb.Simulator(sb.load_scene(tank2)).sweep(2)
    with pytest.raises(TypeError):
        sb.load_scene(3)
