"""The module gives the command's groups, with the command's options and errors."""

import numpy as np
import pytest

import obsgroup
from conftest import run_command

MODELS = ["visibility", "free-space", "points"]


@pytest.mark.parametrize("model", MODELS)
def test_grouping_gives_the_commands_groups_on_the_2d_log(data, tmp_path, model):
    log = data / "office_2d" / "office.clf"
    expected = run_command(log, tmp_path / "out", "--sso", model)
    grouping = obsgroup.Grouping(model=model)
    grouping.extend(obsgroup.read(log))
    partition = grouping.compute()
    assert partition.groups == expected["groups"]
    assert len(partition) == len(expected["groups"]) > 1


@pytest.mark.parametrize("model", MODELS)
def test_grouping_gives_the_commands_groups_on_the_depth_clouds(data, tmp_path, model):
    folder = data / "office_3d" / "pcd"
    poses = data / "office_3d" / "poses.txt"
    expected = run_command(folder, tmp_path / "out", "--sso", model, "--poses", poses)
    grouping = obsgroup.Grouping(model=model)
    grouping.extend(obsgroup.read(folder, poses=poses))
    assert grouping.compute().groups == expected["groups"]


def test_the_paper_preset_and_options_reach_the_grouping(data, tmp_path):
    log = data / "real" / "sena_odometry" / "sena_odometry.clf"
    expected = run_command(log, tmp_path / "paper", "--paper")
    grouping = obsgroup.Grouping(paper=True)
    grouping.extend(obsgroup.read(log))
    assert grouping.parameters["model"] == "points"
    assert grouping.parameters["ncut_threshold"] == 1.0
    assert grouping.compute().groups == expected["groups"]
    # The command corrects this log's raw odometry before grouping;
    # correct_odometry does the same, and Grouping groups at the poses given.
    expected = run_command(log, tmp_path / "threshold", "--ncut-threshold", "0.9", "--cell", "0.25")
    assert expected["statistics"]["odometry_correction"]["applied"]
    corrected, report = obsgroup.correct_odometry(obsgroup.read(log))
    assert report["applied"] and report["matched"] == expected["statistics"]["odometry_correction"]["matched"]
    grouping = obsgroup.Grouping(ncut_threshold=0.9, cell=0.25, threads=1)
    grouping.extend(corrected)
    assert grouping.compute().groups == expected["groups"]
    expected = run_command(log, tmp_path / "as_given", "--ncut-threshold", "0.9", "--cell", "0.25",
                           "--correct-odometry", "off")
    grouping = obsgroup.Grouping(ncut_threshold=0.9, cell=0.25, threads=1)
    grouping.extend(obsgroup.read(log))
    assert grouping.compute().groups == expected["groups"]


def test_correct_odometry_keeps_exact_poses_and_the_clouds(data):
    scans = obsgroup.read(data / "office_2d" / "office.clf")
    corrected, report = obsgroup.correct_odometry(scans)
    assert not report["applied"] and report["sampled"] > 0 and report["sample_matched"] == 0
    for a, b in zip(scans, corrected):
        assert np.array_equal(a.pose, b.pose) and np.array_equal(a.points, b.points)
    corrected, report = obsgroup.correct_odometry(scans, mode="off")
    assert report["steps"] == 0
    with pytest.raises(ValueError):
        obsgroup.correct_odometry(scans, mode="sometimes")


def test_correct_odometry_reports_the_beams_through_walls(data):
    # sena_odometry's poses are raw odometry: fewer beams cross a wall once corrected
    scans = obsgroup.read(data / "real" / "sena_odometry" / "sena_odometry.clf")
    corrected, report = obsgroup.correct_odometry(scans)
    assert report["applied"]
    assert 0 < report["corrected_blocked_share"] < 0.8 * report["input_blocked_share"] <= 0.8
    # its odometry over-counts turns, and the matched steps say by how much
    assert report["odometry_bias"]["turn_scale"] < -0.1 and report["odometry_bias"]["steps"] > 100


def test_the_defaults_are_the_commands():
    parameters = obsgroup.Grouping().parameters
    assert parameters["model"] == "visibility"
    assert parameters["cell"] == 0.2 and parameters["range"] == 6.0
    assert parameters["ncut_threshold"] == 0.7 and parameters["split"] == "best"


def test_points_from_numpy_group_as_the_same_observations_read(data):
    scans = obsgroup.read(data / "office_2d" / "office.clf")
    from_files = obsgroup.Grouping()
    from_files.extend(scans)
    from_arrays = obsgroup.Grouping()
    for scan in scans:
        x, y = scan.pose[0, 3], scan.pose[1, 3]
        theta = np.arctan2(scan.pose[1, 0], scan.pose[0, 0])
        # (n, 2) float64 points and an (x, y, theta) pose, as a user holding 2D scans has them
        index = from_arrays.add(scan.points[:, :2].astype(np.float64), (x, y, theta))
        assert index == len(from_arrays) - 1
    a, b = from_files.compute(), from_arrays.compute()
    assert a.groups == b.groups
    assert np.array_equal(a.group_of, b.group_of)


def test_partition_gives_groups_group_of_weights_and_splits(data):
    grouping = obsgroup.Grouping()
    grouping.extend(obsgroup.read(data / "office_2d" / "office.clf"))
    partition = grouping.compute()
    n = len(grouping)
    assert partition.group_of.shape == (n,) and partition.group_of.dtype == np.int64
    for g, members in enumerate(partition.groups):
        assert all(partition.group_of[i] == g for i in members)
    W = partition.weights
    assert W.shape == (n, n)
    dense = W.toarray()
    assert np.allclose(dense, dense.T) and (dense >= 0).all() and dense.max() <= 1.0
    assert W.nnz > n
    root = partition.splits[0]
    assert sorted(root["members"]) == list(range(n))
    assert root["kind"] in ("bisection", "components")
    assert set(grouping.timings) == {"overlap", "graph", "partition"}


def test_results_do_not_depend_on_the_thread_count(data):
    scans = obsgroup.read(data / "real" / "localization_demo" / "localization_demo.clf")
    groups = []
    for threads in (1, 2, 3):
        grouping = obsgroup.Grouping(threads=threads)
        grouping.extend(scans)
        groups.append(grouping.compute().groups)
    assert groups[0] == groups[1] == groups[2]


def test_usage_errors_are_the_commands_in_python_words():
    with pytest.raises(obsgroup.UsageError, match="cell="):
        obsgroup.Grouping(cell=-1)
    with pytest.raises(ValueError, match="delta= applies to sso= points"):
        obsgroup.Grouping(delta=0.2)
    with pytest.raises(ValueError, match="paper"):
        obsgroup.Grouping(paper=True, ncut_threshold=0.5)
    with pytest.raises(ValueError):
        obsgroup.Grouping(model="voxels")
    with pytest.raises(TypeError, match="did you mean ncut_threshold="):
        obsgroup.Grouping(ncut_treshold=0.8)
    with pytest.raises(TypeError, match="Grouping"):
        obsgroup.Grouping(laser="front")  # a reader option: read() takes it


def test_bad_points_and_poses_are_value_errors():
    grouping = obsgroup.Grouping()
    with pytest.raises(ValueError, match="shape"):
        grouping.add(np.zeros((5, 4)), np.eye(4))
    with pytest.raises(ValueError, match="rotation"):
        grouping.add(np.zeros((5, 3)), np.diag([2.0, 1.0, 1.0, 1.0]))
    with pytest.raises(ValueError, match="pose"):
        grouping.add(np.zeros((5, 3)), [1.0, 2.0])
    with pytest.raises(TypeError):
        grouping.add(np.zeros((5, 3)))
    assert len(grouping) == 0


def test_progress_is_reported_one_step_at_a_time(data):
    import threading

    seen, inside = [], threading.Lock()

    def progress(stage, done, total):
        assert inside.acquire(blocking=False), "two calls at once"
        seen.append((stage, done, total))
        inside.release()

    grouping = obsgroup.Grouping()
    grouping.extend(obsgroup.read(data / "office_2d" / "office.clf"))
    grouping.compute(progress=progress)
    assert seen, "no progress reported"
    assert all(stage == "overlap" and 0 <= done <= total == len(grouping) for stage, done, total in seen)
    assert max(done for _, done, _ in seen) == len(grouping)


def test_ctrl_c_stops_compute_and_leaves_the_grouping_usable(data):
    import os
    import signal

    grouping = obsgroup.Grouping()
    grouping.extend(obsgroup.read(data / "real" / "sena_odometry" / "sena_odometry.clf"))
    calls = []

    def interrupt(stage, done, total):
        calls.append(done)
        if len(calls) == 1:
            os.kill(os.getpid(), signal.SIGINT)  # what Ctrl-C sends

    with pytest.raises(KeyboardInterrupt):
        grouping.compute(progress=interrupt)
    assert len(grouping.compute().groups) > 1


def test_a_callback_that_raises_stops_compute_with_its_error(data):
    grouping = obsgroup.Grouping()
    grouping.extend(obsgroup.read(data / "office_2d" / "office.clf"))

    def fail(stage, done, total):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        grouping.compute(progress=fail)


def test_another_thread_using_a_computing_grouping_gets_an_error(data):
    import threading

    scans = obsgroup.read(data / "office_2d" / "office.clf")
    grouping = obsgroup.Grouping()
    grouping.extend(scans)
    errors = []

    def add_from_another_thread():
        try:
            grouping.add(scans[0])
        except RuntimeError as e:
            errors.append(str(e))

    def progress(stage, done, total):
        if not errors:
            thread = threading.Thread(target=add_from_another_thread)
            thread.start()
            thread.join()

    grouping.compute(progress=progress)
    assert errors and "busy" in errors[0]
    assert len(grouping) == len(scans)  # nothing was added while it computed
