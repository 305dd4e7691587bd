"""ulc.calibrate against the `ulc` command and the simulator's ground truth."""
import json
import os

import numpy as np
import pytest

import ulc
from conftest import errors, lidar, run_ulc, truth, without_timings


@pytest.fixture(scope="module")
def cli_result(drive, tmp_path_factory):
    """`ulc calibrate` of the drive's pair, every default stage, as its result file."""
    out = str(tmp_path_factory.mktemp("cli") / "result.json")
    code, stdout, stderr = run_ulc("calibrate", "--quiet", "--base", lidar(drive, "lidar64"),
                                   "--target", lidar(drive, "lidar32"), "--synced-clocks",
                                   "--output", out)
    assert code == 0, stdout + stderr
    with open(out) as f:
        return f.read()


@pytest.fixture(scope="module")
def frames(drive):
    """Both LiDARs' frames as numpy arrays (x y z t, float64) and their timestamps."""
    return {name: ulc.read_frames(lidar(drive, name)) for name in ("lidar64", "lidar32")}


def test_paths_give_the_command_lines_result_file(drive, cli_result):
    result = ulc.calibrate(lidar(drive, "lidar64"), lidar(drive, "lidar32"), synced_clocks=True)
    assert result.success, result.reason
    assert (result.base, result.target) == ("lidar64", "lidar32")
    cli = json.loads(cli_result)
    ours = json.loads(result.to_json())
    assert without_timings(ours) == without_timings(cli)
    expected = np.array(cli["results"][0]["T_base_target"])
    np.testing.assert_array_equal(result.T_base_target, expected)
    rotation_deg, translation_m = errors(result.T_base_target, truth(drive))
    assert rotation_deg < 0.5 and translation_m < 0.05


def test_yaml_is_the_command_lines(drive, tmp_path):
    result = ulc.calibrate(lidar(drive, "lidar64"), lidar(drive, "lidar32"), stages="terra")
    path = tmp_path / "r.yaml"
    result.write(str(path), format="yaml")
    assert path.read_text() == result.to_yaml()
    assert "static_transform_publisher" in result.to_yaml()


def pair_from_arrays(frames, convert, **options):
    a, b = frames["lidar64"], frames["lidar32"]
    return ulc.calibrate([convert(f) for f in a["frames"]], [convert(f) for f in b["frames"]],
                         base_times=a["times"], target_times=b["times"],
                         names=["lidar64", "lidar32"], synced_clocks=True, **options)


def non_contiguous(f):
    """The same values seen through a view that skips every other column of a wider array."""
    wide = np.zeros((f.shape[0], 2 * f.shape[1]), dtype=np.float64)
    wide[:, ::2] = f
    view = wide[:, ::2]
    assert not view.flags.c_contiguous and not view.flags.f_contiguous
    return view


def test_arrays_of_any_dtype_and_layout_give_the_paths_answer(drive, frames):
    from_path = ulc.calibrate(lidar(drive, "lidar64"), lidar(drive, "lidar32"), synced_clocks=True)
    answers = {
        "float64": pair_from_arrays(frames, lambda f: f),
        # The frames were read as float32 (PointCloud<float>): float32 copies are exact.
        "float32": pair_from_arrays(frames, lambda f: f.astype(np.float32)),
        "non-contiguous": pair_from_arrays(frames, non_contiguous),
        "fortran": pair_from_arrays(frames, np.asfortranarray),
    }
    for name, result in answers.items():
        assert result.success, (name, result.reason)
        np.testing.assert_array_equal(result.T_base_target, from_path.T_base_target, err_msg=name)
        assert without_timings(json.loads(result.to_json())) == without_timings(
            json.loads(from_path.to_json())), name


def test_one_and_two_threads_give_the_same_result(frames):
    one = pair_from_arrays(frames, lambda f: f, threads=1)
    two = pair_from_arrays(frames, lambda f: f, threads=2)
    assert one.success
    assert without_timings(json.loads(one.to_json())) == without_timings(json.loads(two.to_json()))


def test_result_fields(drive):
    result = ulc.calibrate(lidar(drive, "lidar64"), lidar(drive, "lidar32"), synced_clocks=True)
    entry = json.loads(result.to_json())["results"][0]
    assert result.status == entry["status"] and result.reason == entry["reason"]
    assert result.time_offset_s == entry["time_offset_s"]
    np.testing.assert_array_equal(result.covariance_6x6, np.array(entry["covariance_6x6"]))
    assert set(result.stages) == set(entry["stages"]) and "terra" in result.stages
    assert result.stages["jeep"]["status"] == entry["stages"]["jeep"]["status"]
    assert result.to_dict()["T_base_target"] == entry["T_base_target"]


def test_a_rig_closes_its_cycle(frames):
    """Two copies of the same LiDAR as targets: both calibrate to the same extrinsic and the
    cycle base -> a -> b -> base closes."""
    a, b = frames["lidar64"], frames["lidar32"]
    rig = ulc.calibrate(a["frames"], targets=[b["frames"], b["frames"]], base_times=a["times"],
                        target_times=[b["times"], b["times"]], names=["base", "a", "b"],
                        stages="terra,jeep", synced_clocks=True)
    assert rig.success and len(rig.results) == 2
    assert [r.target for r in rig.results] == ["a", "b"]
    np.testing.assert_array_equal(rig.results[0].T_base_target, rig.results[1].T_base_target)
    assert len(rig.cycles) == 1 and rig.cycles[0]["lidars"] == ["base", "a", "b"]
    assert rig.cycles[0]["rotation_deg"] < 0.1 and rig.cycles[0]["translation_m"] < 0.01
    assert json.loads(rig.to_json())["cycles"][0]["lidars"] == ["base", "a", "b"]


def test_progress_reports_the_stages(drive):
    seen = []
    ulc.calibrate(lidar(drive, "lidar64"), lidar(drive, "lidar32"), stages="terra,jeep",
                  synced_clocks=True, progress=lambda stage, f: seen.append((stage, f)))
    stages = {s for s, _ in seen}
    assert {"lidar32 terra", "lidar32 jeep"} <= stages
    assert all(0.0 <= f <= 1.0 for _, f in seen)


def test_an_exception_in_progress_stops_the_call(drive):
    class Stop(Exception):
        pass

    def progress(stage, fraction):
        raise Stop(stage)

    with pytest.raises(Stop):
        ulc.calibrate(lidar(drive, "lidar64"), lidar(drive, "lidar32"), progress=progress)


def test_initial_guess_without_terra(drive, frames):
    T = truth(drive)
    a, b = frames["lidar64"], frames["lidar32"]
    result = ulc.calibrate(a["frames"], b["frames"], base_times=a["times"],
                           target_times=b["times"], stages=["jeep"], initial=T,
                           synced_clocks=True)
    assert result.success, result.reason
    rotation_deg, translation_m = errors(result.T_base_target, T)
    assert rotation_deg < 0.5 and translation_m < 0.05


def test_clouds_with_a_points_attribute_are_read_as_arrays(frames):
    """Open3D's PointCloud is read through numpy.asarray(cloud.points)."""
    class Cloud:
        def __init__(self, xyz):
            self.points = xyz

    a, b = frames["lidar64"]["frames"][0], frames["lidar32"]["frames"][0]
    from_arrays = ulc.calibrate(a[:, :3], b[:, :3], stages="terra")
    from_clouds = ulc.calibrate(Cloud(a[:, :3]), Cloud(b[:, :3]), stages="terra")
    assert from_arrays.success
    np.testing.assert_array_equal(from_clouds.T_base_target, from_arrays.T_base_target)


def test_base_odometry_is_the_command_lines(drive, tmp_path):
    """base_odometry=True is --base-odometry: HOTS from the base's own odometry, same result file."""
    guess = str(tmp_path / "guess.json")
    ulc.calibrate(lidar(drive, "lidar64"), lidar(drive, "lidar32"), stages="terra,jeep",
                  synced_clocks=True).write(guess)
    out = str(tmp_path / "result.json")
    code, stdout, stderr = run_ulc("calibrate", "--quiet", "--base", lidar(drive, "lidar64"),
                                   "--target", lidar(drive, "lidar32"), "--synced-clocks",
                                   "--stages", "hots", "--initial", guess, "--base-odometry",
                                   "--output", out)
    assert os.path.exists(out), stdout + stderr
    ours = ulc.calibrate(lidar(drive, "lidar64"), lidar(drive, "lidar32"), stages="hots",
                         initial=guess, synced_clocks=True, base_odometry=True)
    with open(out) as f:
        cli = json.load(f)
    assert without_timings(json.loads(ours.to_json())) == without_timings(cli)
    assert cli["results"][0]["stages"]["hots"]["odometry_reused"] is False
    assert cli["results"][0]["stages"]["hots"]["odometry"] == "base"
    # base_odometry=False is --joint-odometry; the default (None) lets the pipeline choose,
    # which on this short drive is the joint odometry too.
    joint = ulc.calibrate(lidar(drive, "lidar64"), lidar(drive, "lidar32"), stages="hots",
                          initial=guess, synced_clocks=True, base_odometry=False)
    chosen = ulc.calibrate(lidar(drive, "lidar64"), lidar(drive, "lidar32"), stages="hots",
                           initial=guess, synced_clocks=True)
    assert joint.stages["hots"]["odometry"] == "joint"
    assert chosen.stages["hots"]["odometry"] == "joint"
    np.testing.assert_array_equal(joint.T_base_target, chosen.T_base_target)
