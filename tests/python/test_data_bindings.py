"""python/src/data_bindings.cpp: datasets, the real .mat log and ROS 2 bags read into sweeps."""

import numpy as np
import pytest

import sonarbench as sb
from conftest import SOURCE, run_cli


def test_a_dataset_reads_back_its_manifest_and_labels(tank2_dataset):
    log = sb.read_dataset(tank2_dataset)
    assert log.source == "dataset" and len(log) == 2
    assert log.manifest["format"] == "sonarbench-dataset"
    assert log.beam_count == sum(s.beam_count for s in log.sweeps)
    assert log.sweeps[0].beam_count == log.sensor.beams_per_sweep
    assert all(s.labelled for s in log.sweeps)


def test_the_real_log_reads_as_the_cli_counts_it():
    log = sb.read_mat(SOURCE / "data/cras-tank-static")
    assert log.source == "mat" and log.manifest is None
    assert log.beam_count == sum(s.beam_count for s in log.sweeps)
    first = log.sweeps[0]
    np.testing.assert_array_equal(first.poses, np.repeat(np.eye(4)[None], first.beam_count, 0))
    assert first.intensities.shape[1] == log.sensor.bin_count == 399


def test_a_bag_holds_the_datasets_beams(tank2_dataset, tmp_path):
    bag = tmp_path / "tank2.mcap"
    run_cli("export", tank2_dataset, "--out", bag)
    log, dataset = sb.read_mcap(bag), sb.read_dataset(tank2_dataset)
    assert log.source == "mcap" and log.beam_count == dataset.beam_count
    for a, b in zip(log.sweeps, dataset.sweeps):
        np.testing.assert_array_equal(a.intensities, b.intensities)
        np.testing.assert_allclose(a.poses, b.poses, atol=1e-6)


def test_bad_input_names_the_file(tmp_path):
    with pytest.raises(sb.InputError, match="manifest.json"):
        sb.read_dataset(tmp_path)
    junk = tmp_path / "junk.mat"
    junk.write_bytes(b"not a mat file")
    with pytest.raises(sb.InputError, match="junk.mat"):
        sb.read_mat(junk)
