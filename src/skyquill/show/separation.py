"""The closest two drones of a show come, guaranteed rather than sampled.

For a pair of drones at distance ``d(t)`` whose relative speed is at most ``w``
on ``[a, b]`` (:mod:`skyquill.show.motion`), ``d`` is ``w``-Lipschitz there, so

    d(t) >= (d(a) + d(b) - w (b - a)) / 2        for every t in [a, b].

The show clock is cut into intervals of :data:`STEP_S`; pairs whose bounding
boxes over a window of :data:`WINDOW` intervals (grown by how far a drone can
move between samples) stay apart are pruned without looking closer; every other
interval whose bound falls below the distance asked for (or more than
:data:`TOLERANCE_M` below the closest distance seen) is bisected until it is
proven or a time closer than asked for is found. Everything is vectorised over
the pairs and intervals with numpy.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import SolverError
from skyquill.show.motion import LocalMotion, Motion, taylor_bound
from skyquill.validation import FloatArray, as_float

#: Grid step of the first pass, s.
STEP_S = 0.1
#: Grid intervals per window over which bounding boxes prune pairs.
WINDOW = 32
#: The guaranteed bound is refined until it is this close to the closest distance seen, m.
TOLERANCE_M = 0.01
#: Narrowest interval bisected, s: below it an interval that is still not proven is reported.
MIN_WIDTH_S = 1e-6
#: Pair-windows whose bounding boxes are compared at once (memory: ~100 bytes each).
CHUNK = 2_000_000
#: Most intervals held at once (memory: ~20 float64 each).
MAX_INTERVALS = 5_000_000

IntArray = NDArray[np.intp]


@dataclass(frozen=True)
class Encounter:
    """Two drones closer than asked for (or not proven farther).

    Attributes
    ----------
    drones
        Indices of the two drones in the show.
    first_time_s
        The first time found closer than the minimum, s (to :data:`MIN_WIDTH_S`).
    closest_m
        The smallest distance found between them, m.
    closest_time_s
        When, s.
    margin_m
        ``closest_m - minimum``, m (negative).
    proven
        ``False`` when no time closer than the minimum was found but the bound
        could not be raised to it either (the true minimum is within
        :data:`MIN_WIDTH_S` times the relative speed of it).
    """

    drones: tuple[int, int]
    first_time_s: float
    closest_m: float
    closest_time_s: float
    margin_m: float
    proven: bool = True


@dataclass(frozen=True)
class Separation:
    """The closest approach of a show.

    Attributes
    ----------
    minimum_m
        The distance asked for, m.
    lower_bound_m
        Guaranteed: no two drones are ever closer than this (to round-off), m.
    attained_m
        The smallest distance seen at a sampled time, m (``inf`` for one drone);
        the true minimum lies between the two.
    attained_drones, attained_time_s
        Which pair and when (``(-1, -1)`` and ``nan`` for one drone).
    encounters
        Each pair closer than ``minimum_m``, by first time.
    pairs, pairs_examined, intervals
        Pairs in the show, pairs not pruned by their bounding boxes, intervals bounded.
    """

    minimum_m: float
    lower_bound_m: float
    attained_m: float
    attained_drones: tuple[int, int]
    attained_time_s: float
    encounters: tuple[Encounter, ...]
    pairs: int
    pairs_examined: int
    intervals: int

    @property
    def passed(self) -> bool:
        """Whether no two drones come closer than :attr:`minimum_m` (proven)."""
        return not self.encounters and self.lower_bound_m >= self.minimum_m


@dataclass
class _Intervals:
    """Pair-intervals under examination, each field shape (M,)."""

    pair: IntArray
    a: FloatArray
    b: FloatArray
    da: FloatArray
    db: FloatArray
    w: FloatArray
    jump: FloatArray

    def lower(self) -> FloatArray:
        # A jump J inside the interval (round-off where a file's pieces meet) can move the
        # distance by J at the jump and J again against the Lipschitz line: 2 J of slack.
        slack = 0.5 * (self.da + self.db - self.w * (self.b - self.a)) - 2.0 * self.jump
        return np.minimum(np.minimum(self.da, self.db), slack)

    def take(self, keep: NDArray[np.bool_]) -> _Intervals:
        return _Intervals(
            self.pair[keep],
            self.a[keep],
            self.b[keep],
            self.da[keep],
            self.db[keep],
            self.w[keep],
            self.jump[keep],
        )


class _Closest:
    """The closest distance seen per pair, and the first time each pair is below the minimum."""

    def __init__(self, n_pairs: int, minimum: float) -> None:
        self.minimum = minimum
        self.d = np.full(n_pairs, np.inf)
        self.t = np.full(n_pairs, np.nan)
        self.first_bad = np.full(n_pairs, np.inf)

    def record(self, pair: IntArray, t: FloatArray, d: FloatArray) -> None:
        np.minimum.at(self.d, pair, d)
        hit = d == self.d[pair]
        self.t[pair[hit]] = t[hit]
        bad = d < self.minimum
        np.minimum.at(self.first_bad, pair[bad], t[bad])

    @property
    def best(self) -> float:
        return float(self.d.min()) if self.d.size else math.inf


def guaranteed_separation(
    motions: Sequence[Motion],
    minimum_m: float,
    *,
    step_s: float = STEP_S,
    tolerance_m: float = TOLERANCE_M,
) -> Separation:
    """The guaranteed closest approach of ``motions`` (all on one clock), against ``minimum_m``.

    Parameters
    ----------
    motions
        One per drone, all with the same horizon.
    minimum_m
        The distance two drones must keep, m, >= 0.
    step_s
        Grid step of the first pass, s.
    tolerance_m
        The bound is refined until it is this close to the closest distance seen, m.

    Raises
    ------
    InputError
        A negative or non-finite ``minimum_m``, a ``step_s`` that is not positive.
    SolverError
        More than :data:`MAX_INTERVALS` intervals would have to be bisected at once.
    """
    minimum = as_float("minimum_m", minimum_m, nonneg=True)
    step = as_float("step_s", step_s, positive=True)
    tolerance = as_float("tolerance_m", tolerance_m, positive=True)
    n = len(motions)
    first, second = np.triu_indices(n, 1)
    if n < 2:
        return Separation(minimum, math.inf, math.inf, (-1, -1), math.nan, (), 0, 0, 0)
    horizon = motions[0].horizon
    t = np.linspace(0.0, horizon, max(1, math.ceil(horizon / step)) + 1)
    pos = np.stack([m.position(t) for m in motions])
    # Only the speed bounds of the whole grid are kept: the derivatives are recomputed
    # for the intervals that survive the pruning.
    reach = np.stack([_reach(m, t) for m in motions])
    closest = _Closest(first.size, minimum)
    candidates = _candidates(pos=pos, reach=reach, t=t, first=first, second=second, minimum=minimum)
    grid = _grid_intervals(
        candidates=candidates, pos=pos, motions=motions, t=t, first=first, second=second
    )
    closest.record(grid.pair, grid.a, grid.da)
    closest.record(grid.pair, grid.b, grid.db)
    lower, count = _refine(grid, motions, (first, second), closest, tolerance)
    examined = np.unique(candidates[0]).size
    return _result(
        minimum=minimum,
        lower=lower,
        count=count,
        closest=closest,
        first=first,
        second=second,
        examined=examined,
    )


def _reach(motion: Motion, t: FloatArray) -> FloatArray:
    """How far a drone can stray from its grid samples in each interval (N - 1,), m.

    Half the interval at its speed bound, plus any jump where its pieces meet.
    """
    local = motion.local(t[:-1], t[1:])
    return np.asarray(local.speed * np.diff(t) / 2.0 + local.jump)


def _candidates(
    *,
    pos: FloatArray,
    reach: FloatArray,
    t: FloatArray,
    first: IntArray,
    second: IntArray,
    minimum: float,
) -> tuple[IntArray, IntArray]:
    """``(pair, window)`` whose bounding boxes come closer than needed to be sure."""
    n_int = t.size - 1
    starts = np.arange(0, n_int, WINDOW)
    ends = np.minimum(starts + WINDOW, n_int)
    # Within an interval a drone is within ``reach`` of one of its ends.
    grow = np.maximum.reduceat(reach, starts, axis=1)[..., None]
    lo = np.minimum(np.minimum.reduceat(pos[:, :-1], starts, axis=1), pos[:, ends]) - grow
    hi = np.maximum(np.maximum.reduceat(pos[:, :-1], starts, axis=1), pos[:, ends]) + grow
    chunks = _chunks(first.size, starts.size)
    # The distance at each window's start is one the show attains: pairs whose boxes
    # stay farther apart than it (and than the minimum) cannot hold the closest approach.
    sampled = min(
        float(np.linalg.norm(pos[first[c]][:, starts] - pos[second[c]][:, starts], axis=2).min())
        for c in chunks
    )
    threshold = max(minimum, sampled)
    found = []
    for c in chunks:
        i, j = first[c], second[c]
        gap = np.maximum(0.0, np.maximum(lo[i] - hi[j], lo[j] - hi[i]))
        pair, window = np.nonzero(np.linalg.norm(gap, axis=2) <= threshold)
        found.append((pair + c.start, window))
    return np.concatenate([p for p, _ in found]), np.concatenate([w for _, w in found])


def _chunks(n_pairs: int, n_windows: int) -> list[slice]:
    """Slices of the pairs that keep a chunk's (pairs, windows, 3) arrays within bounds."""
    size = max(1, CHUNK // n_windows)
    return [slice(s, min(s + size, n_pairs)) for s in range(0, n_pairs, size)]


def _grid_intervals(
    *,
    candidates: tuple[IntArray, IntArray],
    pos: FloatArray,
    motions: Sequence[Motion],
    t: FloatArray,
    first: IntArray,
    second: IntArray,
) -> _Intervals:
    """The grid intervals of the candidate windows with their bounds.

    Built a slice of candidate windows at a time, so that the local motions of both
    drones (some 400 bytes per interval while they are compared) never exist for
    more than :data:`CHUNK` intervals at once; what is kept is ~60 bytes per interval,
    at most :data:`MAX_INTERVALS` of them (a show whose drones crowd closer than that
    is refused, not swapped: 2,000 drones took 7 GiB here before).

    Raises
    ------
    SolverError
        More than :data:`MAX_INTERVALS` grid intervals to examine.
    """
    pair, window = candidates
    n_int = t.size - 1
    lengths = np.minimum(WINDOW, n_int - window * WINDOW)
    total = int(lengths.sum())
    if total > MAX_INTERVALS:
        raise SolverError(
            f"separation: got {total:,} grid intervals where drones come close, expected at "
            f"most {MAX_INTERVALS:,} (fewer drones, or drones that keep farther apart)"
        )
    ends = np.cumsum(lengths)
    grid: dict[str, Any] = {
        "pos": pos,
        "motions": motions,
        "t": t,
        "first": first,
        "second": second,
    }
    parts: list[_Intervals] = []
    start = 0
    while start < pair.size:
        stop = int(np.searchsorted(ends, ends[start] - lengths[start] + CHUNK, side="right"))
        stop = max(stop, start + 1)
        parts.append(
            _window_intervals(
                pair[start:stop],
                window[start:stop],
                lengths[start:stop],
                **grid,
            )
        )
        start = stop
    if not parts:
        return _window_intervals(pair, window, lengths, **grid)
    return _Intervals(
        *(
            np.concatenate([getattr(part, f) for part in parts])
            for f in _Intervals.__dataclass_fields__
        )
    )


def _window_intervals(
    pair: IntArray,
    window: IntArray,
    lengths: IntArray,
    *,
    pos: FloatArray,
    motions: Sequence[Motion],
    t: FloatArray,
    first: IntArray,
    second: IntArray,
) -> _Intervals:
    """The grid intervals of some candidate windows (``pair``, ``window``: shape (W,))."""
    pair = np.repeat(pair, lengths)
    offsets = np.arange(lengths.sum()) - np.repeat(np.cumsum(lengths) - lengths, lengths)
    k = np.repeat(window * WINDOW, lengths) + offsets
    i, j = first[pair], second[pair]
    da = np.linalg.norm(pos[i, k] - pos[j, k], axis=1)
    db = np.linalg.norm(pos[i, k + 1] - pos[j, k + 1], axis=1)
    a, b = t[k], t[k + 1]
    one, two = _local(motions, i, a, b), _local(motions, j, a, b)
    return _Intervals(pair, a, b, da, db, _relative(one, two, 0.5 * (b - a)), one.jump + two.jump)


def _pad(derivatives: FloatArray, width: int) -> FloatArray:
    """Derivatives (N, Q, 3) padded with zeros to (N, width, 3): higher orders of a lower degree."""
    return np.pad(derivatives, ((0, 0), (0, width - derivatives.shape[1]), (0, 0)))


def _relative(one: LocalMotion, two: LocalMotion, half_width: FloatArray) -> FloatArray:
    """A bound of ``|v_i - v_j|``: Taylor of the difference where both are one polynomial."""
    w = one.speed + two.speed
    both = one.inside & two.inside
    if both.any():
        diff = one.derivatives[both] - two.derivatives[both]
        w[both] = np.minimum(w[both], taylor_bound(diff, half_width[both]))
    return w


def _refine(
    items: _Intervals,
    motions: Sequence[Motion],
    pairs: tuple[IntArray, IntArray],
    closest: _Closest,
    tolerance: float,
) -> tuple[tuple[float, int, float], int]:
    """Bisect until every interval is proven.

    Returns the guaranteed bound with the pair and time where it is lowest, and
    the number of intervals bounded.
    """
    lower = (math.inf, -1, math.nan)
    count = items.a.size
    while items.a.size:
        lb = items.lower()
        target = max(closest.minimum, closest.best - tolerance)
        open_ = (
            (lb < target)
            & (items.b - items.a > MIN_WIDTH_S)
            & (items.a < closest.first_bad[items.pair])
        )
        if (~open_).any():
            k = int(np.argmin(np.where(open_, np.inf, lb)))
            if lb[k] < lower[0]:
                lower = (float(lb[k]), int(items.pair[k]), float(items.a[k]))
        items = items.take(open_)
        if 2 * items.a.size > MAX_INTERVALS:
            if tolerance == math.inf:
                raise SolverError(
                    f"separation: got more than {MAX_INTERVALS:,} intervals to bisect, expected "
                    "fewer (drones that keep exactly the minimum distance while moving)"
                )
            # Stop tightening the bound: only what decides pass or fail is bisected.
            tolerance = math.inf
            continue
        items = _split(items, motions, *pairs, closest)
        count += items.a.size
    return lower, count


def _split(
    items: _Intervals,
    motions: Sequence[Motion],
    first: IntArray,
    second: IntArray,
    closest: _Closest,
) -> _Intervals:
    """Both halves of every interval, with the distance at the midpoints recorded."""
    mid = 0.5 * (items.a + items.b)
    i, j = first[items.pair], second[items.pair]
    dm = np.linalg.norm(_positions(motions, i, mid) - _positions(motions, j, mid), axis=1)
    closest.record(items.pair, mid, dm)
    a = np.concatenate([items.a, mid])
    b = np.concatenate([mid, items.b])
    ii, jj = np.concatenate([i, i]), np.concatenate([j, j])
    one, two = _local(motions, ii, a, b), _local(motions, jj, a, b)
    return _Intervals(
        np.concatenate([items.pair, items.pair]),
        a,
        b,
        np.concatenate([items.da, dm]),
        np.concatenate([dm, items.db]),
        _relative(one, two, 0.5 * (b - a)),
        one.jump + two.jump,
    )


def _positions(motions: Sequence[Motion], who: IntArray, t: FloatArray) -> FloatArray:
    out = np.empty((t.size, 3))
    for d in np.unique(who):
        mask = who == d
        out[mask] = motions[d].position(t[mask])
    return out


def _local(motions: Sequence[Motion], who: IntArray, a: FloatArray, b: FloatArray) -> LocalMotion:
    width = max(m.order for m in motions) - 1
    derivs = np.zeros((a.size, width, 3))
    inside = np.zeros(a.size, dtype=bool)
    speed = np.empty(a.size)
    jump = np.empty(a.size)
    for d in np.unique(who):
        mask = who == d
        lm = motions[d].local(a[mask], b[mask])
        derivs[mask] = _pad(lm.derivatives, width)
        inside[mask] = lm.inside
        speed[mask] = lm.speed
        jump[mask] = lm.jump
    return LocalMotion(derivs, inside, speed, jump)


def _result(
    *,
    minimum: float,
    lower: tuple[float, int, float],
    count: int,
    closest: _Closest,
    first: IntArray,
    second: IntArray,
    examined: int,
) -> Separation:
    encounters = []
    for p in np.flatnonzero(np.isfinite(closest.first_bad)):
        encounters.append(_encounter(int(p), float(closest.first_bad[p]), closest, (first, second)))
    bound, pair, when = lower
    if not encounters and bound < minimum:  # not found closer, not proven farther either
        encounters.append(_encounter(pair, when, closest, (first, second), proven=False))
    encounters.sort(key=lambda e: (e.first_time_s, e.drones))
    best = int(np.argmin(closest.d))
    finite_lower = min(bound, closest.best)
    return Separation(
        minimum_m=minimum,
        lower_bound_m=finite_lower,
        attained_m=closest.best,
        attained_drones=(int(first[best]), int(second[best])),
        attained_time_s=float(closest.t[best]),
        encounters=tuple(encounters),
        pairs=int(first.size),
        pairs_examined=examined,
        intervals=count,
    )


def _encounter(
    p: int, when: float, closest: _Closest, pairs: tuple[IntArray, IntArray], proven: bool = True
) -> Encounter:
    first, second = pairs
    return Encounter(
        drones=(int(first[p]), int(second[p])),
        first_time_s=when,
        closest_m=float(closest.d[p]),
        closest_time_s=float(closest.t[p]),
        margin_m=float(closest.d[p]) - closest.minimum,
        proven=proven,
    )
