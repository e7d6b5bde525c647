"""Where a drone's Skybrush segments start and end: integer milliseconds chosen from the plan.

Skybrush stores segment durations in whole milliseconds and Bézier points in whole units of
``scale`` mm (:mod:`skyquill.export.skybrush.playback`). Rounding a cubic Bézier point by up
to half a unit ``u`` moves the segment's derivatives by up to (per axis, over a segment of
``h`` seconds)

* velocity ``3 u / h`` (first differences of the points, each off by up to ``u``),
* acceleration ``12 u / h^2`` (second differences, up to ``2 u``, times ``6 / h^2``),
* jerk ``24 u / h^3`` (third differences, up to ``4 u``, times ``6 / h^3``),

and ``sqrt(3)`` times that for a norm over three axes. Short segments are therefore
expensive: 50 ms segments of a millimetre grid can move the jerk by 190 m/s^3. So:

* where the plan is itself one cubic polynomial for at least :data:`MIN_EXACT_MS` (a
  time-optimal move's phase, a hold), that piece is its own segment (split every
  :data:`MAX_EXACT_MS`): the keyframes hold it exactly, and the rounding is kept inside the
  limits by :mod:`skyquill.export.skybrush.grid_rounding`;
* everywhere else (splines of higher degree, coverage's retimed paths, short pieces merged
  with their neighbours) a *fit region* of segments of about :func:`fit_segment_ms` each:
  long enough that the worst-case rounding perturbation above is at most
  :data:`ROUNDING_SHARE` of each limit (the stated bound; what is left is removed by the
  limit-aware rounding), fitted by :mod:`skyquill.export.skybrush.keyframe_fit`.

A fit region needs at least four segments (with position, velocity and acceleration fixed at
both ends and C2 joins, a cubic spline of ``n`` segments has ``n - 3`` free points per axis),
so a short one grows into the exact pieces beside it.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.limits import DerivativeLimit, limit_bounds
from skyquill.trajectory import PiecewisePolynomial, RestToRestSequence, Trajectory

#: Shortest cubic piece of the plan kept as an exact segment of its own, ms (or half a fit
#: segment, if that is longer).
MIN_EXACT_MS = 100
#: Longest exact segment, ms (a hold or a cruise is split into segments of at most this).
MAX_EXACT_MS = 1000
#: Shortest and longest segment of a fit region, ms.
MIN_FIT_MS = 100
MAX_FIT_MS = 1000
#: Fewest segments of a fit region (``n - 3`` free points per axis: at least one).
MIN_REGION_SEGMENTS = 4
#: Share of each limit the worst-case rounding of a fit segment may move its derivative by
#: (velocity, acceleration, jerk); the limit-aware rounding takes out what crosses a limit.
ROUNDING_SHARE = {1: 0.25, 2: 0.5, 3: 1.0}
#: Worst-case per-axis rounding perturbation of a cubic segment: ``factor * u / h^order``.
ROUNDING_FACTOR = {1: 3.0, 2: 12.0, 3: 24.0}
#: Most segments per drone (a 40-hour show at 250 ms): bounds memory and time.
MAX_SEGMENTS = 600_000


@dataclass(frozen=True)
class Segmentation:
    """A drone's segment boundaries and how each segment is made.

    Attributes
    ----------
    times_ms
        Boundaries, shape (P + 1,), integer ms from 0; the last is the duration rounded up.
    exact
        Shape (P,): the segment is one cubic piece of the plan, held exactly.
    regions
        Fit regions as ``(first, stop)`` segment indices (``stop`` excluded), in order.
    """

    times_ms: NDArray[np.int64]
    exact: NDArray[np.bool_]
    regions: tuple[tuple[int, int], ...]


def fit_segment_ms(limits: Sequence[DerivativeLimit], unit_m: float, scale: float = 1.0) -> int:
    """Length of a fit region's segments, ms: the worst-case rounding within the share.

    The shortest ``h`` with ``sqrt(3) * ROUNDING_FACTOR[n] * unit_m / h^n <=
    ROUNDING_SHARE[n] * bound_n`` for every limited order ``n`` (module docstring), times
    ``scale`` (a refit asks for longer segments), within [:data:`MIN_FIT_MS`,
    :data:`MAX_FIT_MS`].
    """
    h = MIN_FIT_MS / 1000.0
    for order, bound in limit_bounds(limits).items():
        if order not in ROUNDING_FACTOR or bound <= 0:
            continue
        worst = math.sqrt(3.0) * ROUNDING_FACTOR[order] * unit_m
        h = max(h, (worst / (ROUNDING_SHARE[order] * bound)) ** (1.0 / order))
    return int(min(MAX_FIT_MS, max(MIN_FIT_MS, round(1000.0 * h * scale))))


def cubic_spans(traj: Trajectory, total_ms: int) -> list[tuple[int, int, bool]]:
    """``(start, end, cubic)`` spans covering ``[0, total_ms]`` ms, from the plan's pieces.

    ``cubic``: the plan is one polynomial of degree <= 3 there. Piece ends are rounded to the
    millisecond; the last span reaches ``total_ms`` (the duration rounded up): a plan ends at
    rest, so its last piece held to the next millisecond is a cubic stretched by less than a
    millisecond (a non-cubic sliver there would need a fit region where the plan brakes at
    its jerk limit, which short fit segments on the millimetre grid cannot follow).
    """
    breaks, cubic = _cubic_breaks(traj)
    ms = np.round(np.asarray(breaks) * 1000).astype(np.int64)
    spans = []
    for k, flag in enumerate(cubic):
        start, end = int(ms[k]), int(min(ms[k + 1], total_ms))
        if end > start:
            spans.append((start, end, flag))
    if not spans:
        return [(0, total_ms, False)]
    start, last, flag = spans[-1]
    spans[-1] = (start, total_ms, flag and total_ms - last <= 1)
    return spans


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


def segmentation(
    traj: Trajectory,
    limits: Sequence[DerivativeLimit],
    unit_m: float,
    *,
    exact: bool = True,
    scale: float = 1.0,
    grow: float = 1.0,
) -> Segmentation:
    """The segments of ``traj`` on Skybrush's millisecond grid (module docstring).

    Parameters
    ----------
    traj
        The plan, s from 0.
    limits
        Its limits (they set the fit segments' length).
    unit_m
        Skybrush's coordinate unit, m (``scale`` mm).
    exact
        Keep the plan's cubic pieces as exact segments; ``False`` fits everything (a refit).
    scale
        Factor on the fit segments' length (a refit asks for longer ones).
    grow
        Factor on the shortest fit region (a region that cannot keep the limits grows).

    Raises
    ------
    InputError
        When the trajectory needs more than :data:`MAX_SEGMENTS` segments.
    """
    total = max(1, math.ceil(traj.duration * 1000 - 1e-6))
    h_fit = fit_segment_ms(limits, unit_m, scale)
    # An exact piece much shorter than a fit segment would be rounded coarser than the limits
    # allow (slow limits: 100 ms at 0.05 m/s moves the speed by 60 % a unit).
    shortest = max(MIN_EXACT_MS, h_fit // 2)
    spans = [
        (a, b, flag and exact and b - a >= shortest) for a, b, flag in cubic_spans(traj, total)
    ]
    regions = _grown(_runs(spans), total, round(2 * h_fit * grow))
    times: list[int] = [0]
    exact_flags: list[bool] = []
    fit_ranges: list[tuple[int, int]] = []
    breaks = np.array([a for a, _, flag in spans if flag] + [b for _, b, flag in spans if flag])
    for start_ms, end_ms, fitted in _pieces(spans, regions):
        if fitted:
            start = len(exact_flags)
            cuts = region_cuts(start_ms, end_ms, breaks, h_fit)
            n = cuts.size
            times.extend(int(c) for c in cuts)
            exact_flags.extend([False] * n)
            fit_ranges.append((start, len(exact_flags)))
        else:
            _exact_segments(start_ms, end_ms, times, exact_flags)
    if len(exact_flags) > MAX_SEGMENTS:
        raise InputError(
            f"trajectory: got {traj.duration:.6g} s needing {len(exact_flags)} Skybrush "
            f"segments, expected at most {MAX_SEGMENTS}"
        )
    return Segmentation(
        np.array(times, dtype=np.int64), np.array(exact_flags, dtype=bool), tuple(fit_ranges)
    )


def region_cuts(
    start_ms: int, end_ms: int, breaks: NDArray[np.int64], h_fit: int
) -> NDArray[np.int64]:
    """A fit region's segment ends after ``start_ms``, ms: at the plan's own cubic breaks.

    Where the plan is made of cubic pieces (a time-optimal move whose jerk switches between
    its bounds), a knot at each switch lets the C2 spline follow it exactly; uniform knots
    would average the jerk across a switch, and a plan on its jerk limit cannot then be
    followed within the limits. Breaks closer than ``h_fit / 2`` to a kept one are dropped (the
    grid's rounding of shorter segments is coarser than the limits), and what remains is
    cut into segments of about ``h_fit``, at least :data:`MIN_REGION_SEGMENTS` in all.
    """
    inside = np.unique(breaks[(breaks > start_ms) & (breaks < end_ms)])
    knots = [start_ms]
    for b in inside:
        if b - knots[-1] >= h_fit // 2 and end_ms - b >= h_fit // 2:
            knots.append(int(b))
    knots.append(end_ms)
    cuts: list[NDArray[np.int64]] = []
    for a, b in itertools.pairwise(knots):
        n = max(1, round((b - a) / h_fit))
        cuts.append(np.round(np.linspace(a, b, n + 1)).astype(np.int64)[1:])
    out = np.concatenate(cuts)
    if out.size < MIN_REGION_SEGMENTS:
        out = np.round(np.linspace(start_ms, end_ms, MIN_REGION_SEGMENTS + 1)).astype(np.int64)[1:]
    return out


def _runs(spans: list[tuple[int, int, bool]]) -> list[tuple[int, int]]:
    """Maximal ``(start, end)`` ms runs of spans that are not exact."""
    runs: list[tuple[int, int]] = []
    for a, b, exact in spans:
        if exact:
            continue
        if runs and runs[-1][1] == a:
            runs[-1] = (runs[-1][0], b)
        else:
            runs.append((a, b))
    return runs


def _grown(runs: list[tuple[int, int]], total: int, shortest: int) -> list[tuple[int, int]]:
    """Each run grown (into the exact pieces beside it) to at least ``shortest`` ms, merged.

    Grown regions start and end inside the plan's cubic pieces, where it is C2, so their
    boundary states are the plan's.
    """
    grown: list[tuple[int, int]] = []
    shortest = min(shortest, total)
    for start, end in runs:
        missing = max(0, shortest - (end - start))
        a = max(0, start - (missing + 1) // 2)
        b = min(total, a + max(shortest, end - a))  # what the start could not take, the end does
        a = max(0, min(a, b - shortest))
        if grown and a <= grown[-1][1]:
            grown[-1] = (grown[-1][0], max(b, grown[-1][1]))
        else:
            grown.append((a, b))
    return grown


def _pieces(
    spans: list[tuple[int, int, bool]], regions: list[tuple[int, int]]
) -> list[tuple[int, int, bool]]:
    """``(start, end, fitted)`` in order over the whole duration, ms: each exact span's parts
    outside the regions (``fitted`` False) and each region (True)."""
    out: list[tuple[int, int, bool]] = []
    edges = [(a, b) for a, b, exact in spans if exact]
    cursor = 0
    for first, last in [*regions, (spans[-1][1], spans[-1][1])]:
        for a, b in edges:
            lo, hi = max(a, cursor), min(b, first)
            if hi > lo:
                out.append((lo, hi, False))
        if last > first:
            out.append((first, last, True))
        cursor = last
    return _absorbed(out)


def _absorbed(pieces: list[tuple[int, int, bool]]) -> list[tuple[int, int, bool]]:
    """Exact remainders shorter than :data:`MIN_EXACT_MS` (where a region cut a piece) joined
    to the fit region beside them; adjacent regions merged."""
    out: list[tuple[int, int, bool]] = []
    for i, (a, b, was_fitted) in enumerate(pieces):
        short = not was_fitted and b - a < MIN_EXACT_MS
        beside = (out and out[-1][2]) or (i + 1 < len(pieces) and pieces[i + 1][2])
        fitted = was_fitted or bool(short and beside)
        if out and fitted and out[-1][2]:
            out[-1] = (out[-1][0], b, True)
        else:
            out.append((a, b, fitted))
    return out


def _exact_segments(start: int, end: int, times: list[int], flags: list[bool]) -> None:
    """Append exact segments from ``start`` to ``end`` ms, each at most :data:`MAX_EXACT_MS`."""
    if end <= start:
        return
    n = math.ceil((end - start) / MAX_EXACT_MS)
    cuts = np.round(np.linspace(start, end, n + 1)).astype(np.int64)[1:]
    times.extend(int(c) for c in cuts)
    flags.extend([True] * n)
