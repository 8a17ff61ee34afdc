"""Shared fixtures: the shipped data and the obsgroup command (OBSGROUP_COMMAND, set by ctest)."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "data"


@pytest.fixture(scope="session")
def data() -> Path:
    return DATA


def run_command(input_path, output, *options):
    """`obsgroup partition INPUT -o OUTPUT -q --no-pictures OPTIONS`: the executable when the build
    gives one (ctest sets OBSGROUP_COMMAND), else the module's partition(), which runs the same code."""
    import json
    import obsgroup

    command = os.environ.get("OBSGROUP_COMMAND") or shutil.which("obsgroup")
    if command:
        subprocess.run([command, "partition", str(input_path), "-o", str(output), "-q", "--no-pictures",
                        *map(str, options)], check=True)
        with open(Path(output) / "partition.json", encoding="utf-8") as f:
            return json.load(f)
    words = list(options)
    kwargs = {}
    while words:
        name = words.pop(0)[2:].replace("-", "_")
        kwargs[name] = words.pop(0)
    return obsgroup.partition(input_path, output, no_pictures=True, **kwargs)
