"""Safe corridors made of yaw-rotated boxes (paper 003 §5.4, Fig. 9).

A corridor is a chain of oriented boxes ``B_0, ..., B_{n-1}`` in the z-up world
frame (metres). Each box is rotated about the world z axis only, so its top
and bottom faces stay horizontal. Consecutive boxes overlap; a nominal
piecewise-linear path (``waypoints``) runs from ``start`` (inside ``B_0``)
through one point in each consecutive overlap to ``goal`` (inside
``B_{n-1}``).

On disk a corridor is a JSON object::

    {
      "description": "...",                      # optional, string
      "frame": "world, z-up, metres",            # optional, string
      "start": [x, y, z],
      "goal": [x, y, z],
      "boxes": [{"center": [x, y, z], "size": [length, width, height], "yaw_deg": 30.0}, ...],
      "waypoints": [[x, y, z], ...]
    }

``size`` is measured along the box's own axes: ``length`` along the yawed x
axis ``(cos yaw, sin yaw, 0)``, ``width`` along ``(-sin yaw, cos yaw, 0)`` and
``height`` along world z. :func:`load_box_corridor` checks the file and raises
:class:`~skyquill.errors.InputError` naming the offending field.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.io.json_read import read_json_file

__all__ = ["CONTAINMENT_TOL", "BoxCorridor", "OrientedBox", "load_box_corridor"]

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

CONTAINMENT_TOL = 1e-9
"""Slack (m) allowed when checking that ``start``/``goal`` lie in their boxes.

Absorbs rounding of the numbers written to a JSON file.
"""

_TOP_KEYS = ("start", "goal", "boxes", "waypoints")
_OPTIONAL_TOP_KEYS = ("description", "frame")
_BOX_KEYS = ("center", "size", "yaw_deg")


# ----------------------------------------------------------------------------- helpers
def _short(value: object, limit: int = 80) -> str:
    """``repr`` of ``value`` cut to ``limit`` characters for error messages."""
    text = repr(value.tolist() if isinstance(value, np.ndarray) else value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _error(field: str, got: str, expected: str, source: str = "") -> InputError:
    """Build an :class:`InputError` whose message names field, received value and expectation."""
    where = f" in {source}" if source else ""
    return InputError(f"{field}{where}: got {got}, expected {expected}")


def _is_number(x: object) -> bool:
    """True for real numbers (int/float, numpy or not), False for bool and everything else."""
    return isinstance(x, int | float | np.integer | np.floating) and not isinstance(
        x, bool | np.bool_
    )


def _finite_float(value: object, field: str, source: str = "") -> float:
    """Return ``value`` as a finite float or raise :class:`InputError` naming ``field``."""
    if not _is_number(value):
        raise _error(field, _short(value), "a finite number", source)
    out = float(value)  # type: ignore[arg-type]
    if not math.isfinite(out):
        raise _error(field, _short(value), "a finite number", source)
    return out


def _points(value: object, field: str, source: str = "", *, single: bool) -> FloatArray:
    """Convert ``value`` to a read-only float64 array of 3-vectors.

    Parameters
    ----------
    value
        A length-3 sequence (``single=True``) or a sequence of them, or an array.
    field
        Name used in error messages, e.g. ``"boxes[2].center"``.
    source
        Where the value came from (a file path), for error messages.
    single
        Expect one point, shape (3,), instead of a list of points, shape (K, 3).

    Returns
    -------
    numpy.ndarray, shape (3,) or (K, 3), float64, read-only
    """
    expected = "a list of 3 finite numbers [x, y, z]" if single else "a list of [x, y, z] points"
    if isinstance(value, np.ndarray):
        if value.dtype.kind not in "fiu":
            raise _error(field, f"an array of dtype {value.dtype}", expected, source)
        arr = np.array(value, dtype=np.float64)
    elif isinstance(value, Sequence) and not isinstance(value, str | bytes):
        rows: list[object] = [value] if single else list(value)
        for k, item in enumerate(rows):
            name = field if single else f"{field}[{k}]"
            row = item.tolist() if isinstance(item, np.ndarray) else item
            if not (isinstance(row, Sequence) and not isinstance(row, str | bytes)):
                raise _error(name, _short(row), "a list of 3 finite numbers [x, y, z]", source)
            if len(row) != 3:
                raise _error(
                    name, f"{len(row)} values {_short(row)}", "exactly 3 numbers [x, y, z]", source
                )
            for j, x in enumerate(row):
                _finite_float(x, f"{name}[{j}]", source)
        arr = np.array(value, dtype=np.float64)
    else:
        raise _error(field, _short(value), expected, source)
    want = (3,) if single else "(K, 3)"
    if (single and arr.shape != (3,)) or (not single and (arr.ndim != 2 or arr.shape[1] != 3)):
        raise _error(field, f"shape {arr.shape}", f"shape {want}", source)
    if not np.all(np.isfinite(arr)):
        raise _error(field, _short(arr), "finite numbers (no NaN or inf)", source)
    arr.setflags(write=False)
    return arr


# ------------------------------------------------------------------------------ types
@dataclass(frozen=True, eq=False)
class OrientedBox:
    """A box rotated about the world z axis (z-up, metres).

    Equality is identity (``eq=False``): the fields are arrays.

    Parameters
    ----------
    center
        Box centre, shape (3,), metres.
    size
        Edge lengths ``[length, width, height]`` along the box's own axes, shape (3,),
        metres, all > 0. ``length`` runs along ``(cos yaw, sin yaw, 0)``, ``width``
        along ``(-sin yaw, cos yaw, 0)``, ``height`` along world z.
    yaw_rad
        Rotation about world z, radians (counter-clockwise seen from above).

    Raises
    ------
    InputError
        If a field has the wrong shape, is not finite, or a size is not positive.
    """

    center: FloatArray
    size: FloatArray
    yaw_rad: float

    def __post_init__(self) -> None:
        center = _points(self.center, "OrientedBox.center", single=True)
        size = _points(self.size, "OrientedBox.size", single=True)
        if np.any(size <= 0.0):
            raise _error("OrientedBox.size", _short(size), "all three sizes > 0 m")
        object.__setattr__(self, "center", center)
        object.__setattr__(self, "size", size)
        object.__setattr__(self, "yaw_rad", _finite_float(self.yaw_rad, "OrientedBox.yaw_rad"))

    @property
    def axes(self) -> FloatArray:
        """Unit box axes as rows: length, width and height directions, shape (3, 3)."""
        c, s = math.cos(self.yaw_rad), math.sin(self.yaw_rad)
        return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])

    def halfspaces(self) -> tuple[FloatArray, FloatArray]:
        """Half-space form of the box.

        Returns
        -------
        A : numpy.ndarray, shape (6, 3)
            Outward unit face normals, in the order ``+length, +width, +height,
            -length, -width, -height``.
        b : numpy.ndarray, shape (6,), metres
            Offsets, so that the box is ``{p : A @ p <= b}``.
        """
        axes = self.axes
        A = np.concatenate([axes, -axes])
        b = A @ self.center + np.concatenate([self.size, self.size]) / 2.0
        return A, b

    def contains(self, p: FloatArray, tol: float = 0.0) -> BoolArray:
        """Which points lie in the box, faces included.

        Parameters
        ----------
        p
            Points, shape (N, 3) (a single point of shape (3,) is treated as N = 1), metres.
        tol
            Slack in metres: a point counts as inside if ``A @ p <= b + tol``.
            Positive grows the box, negative shrinks it.

        Returns
        -------
        numpy.ndarray of bool, shape (N,)

        Raises
        ------
        InputError
            If ``p`` is not (N, 3) / (3,) finite numbers or ``tol`` is not finite.
        """
        pts = np.asarray(p)
        pts = _points(pts.reshape(1, -1) if pts.ndim == 1 else pts, "p", single=False)
        slack = _finite_float(tol, "tol")
        A, b = self.halfspaces()
        inside: BoolArray = np.all(pts @ A.T <= b + slack, axis=1)
        return inside


@dataclass(frozen=True, eq=False)
class BoxCorridor:
    """A chain of overlapping oriented boxes with a nominal path through it.

    Parameters
    ----------
    boxes
        The boxes ``B_0 .. B_{n-1}``, at least one.
    start
        Start position, shape (3,), metres; inside ``boxes[0]``.
    goal
        Goal position, shape (3,), metres; inside ``boxes[-1]``.
    waypoints
        Nominal path, shape (K, 3), metres, K >= 2. In the files shipped with
        skyquill it is ``start``, one point in each consecutive overlap, then
        ``goal`` (K = n + 1), and segment ``i`` lies in ``boxes[i]``; this is
        not enforced.

    Raises
    ------
    InputError
        If a field is malformed or ``start``/``goal`` are outside their boxes
        (tolerance :data:`CONTAINMENT_TOL`).
    """

    boxes: tuple[OrientedBox, ...]
    start: FloatArray
    goal: FloatArray
    waypoints: FloatArray

    def __post_init__(self) -> None:
        boxes = tuple(self.boxes) if isinstance(self.boxes, Sequence) else ()
        if len(boxes) < 1 or not all(isinstance(b, OrientedBox) for b in boxes):
            raise _error("boxes", _short(self.boxes), "at least one OrientedBox")
        start = _points(self.start, "start", single=True)
        goal = _points(self.goal, "goal", single=True)
        waypoints = _points(self.waypoints, "waypoints", single=False)
        if waypoints.shape[0] < 2:
            raise _error("waypoints", f"{waypoints.shape[0]} point(s)", "at least 2 points")
        _check_inside(boxes[0], start, "start", "a point inside boxes[0]")
        _check_chained(boxes)
        _check_inside(
            boxes[-1], goal, "goal", f"a point inside boxes[{len(boxes) - 1}] (the last box)"
        )
        object.__setattr__(self, "boxes", boxes)
        object.__setattr__(self, "start", start)
        object.__setattr__(self, "goal", goal)
        object.__setattr__(self, "waypoints", waypoints)


def _check_chained(boxes: tuple[OrientedBox, ...]) -> None:
    """Raise :class:`InputError` unless every box overlaps the next (a path can pass).

    Two boxes overlap when one point satisfies both half-space forms: a linear
    feasibility problem (HiGHS through scipy), exact for rotated boxes.
    """
    from scipy.optimize import linprog

    for k in range(len(boxes) - 1):
        A0, b0 = boxes[k].halfspaces()
        A1, b1 = boxes[k + 1].halfspaces()
        found = linprog(
            np.zeros(3), A_ub=np.vstack([A0, A1]), b_ub=np.concatenate([b0, b1]),
            bounds=[(None, None)] * 3, method="highs",
        )  # fmt: skip
        if found.status == 2:  # infeasible: the boxes are apart
            raise _error(
                f"boxes[{k + 1}]",
                f"a box apart from boxes[{k}]",
                "each box to overlap the next (a chain from start to goal)",
            )


def _check_inside(box: OrientedBox, p: FloatArray, field: str, expected: str) -> None:
    """Raise :class:`InputError` on ``field`` if point ``p`` (3,) is outside ``box``."""
    if not box.contains(p, tol=CONTAINMENT_TOL)[0]:
        A, b = box.halfspaces()
        excess = float(np.max(A @ p - b))
        raise _error(field, f"{_short(p)}, {excess:.4g} m outside that box", expected)


# ----------------------------------------------------------------------------- loader
def load_box_corridor(path: str | Path) -> BoxCorridor:
    """Read a box corridor from a JSON file (format in the module docstring).

    Parameters
    ----------
    path
        JSON file to read.

    Returns
    -------
    BoxCorridor
        With ``yaw_deg`` converted to radians; all arrays float64, metres.

    Raises
    ------
    InputError
        If the file is missing or unreadable, is not valid JSON, or a field is
        missing, unknown, of the wrong length, not finite, a box size is not
        positive, there are no boxes, or ``start``/``goal`` lie outside the
        first/last box. The message names the field (e.g. ``boxes[2].size``).
    """
    src = str(path)
    file = Path(path)
    # A regular file (a named pipe would block), UTF-8, bounded size and depth, strict JSON.
    data = read_json_file(file, "a corridor JSON file")
    if not isinstance(data, Mapping):
        raise _error("(top level)", type(data).__name__, "a JSON object {...}", src)
    _check_keys(data, "(top level)", _TOP_KEYS, _OPTIONAL_TOP_KEYS, src)
    for key in _OPTIONAL_TOP_KEYS:
        if key in data and not isinstance(data[key], str):
            raise _error(key, _short(data[key]), "a string", src)

    raw_boxes = data["boxes"]
    if not isinstance(raw_boxes, list) or len(raw_boxes) < 1:
        raise _error("boxes", _short(raw_boxes), "a list of at least 1 box object", src)
    boxes = tuple(_parse_box(raw, f"boxes[{i}]", src) for i, raw in enumerate(raw_boxes))

    start = _points(data["start"], "start", src, single=True)
    goal = _points(data["goal"], "goal", src, single=True)
    waypoints = _points(data["waypoints"], "waypoints", src, single=False)
    try:
        return BoxCorridor(boxes=boxes, start=start, goal=goal, waypoints=waypoints)
    except InputError as exc:  # corridor-level checks: add the file to the message
        field, _, rest = str(exc).partition(": ")
        raise InputError(f"{field} in {src}: {rest}") from None


def _check_keys(
    obj: Mapping[str, object],
    name: str,
    required: Sequence[str],
    optional: Sequence[str],
    src: str,
) -> None:
    """Raise :class:`InputError` for a missing required key or an unknown key."""
    prefix = "" if name.startswith("(") else f"{name}."
    for key in required:
        if key not in obj:
            raise _error(
                f"{prefix}{key}",
                f"an object without it (keys: {sorted(obj)})",
                f"the required key {key!r}",
                src,
            )
    unknown = sorted(set(obj) - set(required) - set(optional))
    if unknown:
        raise _error(
            f"{prefix}{unknown[0]}",
            f"unknown key(s) {unknown}",
            f"only keys {[*required, *optional]}",
            src,
        )


def _parse_box(raw: object, name: str, src: str) -> OrientedBox:
    """Parse one ``{"center", "size", "yaw_deg"}`` object into an :class:`OrientedBox`."""
    if not isinstance(raw, Mapping):
        raise _error(
            name, _short(raw), 'an object {"center": ..., "size": ..., "yaw_deg": ...}', src
        )
    _check_keys(raw, name, _BOX_KEYS, (), src)
    center = _points(raw["center"], f"{name}.center", src, single=True)
    size = _points(raw["size"], f"{name}.size", src, single=True)
    if np.any(size <= 0.0):
        raise _error(f"{name}.size", _short(size), "[length, width, height] all > 0 m", src)
    yaw_deg = _finite_float(raw["yaw_deg"], f"{name}.yaw_deg", src)
    return OrientedBox(center=center, size=size, yaw_rad=math.radians(yaw_deg))
