"""The Python examples run as a user runs them, and say what the module computes."""

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

import obsgroup

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "python"


def run(script, *arguments):
    return subprocess.run([sys.executable, str(EXAMPLES / script), *map(str, arguments)], check=True,
                          capture_output=True, text=True, env=dict(os.environ)).stdout


@pytest.mark.skipif(importlib.util.find_spec("matplotlib") is None, reason="needs matplotlib (python3-matplotlib)")
def test_group_log_plots_the_places(data, tmp_path):
    picture = tmp_path / "groups.png"
    out = run("group_log.py", data / "office_2d" / "office.clf", picture)
    grouping = obsgroup.Grouping()
    grouping.extend(obsgroup.read(data / "office_2d" / "office.clf"))
    assert out.startswith(f"{len(grouping.compute())} places; wrote")
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and picture.stat().st_size > 20000


@pytest.mark.skipif(importlib.util.find_spec("open3d") is None, reason="needs Open3D (python3-open3d)")
def test_open3d_clouds_group_as_the_clouds_read_by_obsgroup(data):
    folder, poses = data / "office_3d" / "pcd", data / "office_3d" / "poses.txt"
    out = run("open3d_clouds.py", folder, poses)
    grouping = obsgroup.Grouping()
    grouping.extend(obsgroup.read(folder, poses=poses))
    partition = grouping.compute()
    assert out.splitlines()[-1] == f"40 clouds, {len(partition)} places"
    for g, members in enumerate(partition.groups):
        assert f"place {g}: clouds {members[0]}-{members[-1]} ({len(members)})" in out
