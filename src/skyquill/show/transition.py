"""Transitions between two formations: assigned, straight, delayed or layered, proven apart.

**Assignment.** Drone ``i`` goes to the goal that minimises the total squared
distance (:func:`assign`, scipy's ``linear_sum_assignment``).

**Paths.** Straight rest-to-rest moves, the drones of a wave on one shared
time-optimal profile within the limits (:mod:`skyquill.show.moves`).

**Where straight paths come too close**, **delayed starts**: drones go
in waves, one after another, ordered so that no path passes where another
drone waits (:mod:`skyquill.show.waves`). Delays keep every drone in the
formations' plane and cost only time. When no order works, or the layers
below are faster than many waves flown one after another, **depth layers**
(the formations stand on vertical planes facing -y, so "altitude" layers
would be the next row of drones; the layers are stacked along y instead):
the drones whose straight paths conflict are coloured apart, each colour
steps out of the plane to its own layer (layers the safety distance apart),
crosses there, and steps back in; each of the three legs is itself planned
in waves. When neither works (two drones swapping places along the layers' axis,
formations whose stepping out runs into another drone), the transition is refused with an
:class:`~skyquill.errors.InfeasibleError` naming the pair and the time of
their closest approach on straight synchronised paths.

**Proof.** Whatever the planner believes, the transition is then checked
with :func:`skyquill.show.separation.guaranteed_separation` (bounded between
samples, not sampled).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment
from scipy.spatial.distance import cdist

from skyquill.errors import InfeasibleError, InputError
from skyquill.optimize.legs import LegLimits
from skyquill.show.check import require_separation
from skyquill.show.load import ShowDrone
from skyquill.show.moves import STILL_M, Moves, flight, profile, scheduled
from skyquill.show.waves import Allowed, allowed, closest_on_segments, colours, order_waves
from skyquill.trajectory import PiecewisePolynomial
from skyquill.validation import FloatArray, as_array, as_float

#: Relative margin above the safety distance the planner keeps: a tenth of the
#: formations' (:data:`skyquill.show.formation.SPACING_MARGIN`), so drones
#: leaving a formation are not refused, and the proof still closes.
PLAN_MARGIN = 1e-7
#: Relative margin of the distance between depth layers over the safety distance.
LAYER_MARGIN = 1e-5
#: The direction depth layers are stacked along: the formations' normal.
LAYER_AXIS = np.array([0.0, 1.0, 0.0])
#: Time step at which a wave's profile is inverted for the time of an encounter, s.
INVERT_STEP_S = 1e-3

IntArray = NDArray[np.intp]


def assign(starts: FloatArray, goals: FloatArray) -> IntArray:
    """The goal of each start minimising the total squared distance.

    Parameters
    ----------
    starts
        (N, 3), m.
    goals
        (M, 3), m, M >= N (with more goals some are left free).

    Returns
    -------
    numpy.ndarray, shape (N,)
        Index into ``goals`` of each start's goal, all different.
    """
    a = as_array("starts", starts, ndim=2)
    b = as_array("goals", goals, ndim=2)
    if len(b) < len(a):
        raise InputError(f"goals: got {len(b)}, expected at least one per start ({len(a)})")
    rows, cols = linear_sum_assignment(cdist(a, b, "sqeuclidean"))
    out = np.empty(len(a), dtype=np.intp)
    out[rows] = cols
    return out


@dataclass(frozen=True)
class Transition:
    """Every drone's flight from its start to its goal.

    Attributes
    ----------
    starts, goals
        Each drone's start and goal (N, 3), m (a drone that stays has both equal).
    legs
        Flown one after another: one (in waves), or three with depth layers
        (out to the layers, across, back in).
    layers
        Each drone's depth layer (N,); 0 for the formations' own plane.
    closest_m
        Guaranteed smallest distance between two drones over the transition,
        m (:func:`~skyquill.show.separation.guaranteed_separation`).
    """

    starts: FloatArray
    goals: FloatArray
    legs: tuple[Moves, ...]
    layers: IntArray
    closest_m: float

    @property
    def duration(self) -> float:
        """Length of the transition, s (0 when nobody moves)."""
        return sum(leg.duration for leg in self.legs)

    @property
    def waves(self) -> IntArray:
        """Each drone's wave (-1: stays) on the crossing leg."""
        return self.legs[len(self.legs) // 2].waves

    def trajectory(self, i: int) -> PiecewisePolynomial:
        """Drone ``i``'s flight over the whole transition, cubic pieces."""
        flights = [leg.trajectory(i) for leg in self.legs if leg.duration > 0.0]
        if not flights:
            return flight(self.starts[i], self.goals[i], None, STILL_M)
        durations = np.concatenate([np.diff(f.breaks) for f in flights])
        return PiecewisePolynomial(
            np.concatenate([[0.0], np.cumsum(durations)]),
            np.concatenate([f.coeffs for f in flights]),
        )


def plan_transition(
    starts: FloatArray,
    goals: FloatArray,
    limits: LegLimits,
    safety_m: float,
    names: Sequence[str] | None = None,
) -> Transition:
    """Straight moves from ``starts[i]`` to ``goals[i]``, delayed or layered, ``safety_m`` apart.

    Parameters
    ----------
    starts, goals
        (N, 3), m, each set at least ``safety_m`` apart; ``goals[i]`` is drone
        ``i``'s (use :func:`assign` first). A drone whose goal is its start stays.
    limits
        Speed, acceleration and jerk norms (``per_axis`` unset).
    safety_m
        The distance every two drones keep at all times, m.
    names
        The drones' names in messages (default ``drone <i>``).

    Raises
    ------
    InfeasibleError
        Neither delays nor layers keep the drones apart (naming the pair and
        the time of their closest approach), or the proof finds them closer.
    """
    a = as_array("starts", starts, ndim=2)
    b = as_array("goals", goals, shape=a.shape)
    d = as_float("safety_distance", safety_m, positive=True)
    if limits.per_axis:
        raise InputError("limits: got per-axis limits, expected norms (the moves are scaled)")
    label = list(names) if names is not None else [f"drone {k}" for k in range(len(a))]
    moving = np.linalg.norm(b - a, axis=1) > STILL_M
    flat = np.zeros(len(a), dtype=np.intp)
    if not moving.any():
        return Transition(a, b, (), flat, np.inf)
    ok = allowed(a, b, moving, d * (1.0 + PLAN_MARGIN))
    if ok.held.any():  # no delay moves a drone that stays out of the way: layers may
        i, j = (int(k) for k in np.argwhere(ok.held)[0])
        waves, pair, why = None, (i, j), f"{label[i]}'s path passes {label[j]}, which stays"
    else:
        waves, pair = order_waves(ok, moving)
        why = "neither delayed starts nor depth layers keep them apart"
    delayed = None
    if waves is not None:
        delayed = Transition(a, b, (scheduled(a, b, waves, limits),), flat, np.inf)
        if waves.max() == 0:
            return prove(delayed, d, label)
    layered = _layered(a, b, ok=ok, moving=moving, d=d, limits=limits)
    # Many waves flown one after another can take longer than stepping out and back.
    options = [t for t in (delayed, layered) if t is not None]
    if not options:
        raise _unresolved(a, b, pair, why, limits, label)
    return prove(min(options, key=lambda t: t.duration), d, label)


def _direct(a: FloatArray, b: FloatArray, d: float, limits: LegLimits) -> Moves | None:
    """Straight moves in waves, or ``None`` when no order keeps them apart."""
    moving = np.linalg.norm(b - a, axis=1) > STILL_M
    if not moving.any():
        return Moves(a, b, np.full(len(a), -1, dtype=np.intp), ())
    ok = allowed(a, b, moving, d * (1.0 + PLAN_MARGIN))
    waves = None if ok.held.any() else order_waves(ok, moving)[0]
    return None if waves is None else scheduled(a, b, waves, limits)


def _layered(
    a: FloatArray,
    b: FloatArray,
    *,
    ok: Allowed,
    moving: NDArray[np.bool_],
    d: float,
    limits: LegLimits,
) -> Transition | None:
    """Out to depth layers (conflicting drones coloured apart), across, back in."""
    conflict = ~ok.together & (moving[:, None] | moving[None, :])
    layer = colours(conflict | conflict.T)
    # 0, -1, +1, -2, +2, ...: towards the audience first, then behind, alternately
    depth = np.where(layer % 2 == 1, -1, 1) * ((layer + 1) // 2)
    shift = (depth * d * (1.0 + LAYER_MARGIN))[:, None] * LAYER_AXIS
    legs = []
    for start, goal in ((a, a + shift), (a + shift, b + shift), (b + shift, b)):
        leg = _direct(start, goal, d, limits)
        if leg is None:
            return None
        legs.append(leg)
    return Transition(a, b, tuple(legs), depth.astype(np.intp), np.inf)


def prove(planned: Transition, d: float, label: Sequence[str]) -> Transition:
    """``planned`` with its guaranteed closest approach; refused if below ``d``."""
    drones = [ShowDrone(planned.trajectory(k), label[k]) for k in range(len(planned.starts))]
    separation = require_separation(drones, d, "transition")
    return Transition(
        planned.starts, planned.goals, planned.legs, planned.layers, separation.lower_bound_m
    )


def _unresolved(  # noqa: PLR0917 - private: the pair, why, and what places them
    a: FloatArray,
    b: FloatArray,
    pair: tuple[int, int],
    why: str,
    limits: LegLimits,
    label: Sequence[str],
) -> InfeasibleError:
    """The error for a pair nothing resolves: who, and when they are closest."""
    i, j = pair
    distance, when = _sync_encounter(a, b, i, j, limits)
    return InfeasibleError(
        f"transition: {label[i]} and {label[j]} come within {distance:.3f} m at "
        f"t = {when:.2f} s of the transition (straight paths, moving together), expected at "
        f"least the safety distance; {why}",
        ("separation",),
    )


def _sync_encounter(
    a: FloatArray, b: FloatArray, i: int, j: int, limits: LegLimits
) -> tuple[float, float]:
    """Closest distance of ``i`` and ``j`` when every drone moves at once, and when, s."""
    distance, s = closest_on_segments(a[i] - a[j], b[i] - b[j])
    wave = profile(float(np.linalg.norm(b - a, axis=1).max()), limits, 0.0)
    t = np.arange(0.0, wave.end_s + INVERT_STEP_S, INVERT_STEP_S)
    flown = flight(np.zeros(3), np.ones(3), wave, wave.end_s).evaluate(np.clip(t, 0.0, wave.end_s))[
        :, 0
    ]
    return float(distance), float(np.interp(float(s), flown, t))
