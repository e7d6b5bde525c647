"""The closest two drones of a show come, guaranteed rather than sampled.

For a pair of drones at distance ``d(t)`` whose relative speed is at most ``w``
on ``[a, b]`` (:mod:`skyquill.show.motion`), ``d`` is ``w``-Lipschitz there, so

    d(t) >= (d(a) + d(b) - w (b - a)) / 2        for every t in [a, b].

The show clock is cut into intervals of :data:`STEP_S`. Each drone gets a
box in space over each window of :data:`WINDOW` intervals (its samples, grown
by how far it can move between them); only pairs whose boxes come closer than
the closest distance seen at the windows' starts (or the distance asked for)
are looked at, found by sweep and prune over all the space-time boxes at once
(:mod:`skyquill.show.pairs`), so the work grows with the drones and their
neighbours, not with every pair: a drone has a bounded number of neighbours
within a few metres, whatever the size of the show. Every interval of those
pairs whose bound falls below the distance asked for (or more than
:data:`TOLERANCE_M` below the closest distance seen) is bisected until it is
proven or a time closer than asked for is found. Everything is vectorised over
the pairs, intervals and drones with numpy (:class:`skyquill.show.fleet.Fleet`
holds every drone's pieces in one table), in chunks of bounded memory.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from skyquill.errors import SolverError
from skyquill.show.fleet import Fleet
from skyquill.show.motion import LocalMotion, Motion, taylor_bound
from skyquill.show.pairs import close_boxes
from skyquill.show.waves import closest_on_segments
from skyquill.validation import FloatArray, as_float

#: Grid step of the first pass, s.
STEP_S = 0.1
#: Grid intervals per window over which bounding boxes prune pairs.
WINDOW = 32
#: The guaranteed bound is refined until it is this close to the closest distance seen, m.
TOLERANCE_M = 0.01
#: Narrowest interval bisected, s: below it an interval that is still not proven is reported.
MIN_WIDTH_S = 1e-6
#: Grid intervals bounded at once (memory: ~500 bytes each with degree-7 pieces).
CHUNK = 250_000
#: Drone samples evaluated at once for the boxes (memory: ~250 bytes each).
BOX_SAMPLES = 250_000
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
    taylor: FloatArray

    def lower(self) -> FloatArray:
        # A jump J inside the interval (round-off where a file's pieces meet) can move the
        # distance by J at the jump and J again against the Lipschitz line: 2 J of slack.
        slack = 0.5 * (self.da + self.db - self.w * (self.b - self.a)) - 2.0 * self.jump
        return np.minimum(np.minimum(self.da, self.db), np.maximum(slack, self.taylor))

    def take(self, keep: NDArray[np.bool_]) -> _Intervals:
        return _Intervals(*(getattr(self, f)[keep] for f in _FIELDS))


_FIELDS = tuple(_Intervals.__dataclass_fields__)


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
    prune: bool = True,
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
    prune
        Examine only the pairs whose space-time boxes come close (``False``: every pair in
        every window, ``N^2 / 2`` pairs: the reference the pruning is tested against).

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
    if n < 2:
        return Separation(minimum, math.inf, math.inf, (-1, -1), math.nan, (), 0, 0, 0)
    fleet = Fleet(motions)
    t = np.linspace(0.0, fleet.horizon, max(1, math.ceil(fleet.horizon / step)) + 1)
    # The distance at each window's start is one the show attains: pairs whose boxes
    # stay farther apart than it (and than the minimum) cannot hold the closest approach.
    # (Grown by round-off: the k-d tree's distances and the boxes' gaps round differently.)
    threshold = max(minimum, _sampled_closest(fleet, t[::WINDOW])) * (1.0 + 1e-9) + 1e-12
    first, second, window = (_candidates if prune else _every_pair)(fleet, t, threshold)
    pair_of, pair_index = np.unique(first * n + second, return_inverse=True)
    pairs = (pair_of // n, pair_of % n)
    closest = _Closest(pair_of.size, minimum)
    items, lower, count = _grid_intervals(
        fleet, t, pairs, (pair_index, window), closest=closest, tolerance=tolerance
    )
    lower, count = _refine(
        items, fleet, pairs, closest=closest, tolerance=tolerance, lower=lower, count=count
    )
    return _result(
        minimum=minimum,
        lower=lower,
        count=count,
        closest=closest,
        first=pairs[0],
        second=pairs[1],
        total=n * (n - 1) // 2,
    )


def _sampled_closest(fleet: Fleet, times: FloatArray) -> float:
    """The smallest distance between two drones at any of ``times``, m (k-d trees)."""
    n = len(fleet)
    best = math.inf
    for t in times:
        points = fleet.position(np.arange(n), np.full(n, t))
        distance = np.asarray(cKDTree(points).query(points, k=2)[0])
        best = min(best, float(distance[:, 1].min()))
    return best


def _candidates(fleet: Fleet, t: FloatArray, threshold: float) -> tuple[IntArray, ...]:
    """``(first, second, window)`` whose space-time boxes come within ``threshold``.

    A drone's box over a window of :data:`WINDOW` grid intervals holds its grid
    samples, grown by how far it can stray from the nearest one (half an interval at
    its largest speed bound in the window, plus any jumps where its pieces meet).
    The boxes of all windows are swept at once (:func:`skyquill.show.pairs.close_boxes`).
    """
    n, n_int = len(fleet), t.size - 1
    starts = np.arange(0, n_int, WINDOW)
    lo = np.empty((starts.size, n, 3))
    hi = np.empty((starts.size, n, 3))
    per_batch = max(1, BOX_SAMPLES // (n * (WINDOW + 1)))
    for begin in range(0, starts.size, per_batch):
        windows = np.arange(begin, min(begin + per_batch, starts.size))
        lo[windows], hi[windows] = _boxes(fleet, t, starts[windows])
    boxes_first, boxes_second = close_boxes(
        lo.reshape(-1, 3), hi.reshape(-1, 3), threshold, np.repeat(np.arange(starts.size), n)
    )
    window = boxes_first // n
    one, two = boxes_first % n, boxes_second % n
    return np.minimum(one, two), np.maximum(one, two), window


def _every_pair(fleet: Fleet, t: FloatArray, threshold: float) -> tuple[IntArray, ...]:
    """``(first, second, window)`` of every pair in every window (nothing pruned)."""
    del threshold  # every pair, however far apart
    first, second = np.triu_indices(len(fleet), 1)
    windows = np.arange(0, t.size - 1, WINDOW).size
    return (
        np.tile(first, windows).astype(np.intp),
        np.tile(second, windows).astype(np.intp),
        np.repeat(np.arange(windows), first.size).astype(np.intp),
    )


def _boxes(fleet: Fleet, t: FloatArray, starts: IntArray) -> tuple[FloatArray, FloatArray]:
    """Every drone's box over the windows beginning at grid index ``starts`` (W,): (W, N, 3)."""
    n, last = len(fleet), t.size - 1
    k = np.minimum(starts[:, None] + np.arange(WINDOW + 1)[None, :], last)  # (W, WINDOW + 1)
    times = t[k]
    who = np.repeat(np.arange(n), times.size)
    pos = fleet.position(who, np.tile(times.ravel(), n)).reshape(n, *times.shape, 3)
    a, b = times[:, 0], times[:, -1]
    first = fleet.piece(np.repeat(np.arange(n), a.size), np.tile(a, n), "right")
    stop = fleet.piece(np.repeat(np.arange(n), b.size), np.tile(b, n), "left") + 1
    speed = fleet.largest_whole(first, np.maximum(stop, first + 1)).reshape(n, a.size)
    crossings = (stop - 1 - first).reshape(n, a.size)
    step = float(np.diff(t).max()) if t.size > 1 else 0.0
    grow = (speed * step / 2.0 + crossings * fleet.jump[:, None])[..., None]  # (N, W, 1)
    lo = (pos.min(axis=2) - grow).transpose(1, 0, 2)
    hi = (pos.max(axis=2) + grow).transpose(1, 0, 2)
    return lo, hi


def _grid_intervals(
    fleet: Fleet,
    t: FloatArray,
    pairs: tuple[IntArray, IntArray],
    candidates: tuple[IntArray, IntArray],
    *,
    closest: _Closest,
    tolerance: float,
) -> tuple[_Intervals, tuple[float, int, float], int]:
    """The grid intervals of the candidate windows, bounded, in chunks of :data:`CHUNK`.

    Returns the intervals still open (their bound below what is asked for), the
    lowest bound of those already proven, and how many intervals were bounded.
    Every chunk's samples are recorded in ``closest`` first. Memory holds one chunk
    (some 500 bytes per interval while both drones' motions are compared) and the
    intervals still open (~60 bytes each).

    Raises
    ------
    SolverError
        More than :data:`MAX_INTERVALS` grid intervals to examine (drones crowding
        closer than the distance asked for over much of the show): refused before
        the work, not swapped.
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
    kept: list[_Intervals] = []
    lower = (math.inf, -1, math.nan)
    count = 0
    per_chunk = max(1, CHUNK // WINDOW)
    for begin in range(0, pair.size, per_chunk):
        part = slice(begin, begin + per_chunk)
        # Each window whole first: a pair holding its places, or moving in parallel, is
        # proven by one bound (a formation's hold, the drones waiting while others write);
        # only the windows it leaves open are cut into grid intervals.
        whole = _whole_windows(fleet, t, pairs, pair[part], window[part], lengths[part], closest)
        count += whole.a.size
        lower, still = _settle(whole, closest, tolerance, lower)
        items = _window_intervals(
            fleet,
            t,
            pairs,
            pair=pair[part][still],
            window=window[part][still],
            lengths=lengths[part][still],
            closest=closest,
        )
        closest.record(items.pair, items.a, items.da)
        closest.record(items.pair, items.b, items.db)
        count += items.a.size
        lower, left = _settle(items, closest, tolerance, lower)
        kept.append(items.take(left))
    return _joined(kept), lower, count


def _whole_windows(  # noqa: PLR0917 - private: the slices of one chunk
    fleet: Fleet,
    t: FloatArray,
    pairs: tuple[IntArray, IntArray],
    pair: IntArray,
    window: IntArray,
    lengths: IntArray,
    closest: _Closest,
) -> _Intervals:
    """One interval per candidate window of ``pair``, bounded (ends and midpoint recorded)."""
    a, b = t[window * WINDOW], t[window * WINDOW + lengths]
    da, db = _end_distances(fleet, pairs, pair, (a, b))
    closest.record(pair, a, da)
    closest.record(pair, b, db)
    return _bounded(fleet, pairs, pair, (a, b), (da, db), closest)


def _window_intervals(
    fleet: Fleet,
    t: FloatArray,
    pairs: tuple[IntArray, IntArray],
    *,
    pair: IntArray,
    window: IntArray,
    lengths: IntArray,
    closest: _Closest,
) -> _Intervals:
    """The grid intervals of the windows ``window`` of the pairs ``pair``, with their bounds."""
    pair = np.repeat(pair, lengths)
    offsets = np.arange(lengths.sum()) - np.repeat(np.cumsum(lengths) - lengths, lengths)
    k = np.repeat(window * WINDOW, lengths) + offsets
    ends = (t[k], t[k + 1])
    return _bounded(fleet, pairs, pair, ends, _end_distances(fleet, pairs, pair, ends), closest)


def _end_distances(
    fleet: Fleet,
    pairs: tuple[IntArray, IntArray],
    pair: IntArray,
    ends: tuple[FloatArray, FloatArray],
) -> tuple[FloatArray, FloatArray]:
    """The distances of the pairs ``pair`` at the times ``ends`` (each (P,), s), m."""
    i, j = pairs[0][pair], pairs[1][pair]
    a, b = ends
    da = np.linalg.norm(fleet.position(i, a) - fleet.position(j, a), axis=1)
    db = np.linalg.norm(fleet.position(i, b) - fleet.position(j, b), axis=1)
    return da, db


def _bounded(  # noqa: PLR0917 - private: one interval's every part
    fleet: Fleet,
    pairs: tuple[IntArray, IntArray],
    pair: IntArray,
    ends: tuple[FloatArray, FloatArray],
    distances: tuple[FloatArray, FloatArray],
    closest: _Closest,
) -> _Intervals:
    """Intervals ``ends`` of ``pair`` with the distances there, bounded (midpoints recorded)."""
    a, b = ends
    i, j = pairs[0][pair], pairs[1][pair]
    mid = 0.5 * (a + b)
    offset = fleet.position(i, mid) - fleet.position(j, mid)
    closest.record(pair, mid, np.linalg.norm(offset, axis=1))
    one, two = fleet.local(i, a, b), fleet.local(j, a, b)
    w, taylor = _relative(one, two, 0.5 * (b - a), offset)
    return _Intervals(pair, a, b, *distances, w, one.jump + two.jump, taylor)


def _remainder(derivatives: FloatArray, r: FloatArray) -> FloatArray:
    """``sum_{q >= 2} |D_q| r^q / q!`` for derivatives (M, Q, 3) of orders 1 to Q (M,)."""
    norms = np.linalg.norm(derivatives[:, 1:], axis=2)
    q = np.arange(2, derivatives.shape[1] + 1)
    weights = r[:, None] ** q[None, :] / np.array([math.factorial(int(k)) for k in q])
    return np.asarray((norms * weights).sum(axis=1))


def _joined(parts: Sequence[_Intervals]) -> _Intervals:
    if not parts:
        empty = np.zeros(0)
        return _Intervals(np.zeros(0, dtype=np.intp), *([empty] * (len(_FIELDS) - 1)))
    return _Intervals(*(np.concatenate([getattr(p, f) for p in parts]) for f in _FIELDS))


def _relative(
    one: LocalMotion, two: LocalMotion, half_width: FloatArray, offset: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Two bounds where both drones are one polynomial on the interval (else the speeds').

    Returns ``w``, a bound of ``|v_i - v_j|`` (the Taylor bound of the difference), and
    a lower bound of the distance itself, ``-inf`` where both are not one polynomial.
    The difference ``D(m + tau) = D0 + D1 tau + R(tau)`` of two polynomials is exact
    with ``|R(tau)| <= sum_{q >= 2} |D_q| r^q / q!`` for ``|tau| <= r``, so the
    distance is at least the closest the segment ``D0 + D1 tau`` comes to 0, less
    that remainder: exact for drones in straight uniform motion, and second order in
    ``r`` otherwise, where the Lipschitz bound is first order. It is what proves two
    drones that step apart sideways from exactly the minimum distance (moving
    across their separation, their distance grows though they move fast).
    """
    w = one.speed + two.speed
    taylor = np.full(w.size, -np.inf)
    both = one.inside & two.inside
    if not one.derivatives.shape[1]:  # both stand still (constant pieces)
        taylor[both] = np.linalg.norm(offset[both], axis=1)
    elif both.any():
        diff = one.derivatives[both] - two.derivatives[both]
        r = half_width[both]
        w[both] = np.minimum(w[both], taylor_bound(diff, r))
        d0, d1 = offset[both], diff[:, 0]
        linear, _ = closest_on_segments(d0 - d1 * r[:, None], d0 + d1 * r[:, None])
        taylor[both] = linear - _remainder(diff, r)
    return w, taylor


def _settle(
    items: _Intervals, closest: _Closest, tolerance: float, lower: tuple[float, int, float]
) -> tuple[tuple[float, int, float], NDArray[np.bool_]]:
    """Close the intervals whose bound is high enough; the lowest closed bound so far and
    which intervals stay open.

    An interval stays open while its bound is below what is asked for (or more than
    ``tolerance`` below the closest distance seen), it is wider than
    :data:`MIN_WIDTH_S` and its pair has not already been found closer than asked for.
    """
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
    return lower, open_


def _refine(
    items: _Intervals,
    fleet: Fleet,
    pairs: tuple[IntArray, IntArray],
    *,
    closest: _Closest,
    tolerance: float,
    lower: tuple[float, int, float],
    count: int,
) -> tuple[tuple[float, int, float], int]:
    """Bisect until every interval is proven.

    Returns the guaranteed bound with the pair and time where it is lowest, and
    the number of intervals bounded.
    """
    while items.a.size:
        lower, left = _settle(items, closest, tolerance, lower)
        items = items.take(left)
        if 2 * items.a.size > MAX_INTERVALS:
            if tolerance == math.inf:
                raise SolverError(
                    f"separation: got more than {MAX_INTERVALS:,} intervals to bisect, expected "
                    "fewer (drones that keep exactly the minimum distance while moving)"
                )
            # Stop tightening the bound: only what decides pass or fail is bisected.
            tolerance = math.inf
            continue
        if not items.a.size:
            break
        items = _split(items, fleet, pairs, closest)
        count += items.a.size
    return lower, count


def _split(
    items: _Intervals, fleet: Fleet, pairs: tuple[IntArray, IntArray], closest: _Closest
) -> _Intervals:
    """Both halves of every interval, with the distance at the midpoints recorded."""
    mid = 0.5 * (items.a + items.b)
    i, j = pairs[0][items.pair], pairs[1][items.pair]
    dm = np.linalg.norm(fleet.position(i, mid) - fleet.position(j, mid), axis=1)
    closest.record(items.pair, mid, dm)
    halves = np.concatenate([items.pair, items.pair])
    ends = (np.concatenate([items.a, mid]), np.concatenate([mid, items.b]))
    distances = (np.concatenate([items.da, dm]), np.concatenate([dm, items.db]))
    return _bounded(fleet, pairs, halves, ends, distances, closest)


def _result(
    *,
    minimum: float,
    lower: tuple[float, int, float],
    count: int,
    closest: _Closest,
    first: IntArray,
    second: IntArray,
    total: int,
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
        pairs=total,
        pairs_examined=int(first.size),
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
