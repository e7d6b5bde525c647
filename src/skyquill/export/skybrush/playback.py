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


def _segments(
    where: str, points: Sequence[Any], takeoff_s: float, home: Sequence[float]
) -> list[tuple[int, list[Sequence[float]]]]:
    """``iter_segments(absolute=True)``: (duration ms, [start, *controls, end]) per segment."""
    keyframes = list(points)
    if takeoff_s > 0:  # a still segment from -takeoff to the first keyframe
        keyframes.insert(0, [-takeoff_s, list(home), []])
    out: list[tuple[int, list[Sequence[float]]]] = []
    for i in range(1, len(keyframes)):
        (t0, p0, _), (t1, p1, controls) = keyframes[i - 1], keyframes[i]
        dt = round(float(t1) - float(t0), 3)
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
        if len(controls) > 2:
            raise InputError(
                f"{where}.points[{i}][2]: got {len(controls)} control points, expected at most 2 "
                "(Skybrush Live plays linear, quadratic and cubic segments)"
            )
        out.append((math.floor(dt * 1000), [p0, *controls, p1]))
    return out


def _bezier_float32(points: NDArray[np.float32]) -> NDArray[np.float32]:
    """``sb_poly_make_bezier(poly, 1, xs, n)`` on one axis; ``points`` (n,), float32."""
    n = points.size - 1
    out = np.zeros(4, dtype=np.float32)
    if n == 0:
        out[0] = points[0]
        return out
    if n == 1:  # sb_poly_make_linear with duration 1
        out[0], out[1] = points[0], points[1] - points[0]
        return out
    for j in range(n + 1):
        coeff = np.float32(0.0)
        sign = -1 if j % 2 else 1
        for i in range(j + 1):
            term = np.float32(sign) * points[i]
            coeff = coeff + term / np.float32(_FACTORIALS[i]) / np.float32(_FACTORIALS[j - i])
            sign = -sign
        out[j] = coeff * np.float32(_FACTORIALS[n]) / np.float32(_FACTORIALS[n - j])
    return out


def _axis_points(series: NDArray[np.int64]) -> NDArray[np.int64]:
    """``SegmentEncoder._encode_coordinate_series``: the stored points of one axis (start first)."""
    first, rest = series[0], series[1:]
    if np.all(rest == first):
        return series[:1]  # constant
    if rest.size == 2:  # quadratic raised to cubic, on the integer grid
        raised = ((first + 2 * rest[0]) / 3, (2 * rest[0] + rest[1]) / 3, rest[1])
        return np.array([first, *(round(x) for x in raised)], dtype=np.int64)
    return series


def played_trajectory(where: str, trajectory: dict[str, Any]) -> PlayedTrajectory:
    """The firmware's copy of one validated ``trajectory`` object of ``show.json``.

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
    durations = np.array([d for d, _ in segments], dtype=np.int64)
    coeffs = np.zeros((len(segments), 4, 3), dtype=np.float32)
    current = start
    for k, (_, raw) in enumerate(segments):
        stored = quantize(np.array(raw, dtype=float), scale)
        stored[0] = current  # the start point is the previous end, never re-encoded
        ends = []
        for axis in range(3):
            series = _axis_points(stored[:, axis])
            # segment.c: coords[i] = int16 * scale, as float32
            coeffs[k, :, axis] = _bezier_float32((series * scale).astype(np.float32))
            ends.append(series[-1])
        current = np.array(ends, dtype=np.int64)
    if not segments:  # one keyframe: the drone holds it
        durations = np.array([1], dtype=np.int64)
        coeffs = np.zeros((1, 4, 3), dtype=np.float32)
        coeffs[0, 0] = (start * scale).astype(np.float32)
    return PlayedTrajectory(durations, coeffs, scale)


def played_show(show: dict[str, Any]) -> list[PlayedTrajectory]:
    """Every drone of a validated ``show.json``, as its firmware holds it (drone order)."""
    out = []
    for i, drone in enumerate(show["swarm"]["drones"]):
        where = f"show.json: swarm.drones[{i}].settings.trajectory"
        out.append(played_trajectory(where, drone["settings"]["trajectory"]))
    return out
