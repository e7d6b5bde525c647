"""A trajectory as Skybrush keyframes: C2 cubic Bézier segments on Skybrush's ms and mm grid.

Skybrush's server stores segment durations in whole milliseconds and coordinates in units
of ``scale`` mm (:mod:`skyquill.export.skybrush.playback`). Every segment boundary here is an
integer millisecond and every Bézier point is written as a number that the server's
truncation maps to the intended integer, so what the drone plays is exactly what is built
here, and the export checks it as played.

Construction (each step its own module):

1. segment boundaries (:mod:`.keyframe_times`): the plan's own cubic pieces (time-optimal
   moves, holds) are exact segments; everything else is cut into *fit regions* of segments
   long enough that the grid's rounding moves the derivatives by a bounded share of the
   limits;
2. the curve (:mod:`.keyframe_fit`): exact segments are the plan's cubic (its position and
   velocity at both ends); fit regions are the C2 cubic spline nearest the plan that keeps
   the plan's limits on its Bézier hull, with the plan's position, velocity and acceleration
   where it meets the exact pieces, so the joins are C2 (before rounding; within a
   half-millisecond break of the plan's pieces everywhere);
3. the grid (:mod:`.grid_rounding`): every Bézier point to the nearest unit, except where
   that would cross a limit, where the nearest combination that does not is chosen.

**Why cubics, not degree 5 or 7.** Skybrush's binary format stores 1, 2, 4 or 8 points per
axis (libskybrush ``src/trajectory/utils.c``, ``sb_i_get_num_coords``: degree 0, 1, 3 or 7;
skybrush-server ``show/formats.py``, ``SegmentEncoder._encode_coordinate_series``: degrees 4
to 6 raise ``NotImplementedError``), so a quintic would be flown as a degree-7 segment; the
firmware plays those, but skybrush.js (``packages/show-format/src/trajectory.ts``,
``createSegmentFunctions``: "Only quadratic and cubic Bezier segments are supported") and so
every tool built on it cannot show them. And the rounding is the limit: a degree-``n``
Bézier's ``k``-th derivative moves by ``n!/(n-k)! 2^(k-1) u / h^k`` per axis when its points
move by half a unit ``u``, which for the jerk is 35 times more at degree 7 (840 ``u/h^3``)
than at degree 3 (24 ``u/h^3``): the same bound needs 3.3 times longer segments. A C2 cubic
spline has continuous acceleration, which is what the joins need.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import InfeasibleError, InputError
from skyquill.export.skybrush.grid_rounding import Rounding, round_to_grid
from skyquill.export.skybrush.keyframe_fit import fit_region
from skyquill.export.skybrush.keyframe_times import Segmentation, segmentation
from skyquill.export.skybrush.playback import quantize, scaling_factor
from skyquill.limits import DerivativeLimit
from skyquill.trajectory import Trajectory, derivatives
from skyquill.validation import FloatArray, as_float

#: Points per segment at which the keyframes' distance from the plan is measured (ends included).
ERROR_SAMPLES = 17
#: Times the scaling factor is re-proposed after rounding (it settles after one).
SCALE_ROUNDS = 4


@dataclass(frozen=True)
class Keyframes:
    """One drone's C2 cubic Bézier segments on Skybrush's grid.

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
    exact_segments
        Segments that are the plan's own cubic pieces.
    fit_segment_ms
        Length of the fit regions' segments, ms.
    rounding
        What the rounding to the grid did (:mod:`.grid_rounding`).
    """

    times_ms: NDArray[np.int64]
    units: NDArray[np.int64]
    scale: int
    fit_error_m: float
    exact_segments: int = 0
    fit_segment_ms: int = 0
    rounding: Rounding | None = None

    def report(self) -> dict[str, Any]:
        """JSON-ready: how the keyframes were made (segments, fit, rounding)."""
        out: dict[str, Any] = {
            "segments": int(self.units.shape[0]),
            "exact_segments": self.exact_segments,
            "fit_segment_ms": self.fit_segment_ms,
            "fit_error_m": self.fit_error_m,
            "scale_mm": self.scale,
        }
        if self.rounding is not None:
            out["rounding"] = {
                "adjusted_segments": self.rounding.adjusted,
                "unresolved_segments": len(self.rounding.unresolved),
                # None for an order without a limit
                "hull_excess": [e if math.isfinite(e) else None for e in self.rounding.hull_excess],
            }
        return out

    def points(self) -> list[list[Any]]:
        """The ``points`` list of ``show.json``: ``[t, [x, y, z], [[c1], [c2]]]``, s and m."""
        # one tolist of all the numbers, then lists of its lists: not three per segment
        values = encode(self.units, self.scale).tolist()
        times = (self.times_ms / 1000.0).tolist()
        first: list[Any] = [times[0], values[0][0], []]
        return [first] + [
            [t, segment[3], segment[1:3]] for t, segment in zip(times[1:], values, strict=True)
        ]


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
    at = derivatives(traj, t, (0, 1))
    p, v = at[0], at[1]
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


#: Times a fit region that cannot keep the limits is grown before the fit gives up.
GROW_ROUNDS = 3


def _curve(
    traj: Trajectory,
    limits: Sequence[DerivativeLimit],
    unit_m: float,
    *,
    margin: float,
    exact: bool,
    segment_scale: float,
) -> tuple[Segmentation, FloatArray]:
    """Segments and their unrounded Bézier points (S, 4, 3), m: exact pieces and fit regions.

    A fit region that cannot keep the limits (a short region around a rest, where the plan
    stops and starts again faster than a few cubics can follow) is grown and fitted again.
    """
    grow = 1.0
    for attempt in range(GROW_ROUNDS + 1):
        seg = segmentation(traj, limits, unit_m, exact=exact, scale=segment_scale, grow=grow)
        points = _hermite(traj, seg.times_ms)
        try:
            for first, stop in seg.regions:
                points[first:stop] = fit_region(
                    traj, seg.times_ms[first : stop + 1].astype(float), limits, margin
                )
        except InfeasibleError:
            if attempt == GROW_ROUNDS:
                raise
            grow *= 2.0
            continue
        return seg, points
    raise AssertionError("unreachable")  # pragma: no cover


def skybrush_keyframes(
    traj: Trajectory,
    limits: Sequence[DerivativeLimit] = (),
    *,
    margin: float = 0.0,
    exact: bool = True,
    segment_scale: float = 1.0,
) -> Keyframes:
    """C2 cubic Bézier keyframes of ``traj`` on Skybrush's ms and mm grid, inside ``limits``.

    Parameters
    ----------
    traj
        Any 3-D trajectory, z-up world frame (Skybrush's show frame), m, from 0 s.
    limits
        The limits it was planned for: the fit keeps them on its hull, the rounding does not
        cross them by more than :data:`~.grid_rounding.ALLOWED_EXCESS` (none: no limit).
    margin
        Relative shrink of the limits for the fit, in [0, 0.5] (a refit asks for one).
    exact
        Keep the plan's cubic pieces as exact segments (``False``: fit everything).
    segment_scale
        Factor on the fit regions' segment length, in [0.25, 8] (a refit asks for longer).

    Returns
    -------
    Keyframes
        The last boundary is the duration rounded up to a millisecond (held at the end).

    Raises
    ------
    InputError
        When ``traj`` is not 3-D, an option is out of range, or the trajectory needs more
        than :data:`~.keyframe_times.MAX_SEGMENTS` segments or lies beyond what Skybrush
        can store (about 4 km from the origin).
    InfeasibleError
        When a fit region cannot keep the limits.
    """
    if traj.dim != 3:
        raise InputError(f"traj: got a {traj.dim}-D trajectory, expected 3-D (x, y, z up)")
    margin = as_float("margin", margin, nonneg=True)
    if margin > 0.5:
        raise InputError(f"margin: got {margin:g}, expected at most 0.5")
    segment_scale = as_float("segment_scale", segment_scale, positive=True)
    if not 0.25 <= segment_scale <= 8.0:
        raise InputError(f"segment_scale: got {segment_scale:g}, expected 0.25 to 8")
    # Far from the origin Skybrush's unit is ``scale`` mm (3 mm for a 100 m show).
    coarse = scaling_factor(traj.evaluate(np.linspace(0.0, traj.duration, 1001)))
    seg, points = _curve(
        traj, limits, coarse / 1000.0, margin=margin, exact=exact, segment_scale=segment_scale
    )
    fit_error = float(_errors(traj, seg.times_ms, points).max())
    h = np.diff(seg.times_ms) / 1000.0
    # A keyframe is the same number in both its segments, so it rounds to the same unit.
    scale = max(1, scaling_factor(points))
    rounding = round_to_grid(points, h, limits, scale / 1000.0)
    for _ in range(SCALE_ROUNDS):
        proposed = scaling_factor(encode(rounding.units, scale))
        if proposed == scale:
            break
        scale = proposed
        rounding = round_to_grid(points, h, limits, scale / 1000.0)
    if scale >= 128:
        raise InputError(
            f"traj: got positions up to {float(np.abs(points).max()):.6g} m from the origin, "
            "expected a show Skybrush can store (within about 4 km)"
        )
    return Keyframes(
        seg.times_ms,
        rounding.units,
        scale,
        fit_error,
        int(seg.exact.sum()),
        _fit_length(seg),
        rounding,
    )


def _fit_length(seg: Segmentation) -> int:
    """The median length of the fit regions' segments, ms (0 without any)."""
    fitted = np.diff(seg.times_ms)[~seg.exact]
    return round(float(np.median(fitted))) if fitted.size else 0
