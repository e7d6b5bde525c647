"""Transitions in one synchronised wave: straight, or through depth layers; and their lower bound.

**One wave.** Every drone flies its straight move on the profile of the longest
one (:mod:`skyquill.show.moves`), so the transition lasts exactly as long as the
longest move at the limits. Two drones of one wave are two points moving along
straight lines with one parameter: their closest approach has a closed form
(:func:`skyquill.show.waves.closest_on_segments`), and only pairs whose paths'
boxes come within the safety distance are looked at (:mod:`skyquill.show.pairs`).

**Through layers.** With the minimum-squared-distance assignment, one wave keeps
the drones ``1/sqrt(2)`` of the formations' spacing apart (CAPT, Turpin, Michael &
Kumar, IJRR 2014). Where a formation is tighter than ``sqrt(2)`` times the safety
distance, its drones first step out of its plane into depth layers that are as
loose (:func:`skyquill.show.layers.step_out`), the wave crosses between the loose
sets, and the drones step back in: three legs, the outer two a few metres along
one normal (safe whatever their timing), the middle one proven by CAPT's bound
and checked pair by pair. A transition costs the longest move plus two short steps.

**Lower bound.** No transition between two sets can be faster than the
rest-to-rest move over the *bottleneck* distance (the smallest, over every
assignment, of the longest distance a drone must fly), at the limits: any
trajectory's projection on the line from its start to its goal is itself a
rest-to-rest motion within the scalar limits. :func:`bottleneck_distance` finds
it exactly (bisection over the distances, a bipartite matching at each).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import maximum_bipartite_matching
from scipy.spatial import cKDTree
from scipy.spatial.distance import cdist

from skyquill.optimize.legs import LegLimits
from skyquill.show.layers import Layers, step_out
from skyquill.show.moves import STILL_M, Moves, profile, scheduled
from skyquill.show.pairs import close_boxes
from skyquill.show.transition import PLAN_MARGIN, Transition, assign
from skyquill.show.waves import closest_on_segments
from skyquill.validation import FloatArray

#: Spread the layered formations keep, in units of the safety distance (CAPT's bound).
CAPT_SPREAD = math.sqrt(2.0)

IntArray = NDArray[np.intp]


def sync_conflicts(a: FloatArray, b: FloatArray, d: float) -> tuple[IntArray, IntArray]:
    """Pairs ``i < j`` whose synchronised straight moves ``a -> b`` (N, 3) come within ``d``."""
    i, j = close_boxes(np.minimum(a, b), np.maximum(a, b), d)
    if not i.size:
        return i, j
    distance, _ = closest_on_segments(a[i] - a[j], b[i] - b[j])
    close = distance < d
    return i[close], j[close]


def one_wave(a: FloatArray, b: FloatArray, limits: LegLimits, d: float) -> Moves | None:
    """Every drone from ``a`` to ``b`` in one wave, or ``None`` where two come within ``d``."""
    moving = np.linalg.norm(b - a, axis=1) > STILL_M
    waves = np.where(moving, 0, -1).astype(np.intp)
    if not moving.any():
        return Moves(a, b, waves, ())
    if sync_conflicts(a, b, d * (1.0 + PLAN_MARGIN))[0].size:
        return None
    return scheduled(a, b, waves, limits)


def straight(a: FloatArray, b: FloatArray, limits: LegLimits, d: float) -> Transition | None:
    """The one-wave transition from ``a`` to ``b`` (unproven), or ``None``."""
    moves = one_wave(a, b, limits, d)
    if moves is None:
        return None
    flat = np.zeros(len(a), dtype=np.intp)
    return Transition(a, b, (moves,) if moves.schedule else (), flat, math.inf)


def straight_to(
    a: FloatArray, targets: FloatArray, limits: LegLimits, d: float, matching: Matching
) -> tuple[Transition, IntArray] | None:
    """The fastest one-wave transition to ``targets`` found (unproven), and each drone's target.

    ``matching``: :func:`matchings` of ``a`` and ``targets``.
    """
    for chosen in matching.candidates:
        wave = straight(a, targets[chosen], limits, d)
        if wave is not None:
            return wave, chosen
    return None


@dataclass(frozen=True)
class Matching:
    """Assignments of starts to targets for one wave, the fastest first.

    Attributes
    ----------
    candidates
        Each an index into the targets per start (N,): the assignment that minimises
        the squared distances among those whose longest move is the bottleneck
        distance (the wave is then as fast as any transition can be), and the plain
        minimum-squared-distance one (CAPT's: it keeps loose formations apart); one
        when they are the same.
    bottleneck_m
        The bottleneck distance (:func:`bottleneck_distance`), m.
    """

    candidates: tuple[IntArray, ...]
    bottleneck_m: float


def matchings(a: FloatArray, targets: FloatArray) -> Matching:
    """The assignments of ``a`` (N, 3) to ``targets`` (M, 3) a wave is tried with."""
    plain = assign(a, targets)
    squared = cdist(a, targets, "sqeuclidean")
    bottleneck = bottleneck_distance(a, targets, plain=plain)
    longer = squared > bottleneck**2 * (1.0 + 1e-12)
    if not longer[np.arange(len(a)), plain].any():
        return Matching((plain,), bottleneck)
    # Moves longer than the bottleneck priced out: the cheapest among the fastest.
    rows, cols = linear_sum_assignment(np.where(longer, squared.sum() + 1.0, squared))
    first = np.empty(len(a), dtype=np.intp)
    first[rows] = cols
    return Matching((first, plain), bottleneck)


def through_layers(
    a: FloatArray, targets: FloatArray, limits: LegLimits, d: float
) -> tuple[Transition, IntArray] | None:
    """Out of ``a``'s plane, across in one wave, into the targets' plane (unproven).

    Returns the transition and each drone's target (an index into ``targets``), or
    ``None`` when a formation too tight for one wave does not lie on a plane, or the
    wave between the layers is not clear of conflicts.
    """
    spread = CAPT_SPREAD * d * (1.0 + PLAN_MARGIN)
    out, into = step_out(a, spread), step_out(targets, spread)
    if out is None or into is None:
        return None
    across = None
    for chosen in matchings(out.points, into.points).candidates:
        across = one_wave(out.points, into.points[chosen], limits, d)
        if across is not None:
            break
    if across is None:
        return None
    goals = targets[chosen]
    back = _reordered(into, chosen)
    legs = [_step(a, out, limits), across, _step(goals, back, limits, inward=True)]
    kept = tuple(leg for leg in legs if leg.schedule)
    depth = np.round(2.0 * into.depth[chosen]).astype(np.intp)  # in half steps
    return Transition(a, goals, kept, depth, math.inf), chosen


def _reordered(layers: Layers, order: IntArray) -> Layers:
    return Layers(layers.points[order], layers.depth[order], layers.normal, layers.step_m)


def _step(plane: FloatArray, layers: Layers, limits: LegLimits, *, inward: bool = False) -> Moves:
    """Each drone between its place on the plane and its layer, all in one wave."""
    start, goal = (layers.points, plane) if inward else (plane, layers.points)
    moving = layers.depth != 0
    waves = np.where(moving, 0, -1).astype(np.intp)
    if not moving.any():
        return Moves(start, goal, waves, ())
    return scheduled(start, goal, waves, limits)


def bottleneck_distance(
    starts: FloatArray, targets: FloatArray, *, plain: IntArray | None = None
) -> float:
    """The smallest, over assignments of starts to distinct targets, of the longest distance, m.

    Parameters
    ----------
    starts
        (N, 3), m.
    targets
        (M, 3), M >= N, m.
    plain
        The minimum-squared-distance assignment, if the caller has it (an upper end).
    """
    n = len(starts)
    if n == 0:
        return 0.0
    # Between every start's nearest target (no assignment does better) and the longest
    # move of the minimum-squared-distance assignment (one that exists).
    nearest = np.asarray(cKDTree(targets).query(starts)[0])
    low = float(nearest.max())
    distance = cdist(starts, targets)
    chosen = assign(starts, targets) if plain is None else plain
    high = float(distance[np.arange(n), chosen].max())
    values = np.unique(distance[(distance >= low) & (distance <= high)])
    lo, hi = 0, values.size - 1
    while lo < hi:
        mid = (lo + hi) // 2
        if _matches_all(distance <= values[mid]):
            hi = mid
        else:
            lo = mid + 1
    return float(values[lo]) if values.size else high


def _matches_all(allowed: NDArray[np.bool_]) -> bool:
    """Whether every row of ``allowed`` (N, M) gets a column of its own."""
    matching = maximum_bipartite_matching(csr_matrix(allowed), perm_type="column")
    return bool((matching >= 0).all())


def lower_bound_s(length_m: float, limits: LegLimits) -> float:
    """The shortest any transition whose bottleneck distance is ``length_m`` can last, s."""
    return profile(length_m, limits, 0.0).end_s if length_m > STILL_M else 0.0
