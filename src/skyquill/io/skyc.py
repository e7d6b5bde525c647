"""Skybrush ``.skyc`` drone-show export (one drone per trajectory).

A ``.skyc`` file is a ZIP archive holding ``show.json``::

    {"version": 1,
     "environment": {"type": "indoor"},
     "meta": {"title": ...},
     "swarm": {"drones": [
         {"type": "generic",
          "settings": {"name": "drone1", "home": [x, y, z],
                       "trajectory": {"version": 1, "takeoffTime": 0.0,
                                      "points": [[t, [x, y, z], [[cx, cy, cz], ...]], ...]}}},
         ...]}}

Trajectory convention (the one Skybrush's own reader uses, ``skybrush``
``TrajectorySpecification.segments``): ``points[i] = [t_i, p(t_i), controls_i]``
is a keyframe at show time ``t_i`` (s) and ``controls_i`` are the *inner*
Bézier control points of the segment that **ends** at that keyframe, running
from ``t_{i-1}`` to ``t_i``. The first keyframe has no controls; an empty list
elsewhere means a straight (linear) segment. Skyquill always writes cubic
segments (two inner control points). Segments are at most
:data:`MAX_SEGMENT_S` long (the Skybrush firmware's limit).

Frames and units: Skybrush's show frame is x, y horizontal and z up, metres
and seconds, which is skyquill's world frame, so coordinates are written
unchanged. Keyframe times are the trajectory's own times (starting at 0).

Exactness: a spline of degree <= 3 is a cubic on every knot span, written
exactly (degree < 3 is elevated). A higher degree is approximated per span by
cubic Hermite pieces (matching position and velocity at both ends, so the
result stays C1); a piece is bisected until its error, measured at
:data:`ERROR_SAMPLES` points, is within ``tolerance``. The largest error is
reported in :class:`SkycExport`.
"""

from __future__ import annotations

import itertools
import json
import math
import zipfile
import zlib
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from skyquill.errors import InputError
from skyquill.io.json_read import parse_json
from skyquill.trajectory import PiecewisePolynomial, SplineTrajectory
from skyquill.validation import FloatArray, as_array, as_float

#: Largest ``show.json`` read from an archive, bytes (checked before inflating it).
MAX_SHOW_BYTES = 256 * 2**20
#: Longest Bézier segment Skybrush accepts, s.
MAX_SEGMENT_S = 65.5
#: Points at which each approximated piece's error is measured (ends included).
ERROR_SAMPLES = 65
#: Bisection depth after which an approximation gives up (never reached by polynomials).
MAX_DEPTH = 30
#: Environments Skybrush knows.
ENVIRONMENTS = ("indoor", "outdoor")


@dataclass(frozen=True)
class SkycExport:
    """What :func:`write_skyc` wrote.

    Attributes
    ----------
    path
        The ``.skyc`` file.
    max_error_m
        Largest distance (m) between the trajectory and the written Bézier
        curves, measured densely; round-off (~1e-15 m) for degree <= 3.
    segments
        Total number of Bézier segments over all drones.
    exact
        True when every trajectory has degree <= 3 (conversion exact up to
        round-off); False when some are approximated within ``tolerance``.
    message
        One line for people.
    """

    path: Path
    max_error_m: float
    segments: int
    exact: bool
    message: str


def _poly_eval(coeffs: FloatArray, u: FloatArray, order: int = 0) -> FloatArray:
    """``order``-th derivative of ``sum_j coeffs[j] u^j`` at ``u`` (N,); coeffs (k+1, d)."""
    k = coeffs.shape[0] - 1
    out = np.zeros((u.shape[0], coeffs.shape[1]))
    for j in range(k, order - 1, -1):  # Horner on the differentiated coefficients
        factor = math.perm(j, order)
        out = out * u[:, None] + factor * coeffs[j]
    return out


def _bezier_eval(ctrl: FloatArray, s: FloatArray) -> FloatArray:
    """Cubic Bézier with control points ``ctrl`` (4, d) at ``s`` (N,) in [0, 1]."""
    s = s[:, None]
    r = 1.0 - s
    return np.asarray(
        r**3 * ctrl[0] + 3 * r**2 * s * ctrl[1] + 3 * r * s**2 * ctrl[2] + s**3 * ctrl[3]
    )


def _hermite_bezier(coeffs: FloatArray, u0: float, u1: float) -> FloatArray:
    """Cubic Bézier (4, d) matching position and velocity of the polynomial at ``u0``, ``u1``."""
    ends = np.array([u0, u1])
    p = _poly_eval(coeffs, ends, 0)
    v = _poly_eval(coeffs, ends, 1)
    h = u1 - u0
    return np.stack([p[0], p[0] + v[0] * h / 3.0, p[1] - v[1] * h / 3.0, p[1]])


def _piece_error(coeffs: FloatArray, u0: float, u1: float, bez: FloatArray) -> float:
    s = np.linspace(0.0, 1.0, ERROR_SAMPLES)
    diff = _poly_eval(coeffs, u0 + s * (u1 - u0)) - _bezier_eval(bez, s)
    return float(np.max(np.linalg.norm(diff, axis=1)))


def _span_pieces(
    coeffs: FloatArray, h: float, tolerance: float, exact: bool
) -> list[tuple[float, float, FloatArray, float]]:
    """Cover local time ``[0, h]`` with cubic pieces ``(u0, u1, bezier (4, d), error_m)``."""
    # A cubic is fixed by position and velocity at its ends, so the Hermite
    # construction is also the exact conversion for degree <= 3.
    n_start = max(1, math.ceil(h / MAX_SEGMENT_S - 1e-12))
    cuts = [h * i / n_start for i in range(n_start)] + [h]  # last cut exactly h
    stack = [(cuts[i], cuts[i + 1], 0) for i in range(n_start - 1, -1, -1)]
    out: list[tuple[float, float, FloatArray, float]] = []
    while stack:
        u0, u1, depth = stack.pop()
        bez = _hermite_bezier(coeffs, u0, u1)
        err = _piece_error(coeffs, u0, u1, bez)
        if exact or err <= tolerance:
            out.append((u0, u1, bez, err))
            continue
        if depth >= MAX_DEPTH:
            raise InputError(
                f"tolerance: got {tolerance:g} m, expected a value the cubic approximation "
                f"can reach (error still {err:.3g} m after {MAX_DEPTH} bisections)"
            )
        mid = 0.5 * (u0 + u1)
        stack.append((mid, u1, depth + 1))
        stack.append((u0, mid, depth + 1))
    return out


def trajectory_points(
    traj: SplineTrajectory, tolerance: float = 1e-3
) -> tuple[list[list[Any]], float]:
    """Skybrush ``points`` list for one trajectory, and its max error (m).

    Parameters
    ----------
    traj
        Spline in the z-up world frame, ``dim == 3``, metres; degree <= 3 is
        converted exactly, higher degrees within ``tolerance``.
    tolerance
        Largest allowed position error for degree > 3, m.

    Returns
    -------
    points : list
        ``[[t, [x, y, z], [[cx, cy, cz], [cx, cy, cz]]], ...]``; the first
        keyframe has an empty control list.
    max_error_m : float
    """
    breaks, coeffs = traj.to_piecewise_polynomial()
    exact = traj.degree <= 3
    p0 = _poly_eval(coeffs[0], np.zeros(1))[0]
    points: list[list[Any]] = [[float(breaks[0]), p0.tolist(), []]]
    max_err = 0.0
    for i in range(coeffs.shape[0]):
        h = float(breaks[i + 1] - breaks[i])
        for _u0, u1, bez, err in _span_pieces(coeffs[i], h, tolerance, exact):
            max_err = max(max_err, err)
            t_end = float(breaks[i + 1]) if u1 == h else float(breaks[i]) + u1
            points.append([t_end, bez[3].tolist(), [bez[1].tolist(), bez[2].tolist()]])
    return points, max_err


def write_skyc(
    trajectories: Sequence[SplineTrajectory],
    path: str | Path,
    *,
    homes: Any = None,
    tolerance: float = 1e-3,
    title: str = "skyquill",
) -> SkycExport:
    """Write a Skybrush ``.skyc`` show with one drone per trajectory.

    Parameters
    ----------
    trajectories
        One :class:`~skyquill.trajectory.SplineTrajectory` per drone, each 3-D
        (x, y, z-up world frame = Skybrush show frame), metres, time from 0 s.
    path
        Output file (conventionally ``*.skyc``); overwritten.
    homes
        Home (take-off) positions, shape (K, 3), m; default each trajectory's
        start position ``p(0)``.
    tolerance
        Largest position error allowed when a trajectory of degree > 3 is
        approximated by cubic Bézier segments, m (default 1 mm).
    title
        Show title written to ``meta.title``.

    Returns
    -------
    SkycExport

    Raises
    ------
    InputError
        When ``trajectories`` is empty or holds something that is not a 3-D
        SplineTrajectory, ``homes`` is not (K, 3), or ``tolerance`` is not > 0.
    """
    tolerance = as_float("tolerance", tolerance, positive=True)
    if isinstance(trajectories, SplineTrajectory) or len(trajectories) == 0:
        got = "one SplineTrajectory" if isinstance(trajectories, SplineTrajectory) else "nothing"
        raise InputError(
            f"trajectories: got {got}, expected a non-empty sequence of SplineTrajectory "
            "(one per drone)"
        )
    for i, traj in enumerate(trajectories):
        if not isinstance(traj, SplineTrajectory):
            raise InputError(
                f"trajectories[{i}]: got {type(traj).__name__}, expected a SplineTrajectory"
            )
        if traj.dim != 3:
            raise InputError(
                f"trajectories[{i}]: got a {traj.dim}-D trajectory, expected 3-D (x, y, z up)"
            )
    k = len(trajectories)
    if homes is None:
        home_arr = np.stack([t.evaluate(np.zeros(1))[0] for t in trajectories])
    else:
        home_arr = as_array("homes", homes, shape=(k, 3), max_abs=1e6)
    if not isinstance(title, str):
        raise InputError(f"title: got {type(title).__name__}, expected a string")

    drones: list[dict[str, Any]] = []
    max_err = 0.0
    n_segments = 0
    for i, traj in enumerate(trajectories):
        points, err = trajectory_points(traj, tolerance)
        max_err = max(max_err, err)
        n_segments += len(points) - 1
        drones.append(
            {
                "type": "generic",
                "settings": {
                    "name": f"drone{i + 1}",
                    "home": home_arr[i].tolist(),
                    "trajectory": {"version": 1, "points": points, "takeoffTime": 0.0},
                },
            }
        )
    show: dict[str, Any] = {
        "version": 1,
        "environment": {"type": "indoor"},
        "meta": {"title": title},
        "swarm": {"drones": drones},
    }
    validate_show(show)  # what we write must pass our own reader
    file = Path(path)
    with zipfile.ZipFile(file, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("show.json", json.dumps(show, allow_nan=False))
    exact = all(t.degree <= 3 for t in trajectories)
    kind = "exact (degree <= 3)" if exact else f"approximated within {tolerance:g} m"
    message = (
        f"wrote {k} drone(s), {n_segments} cubic Bézier segment(s) to {file.name}: "
        f"{kind}, max error {max_err:.3g} m"
    )
    return SkycExport(file, max_err, n_segments, exact, message)


def read_show_json(path: str | Path) -> dict[str, Any]:
    """Open a ``.skyc`` archive and return its validated ``show.json``.

    Raises
    ------
    InputError
        When the file is missing, not a ZIP (or a corrupt or encrypted one), has
        no ``show.json`` or one larger than :data:`MAX_SHOW_BYTES`, the JSON is
        malformed, not UTF-8 or nested too deep (:mod:`skyquill.io.json_read`),
        or :func:`validate_show` rejects it.
    """
    file = Path(path)
    if not file.is_file():
        raise InputError(f"skyc file: got {str(file)!r}, expected an existing .skyc file")
    try:
        with zipfile.ZipFile(file) as archive:
            if "show.json" not in archive.namelist():
                raise InputError(
                    f"{file.name}: got members {archive.namelist()[:10]}, expected a show.json"
                )
            # The size in the directory is checked before inflating: a ZIP bomb is
            # a few kilobytes that claim gigabytes.
            size = archive.getinfo("show.json").file_size
            if size > MAX_SHOW_BYTES:
                raise InputError(
                    f"{file.name}: show.json: got {size:,} bytes, expected at most "
                    f"{MAX_SHOW_BYTES:,}"
                )
            raw = archive.read("show.json")
    except InputError:
        raise
    except zipfile.BadZipFile:
        raise InputError(f"{file.name}: got a file that is not a ZIP, expected a .skyc") from None
    except (OSError, EOFError, RuntimeError, NotImplementedError, zlib.error) as exc:
        # encrypted members, unknown compression, a corrupt stream
        raise InputError(
            f"{file.name}: show.json cannot be extracted ({type(exc).__name__}: {exc}), "
            "expected a .skyc written by a show designer"
        ) from None
    show = parse_json(raw, f"{file.name}: show.json", "a Skybrush show object")
    validate_show(show)
    if not isinstance(show, dict):  # pragma: no cover - validate_show checked it
        raise InputError("show.json: expected an object")
    return show


def _is_number(x: Any) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x)


def _vec3(where: str, value: Any) -> list[float]:
    if not (isinstance(value, list) and len(value) == 3 and all(_is_number(c) for c in value)):
        raise InputError(f"{where}: got {value!r:.60}, expected [x, y, z] of finite numbers")
    return [float(c) for c in value]


def _obj(where: str, value: Any) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise InputError(f"{where}: got {type(value).__name__}, expected an object")
    return value


def _check_trajectory(where: str, traj: Any) -> None:
    traj = _obj(where, traj)
    if traj.get("version") != 1:
        raise InputError(f"{where}.version: got {traj.get('version')!r}, expected 1")
    takeoff = traj.get("takeoffTime", 0.0)
    if not _is_number(takeoff):
        raise InputError(f"{where}.takeoffTime: got {takeoff!r}, expected a finite number (s)")
    points = traj.get("points")
    if not isinstance(points, list) or len(points) == 0:
        raise InputError(f"{where}.points: got {points!r:.60}, expected a non-empty list")
    prev_t: float | None = None
    for i, point in enumerate(points):
        here = f"{where}.points[{i}]"
        if not (isinstance(point, list) and len(point) == 3):
            raise InputError(f"{here}: got {point!r:.60}, expected [t, [x, y, z], [controls]]")
        t, pos, controls = point
        if not _is_number(t):
            raise InputError(f"{here}[0]: got {t!r}, expected a finite time (s)")
        if prev_t is not None and not t > prev_t:
            raise InputError(f"{here}[0]: got {t!r} after {prev_t!r}, expected increasing times")
        if prev_t is not None and t - prev_t > MAX_SEGMENT_S:
            raise InputError(
                f"{here}[0]: got a {t - prev_t:g} s segment, expected at most {MAX_SEGMENT_S} s"
            )
        _vec3(f"{here}[1]", pos)
        if not isinstance(controls, list):
            raise InputError(f"{here}[2]: got {controls!r:.60}, expected a list of [x, y, z]")
        if i == 0 and controls:
            raise InputError(f"{here}[2]: got {len(controls)} control point(s), expected none")
        for j, c in enumerate(controls):
            _vec3(f"{here}[2][{j}]", c)
        prev_t = float(t)


def validate_show(show: Any) -> None:
    """Check a ``show.json`` object against the structure in the module docstring.

    Raises
    ------
    InputError
        Naming the path of the first bad field, e.g.
        ``show.json: swarm.drones[1].settings.trajectory.points[3][0]``.
    """
    show = _obj("show.json", show)
    if show.get("version") != 1:
        raise InputError(f"show.json: version: got {show.get('version')!r}, expected 1")
    env = _obj("show.json: environment", show.get("environment"))
    if env.get("type") not in ENVIRONMENTS:
        raise InputError(
            f"show.json: environment.type: got {env.get('type')!r}, expected one of {ENVIRONMENTS}"
        )
    swarm = _obj("show.json: swarm", show.get("swarm"))
    drones = swarm.get("drones")
    if not isinstance(drones, list) or len(drones) == 0:
        raise InputError(f"show.json: swarm.drones: got {drones!r:.60}, expected a non-empty list")
    for i, drone in enumerate(drones):
        where = f"show.json: swarm.drones[{i}]"
        settings = _obj(f"{where}.settings", _obj(where, drone).get("settings"))
        _vec3(f"{where}.settings.home", settings.get("home"))
        _check_trajectory(f"{where}.settings.trajectory", settings.get("trajectory"))


def show_trajectories(show: dict[str, Any]) -> list[PiecewisePolynomial]:
    """The drones' trajectories of a validated ``show.json`` (Skybrush's own reading).

    Each segment ending at keyframe ``i`` is a Bézier curve from keyframe
    ``i - 1`` to ``i`` through its inner control points (none: a straight
    line; one: quadratic; two: cubic), in show time from the first keyframe.

    Returns
    -------
    list of PiecewisePolynomial
        One per drone, its clock starting at its first keyframe, z-up, m.
    """
    out = []
    for drone in show["swarm"]["drones"]:
        points = drone["settings"]["trajectory"]["points"]
        times = np.array([float(p[0]) for p in points])
        pieces = []
        for prev, point in itertools.pairwise(points):
            ctrl = np.array([prev[1], *point[2], point[1]], dtype=float)
            pieces.append(_bezier_power(ctrl, float(point[0]) - float(prev[0])))
        if not pieces:  # a drone that only hovers: one still piece
            pieces.append(np.array([points[0][1]], dtype=float))
            times = np.array([0.0, 1e-3]) + times[0]
        width = max(p.shape[0] for p in pieces)
        coeffs = np.zeros((len(pieces), width, 3))
        for i, piece in enumerate(pieces):
            coeffs[i, : piece.shape[0]] = piece
        out.append(PiecewisePolynomial(times - times[0], coeffs))
    return out


def _bezier_power(ctrl: FloatArray, duration: float) -> FloatArray:
    """Power-basis coefficients in local time (lowest first) of a Bézier curve, shape (n+1, 3)."""
    n = ctrl.shape[0] - 1
    # B(s) = sum_j s^j sum_i (-1)^(j-i) C(n, j) C(j, i) P_i, and s = tau / duration.
    coeffs = np.zeros_like(ctrl)
    for j in range(n + 1):
        for i in range(j + 1):
            sign = (-1) ** (j - i)
            coeffs[j] += sign * math.comb(n, j) * math.comb(j, i) * ctrl[i]
        coeffs[j] /= duration**j
    return coeffs
