"""What a drone plays from a Skybrush show: the server's upload encoding, the firmware's evaluation.

The keyframes in ``show.json`` are not what flies. This module is a faithful copy of the
arithmetic between the two, so that an export is checked on what the drone executes.

Server side (skybrush-io/skybrush-server, ``src/flockwave/server/show/trajectory.py``,
``TrajectorySpecification.iter_segments(max_length=65, absolute=True)``, and
``src/flockwave/server/show/formats.py``, ``SkybrushBinaryShowFile.add_trajectory`` and
``SegmentEncoder``):

* a segment lasts ``dt = round(t_i - t_{i-1}, 3)`` s, stored as ``floor(1000 * dt)`` ms
  (uint16); a positive ``takeoffTime`` puts a still segment at ``home`` in front;
* a coordinate is stored as ``int(x * (1000 / scale))``, truncated toward zero (int16), with
  ``scale = ceil((ceil(1000 * max|c|) + 1) / 32768)`` over the drone's keyframes and control
  points (``propose_scaling_factor``): millimetres for a show within 32.767 m of the origin;
* per axis, a segment whose coordinates are all equal is stored as a constant; a quadratic is
  raised to a cubic on the integer grid (``int(round(...))``).

Firmware side (skybrush-io/libskybrush, ``src/trajectory/player.c``,
``src/trajectory/segment.c``, ``src/trajectory/poly.c``): the clock starts at the first
segment and adds integer milliseconds; each segment's points (``int16 * scale``, mm, float32)
become a polynomial in the relative time ``u = (t - start) / duration``
(``sb_poly_make_bezier``, float32), evaluated by Horner's rule in float32 (``sb_poly_eval``).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.trajectory import PiecewisePolynomial
from skyquill.validation import FloatArray

#: Segments longer than this are split by the server (``max_length=65``), s.
MAX_SEGMENT_S = 65.0
#: ``facs`` of libskybrush's ``poly.c``.
_FACTORIALS = (1, 1, 2, 6, 24, 120, 720, 5040)


@dataclass(frozen=True)
class PlayedTrajectory:
    """One drone's trajectory as its firmware holds it.

    Attributes
    ----------
    durations_ms
        Segment durations, shape (P,), integer ms (the uint16s of the upload).
    coeffs_mm
        Per segment and axis, the float32 polynomial in ``u`` in [0, 1], lowest order first,
        shape (P, 4, 3), mm.
    scale
        Skybrush's scaling factor: one stored unit is ``scale`` mm.
    """

    durations_ms: NDArray[np.int64]
    coeffs_mm: NDArray[np.float32]
    scale: int

    @property
    def start_ms(self) -> NDArray[np.int64]:
        """Start of every segment on the firmware's clock, shape (P + 1,), ms (the end last)."""
        return np.concatenate([[0], np.cumsum(self.durations_ms)]).astype(np.int64)

    def trajectory(self) -> PiecewisePolynomial:
        """The same polynomials in seconds and metres (float64 copies of the float32 values)."""
        h = self.durations_ms.astype(float)[:, None, None] / 1000.0
        powers = np.arange(self.coeffs_mm.shape[1])[None, :, None]
        coeffs = self.coeffs_mm.astype(float) / 1000.0 / h**powers
        return PiecewisePolynomial(self.start_ms / 1000.0, coeffs)

    def positions(self, t: FloatArray) -> FloatArray:
        """Positions at show times ``t`` (N,), s, with the firmware's float32 arithmetic, m."""
        start = self.start_ms
        t32 = np.asarray(t, dtype=np.float32)
        # player.c: start_time_sec = start_time_msec / 1000.0f; the segment holding t
        start_s = (start.astype(np.float32) / np.float32(1000.0)).astype(np.float32)
        i = np.clip(np.searchsorted(start_s, t32, side="right") - 1, 0, start.size - 2)
        duration = (self.durations_ms.astype(np.float32) / np.float32(1000.0))[i]
        u = np.clip((t32 - start_s[i]) / duration, np.float32(0), np.float32(1))
        out = np.zeros((t32.size, 3), dtype=np.float32)
        for j in range(self.coeffs_mm.shape[1] - 1, -1, -1):  # sb_poly_eval: Horner
            out = out * u[:, None] + self.coeffs_mm[i, j]
        return np.asarray(out, dtype=float) / 1000.0


def scaling_factor(values: FloatArray) -> int:
    """Skybrush's ``propose_scaling_factor`` for a drone's coordinates ``values`` (any shape), m."""
    if values.size == 0:
        return 1
    extremum = math.ceil(float(np.max(np.abs(values))) * 1000)
    return math.ceil((extremum + 1) / 32768)


def quantize(values: FloatArray, scale: int) -> NDArray[np.int64]:
    """The server's ``int(x * (1000 / scale))``: truncated toward zero, in ``scale`` mm units."""
    return np.trunc(np.asarray(values, dtype=float) * (1000 / scale)).astype(np.int64)


@dataclass(frozen=True)
class _Segments:
    """``iter_segments(absolute=True)`` of one drone, every segment at once.

    Attributes
    ----------
    durations_ms
        Each segment's ``floor(1000 * round(dt, 3))``, (S,).
    points
        Each segment's ``[start, *controls, end]``, padded with the end to four points,
        (S, 4, 3), m.
    controls
        Each segment's number of control points, 0 to 2, (S,).
    """

    durations_ms: NDArray[np.int64]
    points: FloatArray
    controls: NDArray[np.intp]


def _segments(
    where: str, points: Sequence[Any], takeoff_s: float, home: Sequence[float]
) -> _Segments:
    """``iter_segments(absolute=True)``: the duration (ms) and points of every segment."""
    keyframes = list(points)
    if takeoff_s > 0:  # a still segment from -takeoff to the first keyframe
        keyframes.insert(0, [-takeoff_s, list(home), []])
    times = [float(k[0]) for k in keyframes]
    # Python's round and floor on Python floats, as the server computes them.
    dts = [round(t1 - t0, 3) for t0, t1 in itertools.pairwise(times)]
    counts = [len(k[2]) for k in keyframes[1:]]
    for i, (dt, count) in enumerate(zip(dts, counts, strict=True), start=1):
        t0, t1 = keyframes[i - 1][0], keyframes[i][0]
        if dt <= 0:
            raise InputError(
                f"{where}.points[{i}][0]: got {t1!r} after {t0!r}, expected a time at least "
                "1 ms later (Skybrush rounds segment durations to ms)"
            )
        if dt > MAX_SEGMENT_S:
            raise InputError(
                f"{where}.points[{i}][0]: got a {dt:g} s segment, expected at most "
                f"{MAX_SEGMENT_S:g} s (Skybrush's server splits longer ones off the ms grid)"
            )
        if count > 2:
            raise InputError(
                f"{where}.points[{i}][2]: got {count} control points, expected at most 2 "
                "(Skybrush Live plays linear, quadratic and cubic segments)"
            )
    ends = np.array([k[1] for k in keyframes], dtype=float).reshape(-1, 3)
    stacked = np.repeat(ends[1:, None, :], 4, axis=1)  # (S, 4, 3): padded with the end
    stacked[:, 0] = ends[:-1]
    for i, k in enumerate(keyframes[1:]):
        for j, control in enumerate(k[2]):
            stacked[i, 1 + j] = control
    durations = np.array([math.floor(dt * 1000) for dt in dts], dtype=np.int64)
    return _Segments(durations, stacked, np.array(counts, dtype=np.intp))


def _bezier_float32(points: NDArray[np.float32]) -> NDArray[np.float32]:
    """``sb_poly_make_bezier(poly, 1, xs, n)``, for many: ``points`` (M, n + 1), float32.

    Returns the power-basis coefficients (M, n + 1), float32, with poly.c's operations
    in poly.c's order on every row (so each row is what the firmware computes).
    """
    n = points.shape[1] - 1
    out = np.zeros(points.shape, dtype=np.float32)
    if n == 0:
        out[:, 0] = points[:, 0]
        return out
    if n == 1:  # sb_poly_make_linear with duration 1
        out[:, 0], out[:, 1] = points[:, 0], points[:, 1] - points[:, 0]
        return out
    for j in range(n + 1):
        coeff = np.zeros(points.shape[0], dtype=np.float32)
        sign = -1 if j % 2 else 1
        for i in range(j + 1):
            term = np.float32(sign) * points[:, i]
            coeff = coeff + term / np.float32(_FACTORIALS[i]) / np.float32(_FACTORIALS[j - i])
            sign = -sign
        out[:, j] = coeff * np.float32(_FACTORIALS[n]) / np.float32(_FACTORIALS[n - j])
    return out


def _encoded(stored: NDArray[np.int64], controls: NDArray[np.intp]) -> NDArray[np.int64]:
    """``SegmentEncoder._encode_coordinate_series`` of every segment and axis.

    ``stored`` (S, 4, 3): each segment's start, controls and end on the integer grid,
    padded with the end. Returns the points stored per segment and axis as a cubic
    (S, 4, 3) and, through the number of distinct points, their degree: a constant
    axis is its start repeated, a straight one its start and end, a quadratic raised
    to a cubic on the integer grid (``int(round(...))``).
    """
    first = stored[:, :1]
    constant = np.all(stored == first, axis=1, keepdims=True)  # (S, 1, 3)
    out = stored.copy()
    quadratic = (controls == 1)[:, None]
    if quadratic.any():
        rest0, rest1 = stored[:, 1], stored[:, 2]
        raised = np.stack(
            [
                stored[:, 0],
                np.rint((stored[:, 0] + 2 * rest0) / 3).astype(np.int64),
                np.rint((2 * rest0 + rest1) / 3).astype(np.int64),
                rest1,
            ],
            axis=1,
        )
        out = np.where(quadratic[:, :, None], raised, out)
    return np.where(constant, first, out)


def _coefficients(
    stored: NDArray[np.int64], controls: NDArray[np.intp], scale: int
) -> NDArray[np.float32]:
    """segment.c: every segment's float32 polynomial per axis (S, 4, 3), mm."""
    series = _encoded(stored, controls)
    constant = np.all(series == series[:, :1], axis=1)  # (S, 3)
    straight = (controls == 0)[:, None] & ~constant
    coeffs = np.zeros(series.shape, dtype=np.float32)
    xs = (series * scale).astype(np.float32)  # coords[i] = int16 * scale, as float32
    for mask, width in ((constant, 1), (straight, 2), (~constant & ~straight, 4)):
        seg, axis = np.nonzero(mask)
        if not seg.size:
            continue
        rows = xs[seg, :, axis]  # (M, 4)
        picked = rows[:, :1] if width == 1 else rows[:, [0, 3]] if width == 2 else rows
        coeffs[seg, :width, axis] = _bezier_float32(np.ascontiguousarray(picked))
    return coeffs


def played_trajectory(where: str, trajectory: dict[str, Any]) -> PlayedTrajectory:
    """The firmware's copy of one validated ``trajectory`` object of ``show.json``.

    Every segment is encoded and turned into its polynomial at once (numpy), with the
    server's and the firmware's arithmetic on each.

    Parameters
    ----------
    where
        The object's place in ``show.json``, for error messages.
    trajectory
        ``{"version": 1, "points": [...], "takeoffTime": ...}``, validated.
    Raises
    ------
    InputError
        When a segment is shorter than 1 ms after rounding, longer than :data:`MAX_SEGMENT_S`,
        has more than two control points, or a coordinate does not fit Skybrush's int16.
    """
    points = trajectory["points"]
    takeoff = float(trajectory.get("takeoffTime", 0.0))
    # TrajectorySpecification.home_position: the trajectory's own "home", else its first point
    home = trajectory.get("home") or points[0][1]
    segments = _segments(where, points, takeoff, home)
    # the bounding box of the keyframes and control points only (get_padded_bounding_box)
    everything = [c for p in points for c in [p[1], *p[2]]]
    scale = scaling_factor(np.array(everything, dtype=float))
    if scale >= 128:
        raise InputError(
            f"{where}: got coordinates up to {float(np.max(np.abs(everything))):.6g} m, expected "
            "a show Skybrush can store (scaling factor below 128)"
        )
    start = quantize(np.array(points[0][1] if takeoff <= 0 else home, dtype=float), scale)
    if not segments.durations_ms.size:  # one keyframe: the drone holds it
        coeffs = np.zeros((1, 4, 3), dtype=np.float32)
        coeffs[0, 0] = (start * scale).astype(np.float32)
        return PlayedTrajectory(np.array([1], dtype=np.int64), coeffs, scale)
    stored = quantize(segments.points, scale)
    # The start point is the previous end, never re-encoded: every encoding keeps the
    # end, so it is the previous keyframe's quantised end (the first: the start).
    stored[0, 0] = start
    stored[1:, 0] = stored[:-1, 3]
    coeffs = _coefficients(stored, segments.controls, scale)
    return PlayedTrajectory(segments.durations_ms, coeffs, scale)


def played_show(show: dict[str, Any]) -> list[PlayedTrajectory]:
    """Every drone of a validated ``show.json``, as its firmware holds it (drone order)."""
    out = []
    for i, drone in enumerate(show["swarm"]["drones"]):
        where = f"show.json: swarm.drones[{i}].settings.trajectory"
        out.append(played_trajectory(where, drone["settings"]["trajectory"]))
    return out
