"""The build backend of `pip install .` (PEP 517): CMake builds the extension with what the
system has (Debian's PCL, Eigen, pybind11, ...), and the wheel is zipped here. Nothing is
downloaded and no build package is needed beyond the standard library.

The CMake build folder is ``build-python/`` at the repository root (kept, so that a second
``pip install .`` only rebuilds what changed). ``OBSGROUP_CMAKE_ARGS`` adds arguments to the
CMake configure step; ``OBSGROUP_BUILD_JOBS`` sets the parallel jobs (default: every core).
"""

from __future__ import annotations

import base64
import hashlib
import os
import shlex
import subprocess
import sys
import sysconfig
import tarfile
import zipfile
from pathlib import Path

NAME = "obsgroup"
VERSION = "0.1.0"
ROOT = Path(__file__).resolve().parents[2]
SUMMARY = ("Group robot observations (2D scans, 3D clouds) into consistent local maps and a "
           "metric-topological map")


def _metadata() -> str:
    readme = (ROOT / "python" / "README.md").read_text(encoding="utf-8")
    return (
        "Metadata-Version: 2.1\n"
        f"Name: {NAME}\n"
        f"Version: {VERSION}\n"
        f"Summary: {SUMMARY}\n"
        "License: BSD-3-Clause\n"
        "Requires-Python: >=3.8\n"
        "Requires-Dist: numpy\n"
        "Provides-Extra: scipy\n"
        "Requires-Dist: scipy; extra == \"scipy\"\n"
        "Description-Content-Type: text/markdown\n"
        "\n" + readme)


def _tag() -> str:
    python = f"cp{sys.version_info.major}{sys.version_info.minor}"
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return f"{python}-{python}-{platform}"


def _cmake_build() -> Path:
    """Configures and builds the extension; returns the folder holding the package."""
    build = ROOT / "build-python"
    configure = [
        "cmake", "-S", str(ROOT), "-B", str(build),
        "-DCMAKE_BUILD_TYPE=Release",
        "-DOBSGROUP_BUILD_SHARED=OFF",      # one self-contained extension: the libraries inside it
        "-DOBSGROUP_BUILD_TESTS=OFF", "-DOBSGROUP_BUILD_EXAMPLES=OFF",
        "-DOBSGROUP_BUILD_PYTHON=ON", "-DOBSGROUP_PYTHON_INSTALL=OFF",
        f"-DPython_EXECUTABLE={sys.executable}",
    ] + shlex.split(os.environ.get("OBSGROUP_CMAKE_ARGS", ""))
    jobs = os.environ.get("OBSGROUP_BUILD_JOBS", str(os.cpu_count() or 1))
    for command in (configure, ["cmake", "--build", str(build), "--target", "obsgroup_python", "-j", jobs]):
        print("obsgroup:", " ".join(command), file=sys.stderr, flush=True)
        subprocess.run(command, check=True, stdout=sys.stderr)
    return build / "python" / NAME


def _record_line(name: str, data: bytes) -> str:
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{name},sha256={digest},{len(data)}"


def _write_wheel(wheel_directory: str, files: dict) -> str:
    dist_info = f"{NAME}-{VERSION}.dist-info"
    files = dict(files)
    files[f"{dist_info}/METADATA"] = _metadata().encode()
    files[f"{dist_info}/WHEEL"] = (
        "Wheel-Version: 1.0\nGenerator: obsgroup_build\nRoot-Is-Purelib: false\n"
        f"Tag: {_tag()}\n").encode()
    files[f"{dist_info}/LICENSE"] = (ROOT / "LICENSE").read_bytes()
    record = [_record_line(name, data) for name, data in files.items()] + [f"{dist_info}/RECORD,,"]
    files[f"{dist_info}/RECORD"] = ("\n".join(record) + "\n").encode()
    wheel_name = f"{NAME}-{VERSION}-{_tag()}.whl"
    with zipfile.ZipFile(Path(wheel_directory) / wheel_name, "w", zipfile.ZIP_DEFLATED) as wheel:
        for name, data in files.items():
            info = zipfile.ZipInfo(name, date_time=(2026, 1, 1, 0, 0, 0))
            info.external_attr = (0o755 if name.endswith(".so") else 0o644) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            wheel.writestr(info, data)
    return wheel_name


# --- PEP 517 -------------------------------------------------------------------------------------

def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    """The metadata alone, without building (pip asks for it first)."""
    dist_info = Path(metadata_directory) / f"{NAME}-{VERSION}.dist-info"
    dist_info.mkdir(parents=True, exist_ok=True)
    (dist_info / "METADATA").write_text(_metadata(), encoding="utf-8")
    return dist_info.name


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    package = _cmake_build()
    files = {}
    for path in sorted(package.iterdir()):
        if path.is_file() and not path.name.endswith(".pyc"):
            files[f"{NAME}/{path.name}"] = path.read_bytes()
    if not any(name.endswith(".so") for name in files):
        raise RuntimeError(f"the extension was not built in {package}")
    return _write_wheel(wheel_directory, files)


def build_sdist(sdist_directory, config_settings=None):
    """The tracked files of the repository (git ls-files) as a source archive."""
    listed = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-z"], check=True, capture_output=True).stdout
    base = f"{NAME}-{VERSION}"
    name = f"{base}.tar.gz"
    with tarfile.open(Path(sdist_directory) / name, "w:gz") as archive:
        for relative in filter(None, listed.decode().split("\0")):
            archive.add(ROOT / relative, arcname=f"{base}/{relative}", recursive=False)
    return name
