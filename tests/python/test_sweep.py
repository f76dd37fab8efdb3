"""python/src/sweep.cpp: a sweep's arrays, from and to NumPy."""

import numpy as np
import pytest

import sonarbench as sb
from conftest import wall_sweep


def test_arrays_round_trip_without_copies():
    inten, heads, poses, size = wall_sweep()
    poses[:, 0, 3] = np.arange(len(heads)) * 0.1  # a moving sonar
    s = sb.Sweep(inten, heads, poses, size, times_s=np.arange(len(heads)) * 0.5)
    assert s.beam_count == 40 and s.bin_size_m == size and not s.labelled
    np.testing.assert_array_equal(s.intensities, inten)
    np.testing.assert_array_equal(s.head_angles_rad, heads)
    np.testing.assert_array_equal(s.poses, poses)
    np.testing.assert_array_equal(s.times_s, np.arange(40) * 0.5)
    np.testing.assert_array_equal(s.bin_counts, np.full(40, 399))
    # Views of the sweep's own memory: the same buffer each time, read-only.
    a, b = s.intensities, s.intensities
    assert a.__array_interface__["data"][0] == b.__array_interface__["data"][0]
    assert not a.flags.writeable
    with pytest.raises(ValueError):
        a[0, 0] = 1
    assert s.path_shares is None and s.mesh is None and s.points_sonar_m is None


def test_default_times_count_beams():
    s = sb.Sweep(*wall_sweep(beams=3))
    np.testing.assert_array_equal(s.times_s, [0.0, 1.0, 2.0])


@pytest.mark.parametrize("change, named", [
    (lambda a: a.update(intensities=a["intensities"].astype(np.float32)), "intensities"),
    (lambda a: a.update(head_angles_rad=a["head_angles_rad"][:-1]), "head_angles_rad"),
    (lambda a: a.update(poses=a["poses"][:, :3, :]), "poses"),
    (lambda a: a.update(bin_size_m=0.0), "bin_size_m"),
    (lambda a: a.update(bin_size_m=float("nan")), "bin_size_m"),
    (lambda a: a["poses"].__setitem__((2, 3, 0), 1.0), "poses[2]"),
    (lambda a: a["poses"].__setitem__((1, 0, 0), np.inf), "poses[1]"),
])
def test_bad_arrays_name_the_argument(change, named):
    inten, heads, poses, size = wall_sweep(beams=5)
    args = dict(intensities=inten, head_angles_rad=heads, poses=poses, bin_size_m=size)
    change(args)
    with pytest.raises(sb.InputError) as error:
        sb.Sweep(**args)
    assert named in str(error.value)
    assert isinstance(error.value, ValueError)
