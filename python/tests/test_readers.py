"""obsgroup.read gives what the command's readers give, as numpy views, and words bad input as the command."""

import gzip
import json

import numpy as np
import pytest

import obsgroup


def test_a_carmen_log_reads_into_numpy(data):
    scans = obsgroup.read(data / "office_2d" / "office.clf")
    assert scans.format == "carmen"
    assert len(scans) == 77
    first = scans[0]
    assert first.points.shape == (len(first), 3) and first.points.dtype == np.float32
    assert (first.points[:, 2] == 0).all()  # 2D scans have z = 0
    assert first.pose.shape == (4, 4) and first.pose.dtype == np.float64
    assert np.allclose(first.pose[3], [0, 0, 0, 1])
    assert first.stamp is not None
    assert first.source.endswith("office.clf:" + first.source.rsplit(":", 1)[1])
    assert first.point_type == "xyz" and first.intensity is None and first.colors is None


def test_points_are_a_read_only_view_of_the_cloud_not_a_copy(data):
    scan = obsgroup.read(data / "office_2d" / "office.clf")[3]
    a, b = scan.points, scan.points
    assert np.shares_memory(a, b)  # both views of the one cloud
    assert not a.flags.writeable
    with pytest.raises(ValueError):
        a[0, 0] = 1.0
    del scan  # the view keeps the cloud alive
    assert np.isfinite(a).all()


def test_the_same_sequence_as_a_log_and_as_pcd_files_reads_alike(data):
    folder = data / "real" / "localization_demo"
    log = obsgroup.read(folder / "localization_demo.clf")
    clouds = obsgroup.read(folder / "pcd")
    assert clouds.format == "pcd" and len(clouds) == len(log) == 72
    for a, b in zip(log, clouds):  # the log has the laser's pose, the PCD files the robot's
        world_a = a.points @ a.pose[:3, :3].T + a.pose[:3, 3]
        world_b = b.points @ b.pose[:3, :3].T + b.pose[:3, 3]
        assert 0 < len(b) <= len(a)  # the PCD export thins points closer than 2 cm to the last
        nearest = np.sqrt(((world_b[:, None, :] - world_a[None, :, :]) ** 2).sum(-1)).min(axis=1)
        assert nearest.max() < 1e-3


def test_depth_clouds_with_a_poses_file(data):
    clouds = obsgroup.read(data / "office_3d" / "pcd", poses=data / "office_3d" / "poses.txt")
    assert len(clouds) == 40
    assert clouds.parameters["poses"].endswith("poses.txt")
    assert all(np.ptp(c.points[:, 2]) > 0 for c in clouds)  # 3D points


def test_reader_options_reach_the_reader(data):
    full = obsgroup.read(data / "office_2d" / "office.clf")
    with pytest.warns(obsgroup.ObsgroupWarning, match="no return"):  # some scans see nothing within 3 m
        near = obsgroup.read(data / "office_2d" / "office.clf", max_range=3.0)
    assert near.parameters["max_range"] == 3.0
    assert sum(map(len, near)) < sum(map(len, full))
    assert all(np.linalg.norm(s.points, axis=1).max() < 3.0 for s in near if len(s))


def test_a_bad_line_raises_input_error_naming_file_line_and_field(data, tmp_path):
    lines = (data / "office_2d" / "office.clf").read_text().splitlines()
    numbered = [k for k, line in enumerate(lines) if line.startswith("ROBOTLASER1")]
    k = numbered[5]
    fields = lines[k].split()
    fields[8] = "many"  # the beam count
    lines[k] = " ".join(fields)
    bad = tmp_path / "bad.clf"
    bad.write_text("\n".join(lines) + "\n")
    with pytest.raises(obsgroup.InputError, match=rf"bad\.clf:{k + 1}:") as error:
        obsgroup.read(bad)
    assert isinstance(error.value, ValueError)
    # as the command does, skip_bad_lines makes it a warning
    with pytest.warns(obsgroup.ObsgroupWarning):
        scans = obsgroup.read(bad, skip_bad_lines=True)
    assert len(scans) == 76


def test_a_log_cut_short_and_missing_files_are_input_errors(data, tmp_path):
    cut = tmp_path / "cut.clf.gz"
    cut.write_bytes(gzip.compress((data / "office_2d" / "office.clf").read_bytes())[:-200])
    with pytest.raises(obsgroup.InputError, match="cut.clf.gz"):
        obsgroup.read(cut)
    with pytest.raises(obsgroup.InputError, match="no such file"):
        obsgroup.read(tmp_path / "missing.clf")


def test_options_that_do_not_fit_the_input_are_usage_errors(data):
    with pytest.raises(obsgroup.UsageError, match="intrinsics="):
        obsgroup.read(data / "office_2d" / "office.clf", intrinsics=(500, 500, 320, 240))
    with pytest.raises(TypeError, match="ncut_threshold"):
        obsgroup.read(data / "office_2d" / "office.clf", ncut_threshold=0.8)


def test_a_users_observation_from_numpy(data):
    points = np.random.default_rng(1).uniform(-3, 3, (100, 3))
    observation = obsgroup.Observation(points, np.eye(4), stamp=2.5, source="mine")
    assert np.allclose(observation.points, points.astype(np.float32))
    assert observation.stamp == 2.5 and observation.source == "mine" and len(observation) == 100


def make_datasets():
    """The generator of the shipped data (ctest and CI set OBSGROUP_MAKE_DATASETS): it writes bags."""
    import os

    return os.environ.get("OBSGROUP_MAKE_DATASETS")


@pytest.mark.skipif(not make_datasets(), reason="needs examples/make_datasets (OBSGROUP_MAKE_DATASETS)")
@pytest.mark.parametrize("kind", ["ros1", "ros2"])
def test_a_ros_bag_reads_and_groups_as_the_command_reads_it(data, tmp_path, kind):
    import subprocess
    from conftest import run_command

    bag = tmp_path / ("office.bag" if kind == "ros1" else "office_ros2")
    made = subprocess.run([make_datasets(), f"--{kind}-bag", str(bag)], capture_output=True, text=True)
    if made.returncode != 0:
        pytest.skip(f"this build writes no {kind} bags: {made.stderr.strip()}")
    scans = obsgroup.read(bag, topic="scan")  # the command's topic matching: /scan
    assert scans.format == kind and len(scans) == 77
    assert all(s.stamp is not None and "/scan" in s.source for s in scans)
    log = obsgroup.read(data / "office_2d" / "office.clf")
    assert all(np.allclose(a.points, b.points, atol=1e-4) for a, b in zip(scans, log))
    grouping = obsgroup.Grouping()
    grouping.extend(scans)
    assert grouping.compute().groups == run_command(bag, tmp_path / "out", "--topic", "scan")["groups"]
