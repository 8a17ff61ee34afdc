"""Type stubs of the C++ extension behind the package ``obsgroup`` (use the package, not this module)."""

from typing import Any, Callable, Dict, List, Optional, Tuple

import numpy as np
import numpy.typing as npt

class InputError(ValueError):
    """Input that cannot be read: the message names the file, line and field."""

class UsageError(ValueError):
    """An option out of range, or one that does not fit the input or the model."""

class Observation:
    """One observation: points in the sensor frame and the sensor's pose."""

    def __init__(self, points: npt.ArrayLike, pose: npt.ArrayLike, stamp: Optional[float] = None,
                 source: str = "") -> None: ...
    @property
    def points(self) -> npt.NDArray[np.float32]:
        """(n, 3) float32, read-only: a view of the cloud (2D scans have z = 0)."""
    @property
    def pose(self) -> npt.NDArray[np.float64]:
        """4x4 float64: the sensor's pose in the world frame."""
    @property
    def stamp(self) -> Optional[float]:
        """When it was sensed, seconds (logs and bags), or None."""
    @property
    def source(self) -> str:
        """Where it came from: file and line, file, or bag message."""
    @property
    def point_type(self) -> str:
        """'xyz', 'xyzi' or 'xyzrgb'."""
    @property
    def intensity(self) -> Optional[npt.NDArray[np.float32]]:
        """(n,) float32 intensities of an xyzi cloud, else None."""
    @property
    def colors(self) -> Optional[npt.NDArray[np.uint8]]:
        """(n, 3) uint8 RGB of an xyzrgb cloud, else None."""
    def __len__(self) -> int: ...

class LocalMap:
    """One local map: its members' points merged in its reference frame."""

    @property
    def points(self) -> npt.NDArray[np.float32]:
        """(n, 3) float32, read-only: the merged, voxel-filtered points in the reference frame."""
    @property
    def members(self) -> List[int]:
        """Observation indices, ascending."""
    @property
    def reference(self) -> int:
        """The observation whose frame the map is in."""
    @property
    def pose(self) -> npt.NDArray[np.float64]:
        """4x4: the reference observation's pose in the world frame."""
    @property
    def member_poses(self) -> npt.NDArray[np.float64]:
        """(k, 4, 4): each member's (refined) pose in the reference frame."""
    @property
    def filtered(self) -> bool:
        """False when the map was too large for the voxel filter and kept whole."""

class _Partition:
    groups: List[List[int]]
    group_of: npt.NDArray[np.int64]
    splits: List[Dict[str, Any]]
    warnings: List[str]
    def weight_arrays(self) -> Tuple[npt.NDArray[np.int64], npt.NDArray[np.int64], npt.NDArray[np.float64], int]: ...

class _Grouping:
    def __init__(self, words: List[str]) -> None: ...
    def add(self, observation: Observation) -> int: ...
    def add_points(self, points: npt.ArrayLike, pose: npt.NDArray[np.float64]) -> int: ...
    def __len__(self) -> int: ...
    def compute(self, progress: Optional[Callable[[str, int, int], Any]] = None) -> _Partition: ...
    def timings(self) -> Dict[str, float]: ...
    def parameters(self) -> Dict[str, Any]: ...

class _OnlineGrouping:
    def __init__(self, words: List[str], exact_every: int) -> None: ...
    def insert(self, observation: Observation) -> int: ...
    def insert_points(self, points: npt.ArrayLike, pose: npt.NDArray[np.float64]) -> int: ...
    def update_pose(self, id: int, pose: npt.NDArray[np.float64]) -> None: ...
    def remove(self, id: int) -> None: ...
    def update(self, exact: bool = False) -> Dict[str, Any]: ...
    def groups(self) -> Dict[int, List[int]]: ...
    def group_of(self, id: int) -> int: ...
    def ids(self) -> List[int]: ...
    def partition(self) -> _Partition: ...

class _PlaceMap:
    def locate(self, x: float, y: float, tolerance: float) -> Tuple[Optional[int], float]: ...

def _read(words: List[str], progress: Optional[Callable[[str, int, int], Any]] = None
          ) -> Tuple[List[Observation], List[str], str, str]: ...
def _run_command(words: List[str], progress: Optional[Callable[[str, int, int], Any]] = None) -> int: ...
def _correct_odometry(observations: List[Observation], mode: str, threads: int) -> Tuple[List[Observation], Dict[str, Any]]: ...
def _build_local_maps(observations: List[Observation], partition: _Partition, refine: str, voxel: float,
                      threads: int, progress: Optional[Callable[[str, int, int], Any]]
                      ) -> Tuple[List[LocalMap], List[Dict[str, Any]]]: ...
def _read_place_labels(folder: str) -> _PlaceMap: ...
