"""A trajectory as Skybrush keyframes: cubic Bézier segments on Skybrush's ms and mm grid.

Skybrush's server stores segment durations in whole milliseconds and coordinates in units
of ``scale`` mm (:mod:`skyquill.export.skybrush.playback`). Keyframes off that grid drift: the
old 0.0999 s spacing played 28 mm and 30 ms off on 永. Here every segment boundary is an
integer millisecond and every Bézier point is written as a number that the server's
truncation maps to the intended integer, so what the drone plays is exactly what is built
here, and the export measures its distance from the plan on that.

Construction:

1. segments of :data:`SEGMENT_MS`, each the cubic Hermite of the trajectory (position and
   velocity at both ends, so joins are C1 before rounding), bisected on the ms grid until
   within ``tolerance`` of the trajectory at :data:`ERROR_SAMPLES` points;
2. every Bézier point rounded to the nearest grid unit. A Bézier point of the curve is a
   convex combination of its control points, each off by at most half a unit per axis, so
   the rounding moves the curve by at most ``sqrt(3) / 2`` units (0.87 mm) anywhere.

Why 250 ms: the rounding perturbs the k-th derivative by about ``unit / h^k`` (the jerk of a
cubic is ``6 (P3 - 3 P2 + 3 P1 - P0) / h^3``: up to 12 m/s^3 at 100 ms, 0.8 m/s^3 at
250 ms), while the cubic's own error grows as ``h^4 snap / 384`` (0.4 mm at 250 ms for 永,
whose snap peaks at 47 m/s^4). Measured on 永: 100 ms segments exceed its jerk limit by 147 %
after rounding, 250 ms segments keep acceleration and jerk inside and the speed within
0.013 % of its limit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.export.skybrush.playback import quantize, scaling_factor
from skyquill.trajectory import PiecewisePolynomial, RestToRestSequence, Trajectory
from skyquill.validation import FloatArray, as_float

#: Length of a segment before bisection, ms.
SEGMENT_MS = 250
#: Longest segment over one of the trajectory's own cubic pieces (exact there), ms.
CUBIC_SEGMENT_MS = 1000
#: Shortest cubic piece given its own segment, ms: a shorter one (a time-optimal move's
#: brief jerk phase) would amplify the mm rounding (``unit / h^2``); it joins the next span.
MIN_CUBIC_MS = 100
#: Shortest segment bisection makes, ms.
MIN_SEGMENT_MS = 10
#: Default largest distance of the cubics from the trajectory before rounding, m (the
#: rounding adds at most 0.87 mm: 1.37 mm in all, inside the 2 mm the export promises).
FIT_TOLERANCE_M = 0.5e-3
#: Points per segment at which the cubic's error is measured (ends included).
ERROR_SAMPLES = 17
#: Most segments per drone (a 40-hour show at 250 ms): bounds memory and time.
MAX_SEGMENTS = 600_000
#: Times the scaling factor is re-proposed after rounding (it settles after one).
SCALE_ROUNDS = 4


@dataclass(frozen=True)
class Keyframes:
    """One drone's cubic Bézier segments on Skybrush's grid.

    Attributes
    ----------
    times_ms
        Segment boundaries, shape (P + 1,), integer ms from 0.
    units
        Bézier points of every segment, shape (P, 4, 3), in units of ``scale`` mm; a
        segment's first point is the previous segment's last.
    scale
        Skybrush's scaling factor for these points (1 within 32.767 m of the origin).
    fit_error_m
        Largest distance of the cubics from the trajectory before rounding, m.
    """

    times_ms: NDArray[np.int64]
    units: NDArray[np.int64]
    scale: int
    fit_error_m: float

    def points(self) -> list[list[Any]]:
        """The ``points`` list of ``show.json``: ``[t, [x, y, z], [[c1], [c2]]]``, s and m."""
        values = encode(self.units, self.scale)
        times = self.times_ms / 1000.0
        out: list[list[Any]] = [[float(times[0]), values[0, 0].tolist(), []]]
        for i in range(values.shape[0]):
            out.append([float(times[i + 1]), values[i, 3].tolist(), values[i, 1:3].tolist()])
        return out


def encode(units: NDArray[np.int64], scale: int) -> FloatArray:
    """Numbers (m) that Skybrush's ``int(x * (1000 / scale))`` maps back to ``units``.

    ``units * scale / 1000`` is usually one; when the product falls a rounding error short
    of the integer, truncation would lose a unit, so the number is moved one float away
    from zero (a change of about 1e-16 m).
    """
    values = np.asarray(units * scale / 1000.0, dtype=float)
    for _ in range(4):
        wrong = quantize(values, scale) != units
        if not wrong.any():
            return values
        values[wrong] = np.nextafter(values[wrong], np.sign(units[wrong]) * np.inf)
    raise AssertionError("encode: a unit that no float reaches")  # pragma: no cover


def _hermite(traj: Trajectory, times_ms: NDArray[np.int64]) -> FloatArray:
    """Cubic Hermite Bézier points of every segment, shape (P, 4, 3), m."""
    t = np.minimum(times_ms / 1000.0, traj.duration)  # past the end: held at the end
    p = traj.evaluate(t)
    v = traj.evaluate(t, 1)
    h = np.diff(times_ms)[:, None] / 1000.0
    return np.stack([p[:-1], p[:-1] + v[:-1] * h / 3, p[1:] - v[1:] * h / 3, p[1:]], axis=1)


def _errors(traj: Trajectory, times_ms: NDArray[np.int64], ctrl: FloatArray) -> FloatArray:
    """Largest distance of each segment's cubic from the trajectory, shape (P,), m."""
    s = np.linspace(0.0, 1.0, ERROR_SAMPLES)[1:-1]
    start = times_ms[:-1, None] / 1000.0
    h = np.diff(times_ms)[:, None] / 1000.0
    t = np.minimum(start + s[None, :] * h, traj.duration)
    exact = traj.evaluate(t.ravel()).reshape(*t.shape, 3)
    w = s[None, :, None]
    r = 1.0 - w
    bez = (
        r**3 * ctrl[:, None, 0]
        + 3 * r**2 * w * ctrl[:, None, 1]
        + 3 * r * w**2 * ctrl[:, None, 2]
        + w**3 * ctrl[:, None, 3]
    )
    return np.asarray(np.linalg.norm(bez - exact, axis=2).max(axis=1))


def _boundaries(traj: Trajectory) -> NDArray[np.int64]:
    """First segment boundaries over the duration, ms (the end rounded up).

    Segments of :data:`SEGMENT_MS`, except over the trajectory's own cubic pieces
    (:func:`_cubic_spans`): a cubic Bézier is such a piece exactly, so it is one segment
    of up to :data:`CUBIC_SEGMENT_MS` with no fit error and no bisection, and the longer
    segment shrinks the ms/mm rounding's effect on acceleration and jerk (``unit / h^2``,
    ``unit / h^3``).
    """
    total = max(1, math.ceil(traj.duration * 1000 - 1e-6))
    out: list[NDArray[np.int64]] = []
    for start, end, cubic in _cubic_spans(traj, total):
        n = math.ceil((end - start) / (CUBIC_SEGMENT_MS if cubic else SEGMENT_MS))
        out.append(np.round(np.linspace(start, end, n + 1)).astype(np.int64)[:-1])
    times = np.append(np.concatenate(out), total)
    if times.size - 1 > MAX_SEGMENTS:
        raise InputError(
            f"trajectory: got {traj.duration:.6g} s, expected at most "
            f"{MAX_SEGMENTS * SEGMENT_MS / 3.6e6:g} h for one Skybrush drone"
        )
    return times


def _cubic_spans(traj: Trajectory, total_ms: int) -> list[tuple[int, int, bool]]:
    """``(start, end, cubic)`` spans covering ``[0, total_ms]``, ms.

    ``cubic``: the trajectory is one polynomial of degree <= 3 there (a time-optimal move's
    phase, a hold). Piece ends are rounded to the ms (a cubic Hermite across a break at
    most 0.5 ms off is within nanometres); pieces shorter than :data:`MIN_CUBIC_MS` are
    merged into the span after them, which is then not exact (and bisected if needed).
    """
    breaks, cubic = _cubic_breaks(traj)
    ms = np.round(np.asarray(breaks) * 1000).astype(np.int64)
    spans: list[tuple[int, int, bool]] = []
    start = 0
    for k in range(len(cubic)):
        end = int(min(ms[k + 1], total_ms))
        if end - start < MIN_CUBIC_MS and k + 1 < len(cubic):
            continue  # too short for its own segment: joins the next span
        exact = cubic[k] and end - start == int(ms[k + 1] - ms[k])
        spans.append((start, end, exact))
        start = end
    if start < total_ms:  # the end rounded up: held
        spans.append((start, total_ms, False))
    return [span for span in spans if span[1] > span[0]]


def _cubic_breaks(traj: Trajectory) -> tuple[list[float], list[bool]]:
    """Break times (s) and, per span between them, whether it is one cubic polynomial."""
    if isinstance(traj, PiecewisePolynomial):
        cubic = traj.coeffs.shape[1] <= 4
        breaks = list(np.asarray(traj.breaks, dtype=float)) if cubic else [0.0, traj.duration]
        return breaks, [cubic] * (len(breaks) - 1)
    if isinstance(traj, RestToRestSequence):
        breaks, flags = [0.0], []
        for offset, piece in zip(traj.starts, traj.pieces, strict=False):
            inner, inner_flags = _cubic_breaks(piece)
            breaks.extend(float(offset) + b for b in inner[1:])
            flags.extend(inner_flags)
        return breaks, flags
    return [0.0, traj.duration], [False]


def _fit(traj: Trajectory, tolerance: float) -> tuple[NDArray[np.int64], FloatArray, float]:
    """Boundaries (ms), unrounded Bézier points (m) and largest error (m), bisected to fit."""
    times = _boundaries(traj)
    while True:
        ctrl = _hermite(traj, times)
        err = _errors(traj, times, ctrl)
        split = (err > tolerance) & (np.diff(times) >= 2 * MIN_SEGMENT_MS)
        if not split.any() or times.size > MAX_SEGMENTS:
            return times, ctrl, float(err.max())
        middles = (times[:-1][split] + times[1:][split]) // 2
        times = np.sort(np.concatenate([times, middles]))


def skybrush_keyframes(traj: Trajectory, tolerance: float = FIT_TOLERANCE_M) -> Keyframes:
    """Cubic Bézier keyframes of ``traj`` on Skybrush's ms and mm grid.

    Parameters
    ----------
    traj
        Any 3-D trajectory, z-up world frame (Skybrush's show frame), m, from 0 s.
    tolerance
        Largest distance of the cubics from ``traj`` before rounding to the grid, m, for
        Skybrush's millimetre unit; times its unit where that is coarser.

    Returns
    -------
    Keyframes
        The last boundary is the duration rounded up to a millisecond (held at the end).

    Raises
    ------
    InputError
        When ``traj`` is not 3-D, ``tolerance`` is not positive, or the trajectory needs more
        than :data:`MAX_SEGMENTS` segments.
    """
    tolerance = as_float("tolerance", tolerance, positive=True)
    if traj.dim != 3:
        raise InputError(f"traj: got a {traj.dim}-D trajectory, expected 3-D (x, y, z up)")
    # Far from the origin Skybrush's unit is ``scale`` mm (3 mm for a 100 m show): a fit
    # finer than half a unit buys nothing after rounding, and the bisection it would need
    # makes short segments, where the rounding moves the acceleration most.
    coarse = scaling_factor(traj.evaluate(np.linspace(0.0, traj.duration, 1001)))
    times, ctrl, fit_error = _fit(traj, tolerance * coarse)
    # A keyframe is the same number in both its segments, so it rounds to the same unit.
    scale = 1
    for _ in range(SCALE_ROUNDS):
        units = np.rint(ctrl * (1000.0 / scale)).astype(np.int64)
        proposed = scaling_factor(encode(units, scale))
        if proposed == scale:
            break
        scale = proposed
    if scale >= 128:
        raise InputError(
            f"traj: got positions up to {float(np.abs(ctrl).max()):.6g} m from the origin, "
            "expected a show Skybrush can store (within about 4 km)"
        )
    return Keyframes(times, units, scale, fit_error)
