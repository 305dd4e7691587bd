"""The stages, readers and simulator on their own."""
import numpy as np

import ulc
from conftest import errors, lidar


def test_version_and_scenarios():
    assert ulc.__version__.count(".") == 2
    names = [name for name, _ in ulc.scenarios()]
    assert "64-32" in names and "64-horizon" in names


def test_read_cloud_and_read_frames_agree(drive):
    frames = ulc.read_frames(lidar(drive, "lidar32"))
    assert frames["name"] == "lidar32" and len(frames["frames"]) == 6
    assert np.all(np.diff(frames["times"]) > 0)
    first = ulc.read_cloud(lidar(drive, "lidar32") + "/000000.pcd")
    assert first.shape[1] == 4 and frames["frames"][0].shape == first.shape
    np.testing.assert_array_equal(first[:, :3], frames["frames"][0][:, :3])


def test_simulate_terra_and_jeep_recover_the_truth():
    drive = ulc.simulate("64-32", seconds=0.5, seed=2)
    base, target = drive["lidars"]
    T_true = drive["truth"][0]["T_base_target"]
    assert drive["truth"][0]["base"] == base["name"] == "lidar64"
    assert len(base["frames"]) == len(base["times"]) == 5
    assert base["frames"][0].shape[1] == 4

    terra = ulc.terra.search(base["frames"][0], target["frames"][0])
    assert terra["success"], terra["reason"]
    guess = np.eye(4)
    guess[:3, :3] = terra["rotation"]
    rotation_deg, _ = errors(guess, T_true)
    assert rotation_deg < 2.0

    jeep = ulc.jeep.run(base["frames"], base["times"], target["frames"], target["times"], guess)
    assert jeep["success"], jeep["reason"]
    rotation_deg, translation_m = errors(jeep["T_base_target"], T_true)
    assert rotation_deg < 0.5 and translation_m < 0.05


def test_simulate_is_deterministic():
    a = ulc.simulate("64-32", seconds=0.2, seed=5, decimation=8)
    b = ulc.simulate("64-32", seconds=0.2, seed=5, decimation=8)
    for la, lb in zip(a["lidars"], b["lidars"]):
        np.testing.assert_array_equal(la["times"], lb["times"])
        for fa, fb in zip(la["frames"], lb["frames"]):
            np.testing.assert_array_equal(fa, fb)
