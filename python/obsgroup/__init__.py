"""obsgroup: group robot observations into consistent local maps and a metric-topological map.

The method of Blanco, Gonzalez and Fernandez-Madrigal (ICRA 2006) as the C++ library and the
``obsgroup`` command run it, from Python, with numpy arrays in and out::

    import obsgroup
    scans = obsgroup.read("data/intel_lab.log.gz")         # any input the command reads
    grouping = obsgroup.Grouping()                         # the command's defaults
    grouping.extend(scans)
    partition = grouping.compute()
    print(len(partition), "places;", partition.group_of[:10])

Options are the command's, as keyword arguments with ``_`` for ``-`` (``ncut_threshold=0.8`` is
``--ncut-threshold 0.8``; ``model=`` is ``--sso``): the same defaults, the same checks, the same
messages. Bad input raises :class:`InputError`, a bad option :class:`UsageError` (both
``ValueError``). Long calls release the GIL and stop on Ctrl-C with ``KeyboardInterrupt``
(when made from the main thread, where Python handles signals).
"""

from __future__ import annotations

import difflib
import json
import math
import os
import re
import warnings
from typing import Any, Callable, Dict, Iterable, Iterator, List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np

# OpenMP reads this once, when its runtime loads with the extension below: idle threads then
# sleep instead of spinning, which on a busy machine (a robot's, or a notebook beside other
# work) take the cores the working threads wait for (the 1,001-scan stream: 26-30 s instead of
# 11 s beside one busy process; docs/performance.md). A value of the user's own is kept; it has
# no effect when another library loaded OpenMP's runtime first. Taken back once read, so that
# the processes the user starts do not inherit it.
_wait_policy_set = "OMP_WAIT_POLICY" not in os.environ
if _wait_policy_set:
    os.environ["OMP_WAIT_POLICY"] = "passive"
try:
    from . import _obsgroup  # noqa: E402
finally:
    if _wait_policy_set:
        del os.environ["OMP_WAIT_POLICY"]
del _wait_policy_set
from ._obsgroup import InputError, LocalMap, Observation, UsageError

__version__ = "0.1.0"

__all__ = [
    "InputError", "UsageError", "ObsgroupWarning", "Observation", "Observations", "read", "Grouping",
    "Partition", "OnlineGrouping", "Change", "LocalMap", "MetricTopologicalMap", "build_local_maps",
    "Places", "Location", "partition", "correct_odometry",
]

ProgressCallback = Callable[[str, int, int], Any]
"""Called as ``progress(stage, done, total)``, one call at a time, from whichever thread is doing the
work (with the GIL); if it raises, the work stops and the call raises its exception."""

PoseLike = Union[np.ndarray, Sequence[float], Sequence[Sequence[float]]]
"""A 4x4 homogeneous matrix, a 3x3 planar one, or ``(x, y, theta)`` (radians)."""


class ObsgroupWarning(UserWarning):
    """What the command prints as ``obsgroup: warning: ...`` (a skipped line, an empty cloud, ...)."""


# The command's options, by what they apply to (`obsgroup partition --help`).
_READER_OPTIONS = {
    "format", "laser", "fov", "max_range", "skip_bad_lines", "poses", "pose_format", "max_time_difference",
    "skip_bad_files", "intrinsics", "depth_scale", "depth_max", "up", "stride", "topic", "pose_topic",
    "fixed_frame", "voxel", "threads",
}
_METHOD_OPTIONS = {
    "sso", "model", "paper", "cell", "range", "clearance", "min_observations", "band", "door_width", "door_depth",
    "delta", "voxel", "ncut_threshold", "boundary_passes", "mutual_neighbours", "mutual_neighbours_share", "split",
    "open_floor_width", "join_passages", "min_group_size", "max_depth", "threads",
}
_COMMAND_OPTIONS = _READER_OPTIONS | _METHOD_OPTIONS | {
    "keyframes", "refine", "map_voxel", "force", "quiet", "no_pictures",
}
_FLAGS = {"skip_bad_lines", "skip_bad_files", "paper", "force", "quiet", "no_pictures"}
_SWITCHES = {"join_passages"}  # True or False, given to the command as on or off
_COMMA_LISTS = {"intrinsics", "keyframes"}  # one argument "a,b,c"; band is two arguments
_ALIASES = {"model": "sso"}


def _pythonic(message: str) -> str:
    """The command's message with its options as this module's keyword arguments."""
    return re.sub(r"--([a-z][a-z-]*)", lambda m: m.group(1).replace("-", "_") + "=", message)


def _words(options: Dict[str, Any], allowed: set, where: str) -> List[str]:
    """Keyword arguments as the command's arguments."""
    words: List[str] = []
    for name, value in options.items():
        if name not in allowed:
            near = difflib.get_close_matches(name, sorted(allowed), n=1)
            hint = f"; did you mean {near[0]}=?" if near else ""
            raise TypeError(f"{where}() got an unexpected keyword argument '{name}'{hint}")
        if value is None:
            continue
        option = "--" + _ALIASES.get(name, name).replace("_", "-")
        if name in _FLAGS or name in _SWITCHES:
            if not isinstance(value, (bool, np.bool_)):
                raise TypeError(f"{name}= is True or False, not {value!r}")
            if name in _SWITCHES:
                words += [option, "on" if value else "off"]
            elif value:
                words.append(option)
            continue
        if isinstance(value, (list, tuple, np.ndarray)):
            items = [_text(v) for v in value]
            words += [option, ",".join(items)] if name in _COMMA_LISTS else [option, *items]
        else:
            words += [option, _text(value)]
    return words


def _text(value: Any) -> str:
    if isinstance(value, (bool, np.bool_)):
        raise TypeError(f"expected a number or a name, not {value!r}")
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    text = str(value)
    return "free-space" if text == "free_space" else text


def _call(function: Callable, *args: Any, **kwargs: Any) -> Any:
    """Calls into the library, wording usage errors for Python."""
    try:
        return function(*args, **kwargs)
    except UsageError as e:
        raise UsageError(_pythonic(str(e))) from None


def _warn(messages: Iterable[str]) -> None:
    for message in messages:
        warnings.warn(message, ObsgroupWarning, stacklevel=3)


def _pose_matrix(pose: PoseLike) -> np.ndarray:
    """A 4x4 float64 pose from a 4x4 or 3x3 matrix or (x, y, theta)."""
    p = np.asarray(pose, dtype=np.float64)
    if p.shape == (4, 4):
        return np.ascontiguousarray(p)
    m = np.eye(4)
    if p.shape == (3,):
        x, y, theta = p
        c, s = math.cos(theta), math.sin(theta)
        m[:2, :2] = [[c, -s], [s, c]]
        m[:2, 3] = [x, y]
        return m
    if p.shape == (3, 3):
        m[:2, :2] = p[:2, :2]
        m[:2, 3] = p[:2, 2]
        return m
    raise ValueError(f"pose: a 4x4 matrix, a 3x3 planar matrix or (x, y, theta); got shape {p.shape}")


# --- reading ---------------------------------------------------------------------------------------

class Observations(list):
    """The observations of an input (a list of :class:`Observation`), with what reading it said."""

    format: str
    """The input's format: carmen, pcd, tum-rgbd, redwood, kitti, ros1 or ros2."""
    parameters: Dict[str, Any]
    """The reader settings actually used (as ``partition.json`` records them)."""
    warnings: List[str]
    """The readers' warnings (also issued as :class:`ObsgroupWarning`)."""


def read(path: Union[str, os.PathLike], *, progress: Optional[ProgressCallback] = None,
         **options: Any) -> Observations:
    """Reads any input the command reads: a CARMEN log (gzipped or not), a folder of PCD files,
    depth images (TUM RGB-D, Redwood), KITTI odometry, a ROS 1 bag or a ROS 2 bag.

    Keyword arguments are the command's reader options (``laser=``, ``fov=``, ``max_range=``,
    ``skip_bad_lines=``, ``poses=``, ``pose_format=``, ``intrinsics=(fx, fy, cx, cy)``,
    ``depth_scale=``, ``stride=``, ``topic=``, ``fixed_frame=``, ``voxel=``, ``threads=``, ...).
    Dense frames are reduced as they are read, as the command does.

    Raises :class:`InputError` naming the file, line and field of what cannot be read, and
    :class:`UsageError` for options that do not fit the input.
    """
    words = ["partition", os.fspath(path), "-o", os.devnull, "-q"] + _words(options, _READER_OPTIONS, "read")
    observations, messages, fmt, parameters = _call(_obsgroup._read, words, progress)
    out = Observations(observations)
    out.format = fmt
    out.parameters = json.loads(parameters)
    out.warnings = list(messages)
    _warn(messages)
    return out


def correct_odometry(observations: Sequence[Observation], *, mode: str = "auto",
                     threads: int = 0) -> Tuple[List[Observation], Dict[str, Any]]:
    """The observations at their poses corrected by scan matching, as the command corrects them
    before grouping (``--correct-odometry``): each aligned with the one before it from the step
    their poses give. ``mode="auto"`` keeps the poses unless the corrected map is more consistent (drifted
    odometry; exact or SLAM-corrected poses are kept), ``"on"`` always corrects, ``"off"`` never.
    Returns the observations (the same clouds, new poses) and what was done (``applied``,
    ``steps``, ``matched``, ...; as ``partition.json``'s ``statistics.odometry_correction``).
    ``Grouping`` groups at the poses it is given: correct them first to get the command's groups."""
    corrected, report = _call(_obsgroup._correct_odometry, list(observations), mode, int(threads))
    return list(corrected), dict(report)


# --- the batch grouping ----------------------------------------------------------------------------

class Partition:
    """The groups of a grouping: each a place, or the observations of one local map."""

    def __init__(self, native: Any) -> None:
        self._native = native
        self.groups: List[List[int]] = native.groups
        """Observation indices of each group, ascending; groups ordered by their first observation."""
        self.group_of: np.ndarray = native.group_of
        """(n,) int64: the group of each observation."""
        self.warnings: List[str] = native.warnings
        """What the grouping had to say (observations with no point, eigen-solver fallbacks)."""

    @property
    def splits(self) -> List[Dict[str, Any]]:
        """The split tree, breadth first: members, kind, outcome, ncut, threshold, eigenvalue, children."""
        return self._native.splits

    @property
    def weights(self) -> Any:
        """W (eq. 18): a ``scipy.sparse.csr_matrix`` when scipy is importable, else the arrays
        ``(rows, cols, values)`` of its entries."""
        rows, cols, values, n = self._native.weight_arrays()
        try:
            from scipy.sparse import csr_matrix
        except ImportError:
            return rows, cols, values
        return csr_matrix((values, (rows, cols)), shape=(n, n))

    def __len__(self) -> int:
        return len(self.groups)

    def __iter__(self) -> Iterator[List[int]]:
        return iter(self.groups)

    def __getitem__(self, index: int) -> List[int]:
        return self.groups[index]

    def __repr__(self) -> str:
        return f"<obsgroup.Partition: {len(self.groups)} groups of {len(self.group_of)} observations>"


def _add(native_add: Callable, native_add_points: Callable, points: Any, pose: Optional[PoseLike]) -> int:
    if isinstance(points, Observation):
        if pose is not None:
            raise TypeError("an Observation carries its pose: give no pose with it")
        return _call(native_add, points)
    if pose is None:
        raise TypeError("points need a pose: add(points, pose)")
    return _call(native_add_points, np.asarray(points), _pose_matrix(pose))


class Grouping:
    """Groups observations at once (the command's ``partition``): W_ij = Psi(n_i, n_j) of the
    sensed-space model (eq. 16-18), then recursive spectral bisection by minimum normalized cut.

    Keyword arguments are the command's method options: ``model=`` (``"visibility"``,
    ``"free-space"``, ``"points"``), ``cell=``, ``range=``, ``clearance=``, ``min_observations=``,
    ``band=(low, high)``, ``door_width=``, ``door_depth=``, ``delta=``, ``voxel=``, ``split=``, ``ncut_threshold=``,
    ``boundary_passes=``, ``mutual_neighbours=``, ``mutual_neighbours_share=``, ``open_floor_width=``,
    ``join_passages=`` (``True``: groups whose places meet through a passage, a corridor cut across, are
    joined, as the command does), ``min_group_size=``, ``max_depth=``, ``paper=True``, ``threads=``.
    Their defaults are the command's; a bad value raises :class:`UsageError`.
    """

    def __init__(self, **options: Any) -> None:
        words = ["partition", "-", "-o", os.devnull] + _words(options, _METHOD_OPTIONS, "Grouping")
        self._native = _call(_obsgroup._Grouping, words)

    def add(self, points: Union[np.ndarray, Observation], pose: Optional[PoseLike] = None) -> int:
        """Adds an observation and returns its index: an :class:`Observation` (its cloud is shared,
        not copied), or points ``(n, 2)`` or ``(n, 3)`` in the sensor frame with the sensor's pose
        (4x4, 3x3 planar, or ``(x, y, theta)``)."""
        return _add(self._native.add, self._native.add_points, points, pose)

    def extend(self, observations: Iterable[Observation]) -> None:
        """Adds every observation of a sequence (as :meth:`add`)."""
        for observation in observations:
            self.add(observation)

    def compute(self, progress: Optional[ProgressCallback] = None) -> Partition:
        """Computes the overlap, W and the partition. ``progress(stage, done, total)`` follows the
        overlap stage. Ctrl-C raises ``KeyboardInterrupt``; the grouping stays usable."""
        result = Partition(_call(self._native.compute, progress))
        _warn(result.warnings)
        return result

    @property
    def parameters(self) -> Dict[str, Any]:
        """The settings the grouping runs with (model, cell, range, delta, split, threshold, ...)."""
        return self._native.parameters()

    @property
    def timings(self) -> Dict[str, float]:
        """Seconds spent in each stage of the last :meth:`compute`."""
        return self._native.timings()

    def __len__(self) -> int:
        return len(self._native)


# --- the online grouping ---------------------------------------------------------------------------

class Change(NamedTuple):
    """One change of the places made by :meth:`OnlineGrouping.update`."""

    kind: str
    """created, grown, shrunk, changed, split, merged or removed."""
    place: int
    """The place's stable id."""
    related: List[int]
    """For split and merged: the places it went to or came from."""
    members: List[int]
    """The place's observation ids after the change (empty when it is gone)."""


class OnlineGrouping:
    """Places kept up to date as observations come (the command's ``stream``): after each
    :meth:`update`, the groups equal what :class:`Grouping` gives for the same observations.

    ``exact_every=N`` makes updates local between exact ones (an exact one once N observations
    came since the last). Other keyword arguments are :class:`Grouping`'s.
    """

    def __init__(self, *, exact_every: int = 1, **options: Any) -> None:
        words = ["stream", "-", "-o", os.devnull] + _words(options, _METHOD_OPTIONS, "OnlineGrouping")
        if int(exact_every) < 1:
            raise UsageError("exact_every= must be at least 1")
        self._native = _call(_obsgroup._OnlineGrouping, words, int(exact_every))

    def insert(self, points: Union[np.ndarray, Observation], pose: Optional[PoseLike] = None) -> int:
        """Inserts an observation (as :meth:`Grouping.add`); returns its id."""
        return _add(self._native.insert, self._native.insert_points, points, pose)

    def update_pose(self, id: int, pose: PoseLike) -> None:
        """Moves an observation (a corrected pose, after a loop closure say)."""
        _call(self._native.update_pose, int(id), _pose_matrix(pose))

    def remove(self, id: int) -> None:
        """Removes an observation; its id is not reused."""
        _call(self._native.remove, int(id))

    def update(self, exact: bool = False) -> List[Change]:
        """Updates the places; returns what changed (splits and merges first)."""
        result = _call(self._native.update, bool(exact))
        return [Change(c["kind"], c["place"], list(c["related"]), list(c["members"])) for c in result["changes"]]

    @property
    def groups(self) -> Dict[int, List[int]]:
        """Place id -> its observation ids, ascending: the groups each update keeps, before
        :attr:`partition` joins those that meet through a passage (``join_passages=``)."""
        return dict(self._native.groups())

    def place_of(self, id: int) -> int:
        """The place of an observation id (-1 before its first update)."""
        return self._native.group_of(int(id))

    @property
    def ids(self) -> List[int]:
        """The ids of the observations present."""
        return self._native.ids()

    def partition(self) -> Partition:
        """The last update's partition, over the present observations in id order, with the groups
        whose places meet through a passage joined as :meth:`Grouping.compute` and the command join
        them (``join_passages=``)."""
        return Partition(self._native.partition())


# --- local maps and the topological map ------------------------------------------------------------

class MetricTopologicalMap(NamedTuple):
    """Local maps (nodes) and the arcs between them."""

    local_maps: List[LocalMap]
    """One per group, in group order."""
    arcs: List[Dict[str, Any]]
    """from, to (local map indices), transform (4x4: ``to``'s frame in ``from``'s), weight, ..."""


def build_local_maps(observations: Sequence[Observation], partition: Partition, *, refine: str = "none",
                     voxel: float = 0.05, threads: int = 0,
                     progress: Optional[ProgressCallback] = None) -> MetricTopologicalMap:
    """Builds each group's local map (its members' points merged in its reference frame, refined by
    ``refine="icp"`` or ``"lum"``) and the topological map whose arcs hold the averaged relative
    transforms (the paper's step 3). ``voxel`` is the local maps' voxel leaf (the command's
    ``map_voxel``, 0 keeps every point)."""
    maps, arcs = _call(_obsgroup._build_local_maps, list(observations), partition._native, refine,
                       float(voxel), int(threads), progress)
    return MetricTopologicalMap(maps, arcs)


# --- places ----------------------------------------------------------------------------------------

class Location(NamedTuple):
    """Where a pose is: the place holding it (None when none is within the tolerance)."""

    place: Optional[int]
    distance_m: float
    """0 inside a place, else the distance to the nearest cell of ``place``."""


class Places:
    """The places of an output folder of ``partition`` or ``stream`` (``places.json`` and the label
    map ``places.png``): outlines, doors, and which place a pose is in."""

    def __init__(self, folder: Union[str, os.PathLike]) -> None:
        folder = os.fspath(folder)
        self._labels = _call(_obsgroup._read_place_labels, folder)
        path = os.path.join(folder, "places.json")
        try:
            with open(path, encoding="utf-8") as f:
                data = json.load(f)
        except (OSError, ValueError) as e:
            raise InputError(f"{path}: {e}") from None
        self.places: List[Dict[str, Any]] = data["places"]
        """id, members, outline (rings of [x, y]), area_m2, centroid, bbox, neighbours."""
        self.doors: List[Dict[str, Any]] = data["doors"]
        """places [a, b], midpoint, width_m, segment."""

    def locate(self, pose: PoseLike, tolerance: float = 1.0) -> Location:
        """The place holding a pose ((x, y), (x, y, theta), or a matrix), or the nearest within
        ``tolerance`` metres."""
        p = np.asarray(pose, dtype=np.float64)
        x, y = (p[0], p[1]) if p.ndim == 1 else (p[0, -1], p[1, -1])
        place, distance = self._labels.locate(float(x), float(y), float(tolerance))
        return Location(place, distance)

    def __len__(self) -> int:
        return len(self.places)


# --- the command -----------------------------------------------------------------------------------

def partition(input: Union[str, os.PathLike], output_dir: Union[str, os.PathLike], *, quiet: bool = True,
              progress: Optional[ProgressCallback] = None, **options: Any) -> Dict[str, Any]:
    """Does what ``obsgroup partition INPUT -o OUTPUT_DIR`` does (any of its options as keyword
    arguments: ``refine="lum"``, ``no_pictures=True``, ``keyframes=(0.1, 10)``, ``force=True``,
    ...) and returns the parsed ``partition.json``. ``quiet=False`` prints the command's progress
    bar, warnings and summary on stderr; ``progress(stage, done, total)`` follows every stage
    (read, overlap, local maps, places, pictures)."""
    options["quiet"] = quiet
    words = ["partition", os.fspath(input), "-o", os.fspath(output_dir)] + _words(
        options, _COMMAND_OPTIONS, "partition")
    _call(_obsgroup._run_command, words, progress)
    with open(os.path.join(os.fspath(output_dir), "partition.json"), encoding="utf-8") as f:
        return json.load(f)
