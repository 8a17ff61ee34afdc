"""The online grouping ends with the batch's groups; local maps, places and the command from Python."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import obsgroup


def batch_groups(observations, **options):
    grouping = obsgroup.Grouping(**options)
    grouping.extend(observations)
    return grouping.compute().groups


def test_online_grouping_equals_the_batch_after_every_exact_update(data):
    scans = obsgroup.read(data / "office_2d" / "office.clf")
    online = obsgroup.OnlineGrouping()
    created = set()
    for k, scan in enumerate(scans):
        assert online.insert(scan) == k
        if (k + 1) % 20 == 0 or k + 1 == len(scans):
            changes = online.update()
            assert all(isinstance(c, obsgroup.Change) for c in changes)
            created |= {c.place for c in changes if c.kind == "created"}
            groups = sorted(online.groups.values())  # each update's groups: before the passages join some
            assert groups == sorted(batch_groups(scans[: k + 1], join_passages=False))
            assert online.partition().groups == batch_groups(scans[: k + 1])
    assert set(online.groups) <= created | {c for c in online.groups}
    assert all(online.place_of(i) in online.groups for i in range(len(scans)))


def test_online_updates_poses_and_removals(data):
    scans = obsgroup.read(data / "office_2d" / "office.clf")
    online = obsgroup.OnlineGrouping()
    for scan in scans:
        online.insert(scan)
    online.update()
    online.remove(10)
    moved = scans[20].pose.copy()
    moved[0, 3] += 0.05
    online.update_pose(20, moved)
    changes = online.update()
    assert changes, "a removal and a move change some place"
    assert 10 not in online.ids and all(10 not in m for m in online.groups.values())
    kept = [obsgroup.Observation(s.points, moved if i == 20 else s.pose) for i, s in enumerate(scans) if i != 10]
    ids = [i for i in range(len(scans)) if i != 10]
    expected = sorted([ids[k] for k in g] for g in batch_groups(kept, join_passages=False))
    assert sorted(online.groups.values()) == expected
    assert online.partition().groups == batch_groups(kept)
    with pytest.raises(IndexError, match="no observation 10"):
        online.update_pose(10, np.eye(4))  # removed


def test_local_maps_and_the_topological_map(data):
    scans = obsgroup.read(data / "office_2d" / "office.clf")
    grouping = obsgroup.Grouping()
    grouping.extend(scans)
    partition = grouping.compute()
    maps = obsgroup.build_local_maps(scans, partition, refine="icp")
    assert len(maps.local_maps) == len(partition)
    for local_map, group in zip(maps.local_maps, partition.groups):
        assert local_map.members == group
        assert local_map.reference in group
        assert local_map.points.shape[1] == 3 and len(local_map.points) > 100
        assert local_map.member_poses.shape == (len(group), 4, 4)
    assert maps.arcs and all(a["from"] < a["to"] < len(partition) for a in maps.arcs)
    assert maps.arcs[0]["transform"].shape == (4, 4)
    with pytest.raises(ValueError, match="refinement"):
        obsgroup.build_local_maps(scans, partition, refine="best")


def test_partition_runs_the_command_and_places_locate_poses(data, tmp_path):
    log = data / "office_2d" / "office.clf"
    result = obsgroup.partition(log, tmp_path / "out", no_pictures=True)
    assert result["groups"] == batch_groups(obsgroup.read(log))
    assert (tmp_path / "out" / "places.json").exists()
    with pytest.raises(obsgroup.UsageError, match="force="):
        obsgroup.partition(log, tmp_path / "out", no_pictures=True)
    places = obsgroup.Places(tmp_path / "out")
    assert len(places) == len(result["groups"]) and places.doors
    scans = obsgroup.read(log)
    ids = result["place_ids"]
    located = [places.locate(s.pose).place == ids[g] for g, members in enumerate(result["groups"]) for s in
               (scans[i] for i in members)]
    assert sum(located) >= 0.9 * len(located)
    assert places.locate((1000.0, 1000.0)).place is None


def test_a_folder_without_places_is_an_input_error(tmp_path):
    with pytest.raises(ValueError):
        obsgroup.Places(tmp_path)


def test_partition_reports_the_progress_of_every_stage(data, tmp_path):
    steps = []
    obsgroup.partition(data / "office_3d" / "pcd", tmp_path / "out", poses=data / "office_3d" / "poses.txt",
                       progress=lambda stage, done, total: steps.append((stage, done, total)))
    stages = []
    for stage, done, total in steps:
        assert 0 <= done <= total
        if not stages or stages[-1] != stage:
            stages.append(stage)
    assert stages == ["read", "overlap", "local maps", "places", "pictures"]
    last = {stage: (done, total) for stage, done, total in steps}
    assert all(done == total for done, total in last.values())  # each stage ends complete



@pytest.mark.parametrize("given, sleeps", [(None, True), ("active", False)])
def test_openmp_threads_sleep_when_idle_unless_the_user_chose(given, sleeps):
    # How long idle threads spin, as OpenMP read it when the extension loaded its runtime
    # (OMP_DISPLAY_ENV=verbose, on standard error; "0": they sleep at once), and the environment
    # handed to the user's own processes left as it was.
    env = {k: v for k, v in os.environ.items() if k != "OMP_WAIT_POLICY"}
    env["OMP_DISPLAY_ENV"] = "verbose"
    if given is not None:
        env["OMP_WAIT_POLICY"] = given
    script = "import os, obsgroup; print(os.environ.get('OMP_WAIT_POLICY'))"
    out = subprocess.run([sys.executable, "-c", script], env=env, check=True, capture_output=True, text=True)
    spins = [line.strip() for line in out.stderr.splitlines() if "GOMP_SPINCOUNT = " in line]
    assert spins, out.stderr
    assert (spins[-1] == "GOMP_SPINCOUNT = '0'") == sleeps
    assert out.stdout.strip() == str(given)
