"""Bad input raises ulc.Error whose message names the problem, as the command line prints it."""
import os

import numpy as np
import pytest

import ulc
from conftest import lidar, run_ulc


def frame(n=100):
    return np.random.default_rng(0).normal(size=(n, 3)) * 10


def test_wrong_shape_is_named():
    with pytest.raises(ulc.Error, match=r"base frame 0: expected an N x 3 or N x 4 array .*\(100, 2\)"):
        ulc.calibrate(frame()[:, :2], frame())


def test_wrong_dtype_is_named():
    with pytest.raises(ulc.Error, match="target frame 0: expected float32 or float64 values, got int64"):
        ulc.calibrate(frame(), frame().astype(np.int64))


def test_not_finite_is_named():
    f = frame()
    f[7, 1] = np.nan
    with pytest.raises(ulc.Error, match="base frame 0: row 7 is not finite"):
        ulc.calibrate(f, frame())


def test_missing_timestamps_are_named():
    with pytest.raises(ulc.Error, match="2 frames need their timestamps"):
        ulc.calibrate([frame(), frame()], frame())
    with pytest.raises(ulc.Error, match="3 timestamps for 2 frames"):
        ulc.calibrate([frame(), frame()], frame(), base_times=[0, 0.1, 0.2])
    with pytest.raises(ulc.Error, match="timestamp 1 does not increase"):
        ulc.calibrate([frame(), frame()], frame(), base_times=[0.1, 0.1])


def test_options_are_checked_as_the_command_line_does():
    with pytest.raises(ulc.Error, match="option '--stages'"):
        ulc.calibrate(frame(), frame(), stages="terra,bogus")
    with pytest.raises(ulc.Error, match="needs an initial extrinsic"):
        ulc.calibrate(frame(), frame(), stages="jeep")
    with pytest.raises(ulc.Error, match=r"option '--time-offset' must be within \[-1, 1\] s"):
        ulc.calibrate(frame(), frame(), time_offset=3.0)
    with pytest.raises(ulc.Error, match="not a rigid transform"):
        ulc.calibrate(frame(), frame(), stages="jeep", initial=np.ones((4, 4)))


def test_a_missing_folder_says_what_the_command_line_says(tmp_path):
    missing = str(tmp_path / "nowhere")
    code, _, stderr = run_ulc("calibrate", "--quiet", "--base", missing, "--target", missing)
    assert code == 2
    with pytest.raises(ulc.Error) as e:
        ulc.calibrate(missing, missing)
    assert str(e.value) == stderr.strip().splitlines()[-1]
    assert "nowhere" in str(e.value)


def test_frame_index_past_the_end_says_what_the_command_line_says(drive):
    args = ["--base", lidar(drive, "lidar64"), "--target", lidar(drive, "lidar32"),
            "--frame-index", "50"]
    code, _, stderr = run_ulc("calibrate", "--quiet", *args)
    assert code == 2
    with pytest.raises(ulc.Error) as e:
        ulc.calibrate(lidar(drive, "lidar64"), lidar(drive, "lidar32"), frame_index=50)
    assert str(e.value) == stderr.strip()


def test_a_damaged_cloud_file_is_named(tmp_path):
    bad = tmp_path / "bad.pcd"
    bad.write_bytes(b"VERSION .7\nFIELDS x y\n")
    with pytest.raises(ulc.Error, match="bad.pcd"):
        ulc.read_cloud(str(bad))


def test_unknown_scenario():
    with pytest.raises(ulc.Error, match="unknown scenario 'nope'"):
        ulc.simulate("nope")


def test_writing_into_a_missing_folder_is_named(drive, tmp_path):
    result = ulc.calibrate(lidar(drive, "lidar64"), lidar(drive, "lidar32"), stages="terra")
    with pytest.raises(ulc.Error, match="nowhere"):
        result.write(str(tmp_path / "nowhere" / "r.json"))
    with pytest.raises(ulc.Error, match="'xml' is not json or yaml"):
        result.write(str(tmp_path / "r.xml"), format="xml")
