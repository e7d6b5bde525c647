"""Transitions between two formations: assigned, straight, in waves, proven apart.

**Assignment.** Drone ``i`` goes to the goal that minimises the total squared
distance (:func:`assign`, scipy's ``linear_sum_assignment``).

**Paths.** Every drone flies a straight rest-to-rest move. The drones of one
*wave* share one time-optimal Ruckig profile ``s(t)`` (0 to 1), that of the
wave's longest move (:func:`skyquill.optimize.legs.leg_pieces`): drone ``i``
is at ``a_i + s(t) (b_i - a_i)``. A shorter move is the longest one scaled
down, so every drone keeps the speed, acceleration and jerk limits (norms),
and the distance between two drones of a wave is that of two points moving
along straight lines with one parameter: its minimum has a closed form. With
the minimum-squared-distance assignment, synchronised straight moves keep
drones apart by at least ``1/sqrt(2)`` of their formations' spacing (Turpin,
Michael & Kumar, "CAPT", IJRR 2014), so most transitions need one wave.

**Delayed starts where paths come too close.** A pair is resolved by order:
if drone ``i``'s path passes within the safety distance of where ``j``
starts, ``j`` leaves first (an earlier wave); if it passes where ``j`` ends,
``j`` arrives later; two drones that come too close moving together go in
different waves. Waves are flown one after another, so a drone only ever
meets drones that are still (at their start or their goal) or moving with it.
Delays were chosen over altitude layers because the formations stand on
vertical planes: a layer above or below one row is the next row of drones.
When no order works (one path passes both where another drone starts and
where it ends, or a drone that does not move), the transition is refused
with an :class:`~skyquill.errors.InfeasibleError` naming the pair and the
time of their closest approach on straight synchronised paths.

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
from skyquill.optimize.legs import LegLimits, leg_pieces
from skyquill.show.motion import motion_of
from skyquill.show.separation import guaranteed_separation
from skyquill.trajectory import PiecewisePolynomial
from skyquill.validation import FloatArray, as_array, as_float

#: Moves shorter than this are "stays", m.
STILL_M = 1e-9
#: Relative margin above the safety distance the planner keeps: a tenth of the
#: formations' (:data:`skyquill.show.formation.SPACING_MARGIN`), so drones
#: leaving a formation are not refused, and the proof still closes.
PLAN_MARGIN = 1e-7
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
class Wave:
    """Drones that move together on one profile.

    Attributes
    ----------
    start_s
        When they leave, s from the transition's start.
    durations
        Phase durations of the profile, (P,), s.
    profile
        ``s(tau)`` per phase in local time: power-basis coefficients (P, 4), lowest first,
        from 0 at the wave's start to 1 at its end.
    """

    start_s: float
    durations: FloatArray
    profile: FloatArray

    @property
    def end_s(self) -> float:
        """When the last of them arrives, s."""
        return self.start_s + float(self.durations.sum())


@dataclass(frozen=True)
class Transition:
    """Every drone's straight move from its start to its goal, in waves.

    Attributes
    ----------
    starts, goals
        Each drone's start and goal (N, 3), m (a drone that stays has both equal).
    waves
        Each drone's wave (N,); -1 for a drone that stays.
    schedule
        The waves, flown one after another.
    closest_m
        Guaranteed smallest distance between two drones over the transition,
        m (:func:`~skyquill.show.separation.guaranteed_separation`).
    """

    starts: FloatArray
    goals: FloatArray
    waves: IntArray
    schedule: tuple[Wave, ...]
    closest_m: float

    @property
    def duration(self) -> float:
        """Length of the transition, s (0 when nobody moves)."""
        return self.schedule[-1].end_s if self.schedule else 0.0

    def trajectory(self, i: int) -> PiecewisePolynomial:
        """Drone ``i``'s flight over the whole transition (waiting, moving, holding), cubic."""
        return _flight(self.starts[i], self.goals[i], self._wave(i), self.duration)

    def _wave(self, i: int) -> Wave | None:
        return None if self.waves[i] < 0 else self.schedule[int(self.waves[i])]


def _hold(p: FloatArray, duration: float) -> tuple[FloatArray, FloatArray]:
    coeffs = np.zeros((1, 4, 3))
    coeffs[0, 0] = p
    return np.array([duration]), coeffs


def _flight(a: FloatArray, b: FloatArray, wave: Wave | None, total: float) -> PiecewisePolynomial:
    parts = []
    if wave is None:
        parts.append(_hold(a, max(total, STILL_M)))
    else:
        if wave.start_s > 0.0:
            parts.append(_hold(a, wave.start_s))
        parts.append((wave.durations, _moved(wave.profile, a, b)))
        if total - wave.end_s > STILL_M:
            parts.append(_hold(b, total - wave.end_s))
    durations = np.concatenate([d for d, _ in parts])
    return PiecewisePolynomial(
        np.concatenate([[0.0], np.cumsum(durations)]), np.concatenate([c for _, c in parts])
    )


def _moved(profile: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """Position coefficients (P, 4, 3) of ``a + s (b - a)`` for ``s``'s coefficients (P, 4)."""
    coeffs = profile[:, :, None] * (b - a)[None, None, :]
    coeffs[:, 0, :] += a
    return np.asarray(coeffs)


def _profile(length: float, limits: LegLimits, start_s: float) -> Wave:
    """The time-optimal rest-to-rest profile over ``length``, normalised to ``s`` in [0, 1]."""
    durations, coeffs = leg_pieces(np.zeros(1), np.array([length]), limits)
    return Wave(start_s, durations, coeffs[:, :, 0] / length)


def _closest(d0: FloatArray, d1: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Smallest ``|d0 + s (d1 - d0)|`` over ``s`` in [0, 1] and where, for (..., 3) arrays."""
    e = d1 - d0
    ee = np.einsum("...k,...k->...", e, e)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(ee > 0.0, -np.einsum("...k,...k->...", d0, e) / ee, 0.0)
    s = np.clip(s, 0.0, 1.0)
    return np.linalg.norm(d0 + s[..., None] * e, axis=-1), s


@dataclass(frozen=True)
class _Allowed:
    """Which order each pair may fly in, each (N, N) boolean.

    ``first[i, j]``: ``i``'s wave may come before ``j``'s (``i``'s path keeps
    clear of where ``j`` waits, ``j``'s path of where ``i`` ended);
    ``together[i, j]``: the same wave (their synchronised straight paths keep
    apart); ``held[i, j]``: ``i`` moves and its path comes too close to ``j``,
    which does not move.
    """

    first: NDArray[np.bool_]
    together: NDArray[np.bool_]
    held: NDArray[np.bool_]


def _allowed(a: FloatArray, b: FloatArray, moving: NDArray[np.bool_], d: float) -> _Allowed:
    # [i, j]: the smallest distance from i's path to where j starts / ends
    near_start = _closest(a[:, None] - a[None], b[:, None] - a[None])[0] < d
    near_goal = _closest(a[:, None] - b[None], b[:, None] - b[None])[0] < d
    sync = _closest(a[:, None] - a[None], b[:, None] - b[None])[0]
    other = ~np.eye(len(a), dtype=bool)
    held = moving[:, None] & ~moving[None, :] & (near_start | near_goal)
    return _Allowed(~near_start & ~near_goal.T, sync >= d, held & other)


def _longest_paths(before: IntArray, after: IntArray, n: int) -> IntArray | None:
    """Waves from the orders ``before[k]`` ahead of ``after[k]``; ``None`` for a cycle."""
    wave = np.zeros(n, dtype=np.intp)
    for _ in range(n + 1):
        old = wave.copy()
        np.maximum.at(wave, after, wave[before] + 1)
        if np.array_equal(wave, old):
            return wave
    return None


def _waves(ok: _Allowed, moving: NDArray[np.bool_]) -> tuple[IntArray | None, tuple[int, int]]:
    """Each drone's wave (-1: stays), or ``None`` and a pair no order satisfies.

    All movers start in one wave; each pair whose relation is not allowed is
    given an allowed order (the lower index first when both are), and the
    waves are the longest paths of the orders, until every pair is satisfied.
    """
    n = moving.size
    i, j = np.nonzero(np.triu(moving[:, None] & moving[None, :], 1))
    before = np.zeros(0, dtype=np.intp)
    after = np.zeros(0, dtype=np.intp)
    wave: IntArray | None = np.zeros(n, dtype=np.intp)
    for _ in range(n + 1):
        assert wave is not None
        wi, wj = wave[i], wave[j]
        fine = np.where(
            wi == wj, ok.together[i, j], np.where(wi < wj, ok.first[i, j], ok.first[j, i])
        )
        if fine.all():
            return np.where(moving, wave, -1), (-1, -1)
        bi, bj = i[~fine], j[~fine]
        forward = ok.first[bi, bj]
        backward = ok.first[bj, bi]
        if not (forward | backward).all():
            k = int(np.flatnonzero(~(forward | backward))[0])
            return None, (int(bi[k]), int(bj[k]))
        before = np.concatenate([before, np.where(forward, bi, bj)])
        after = np.concatenate([after, np.where(forward, bj, bi)])
        wave = _longest_paths(before, after, n)
        if wave is None:
            return None, (int(bi[0]), int(bj[0]))
    return None, (int(i[0]), int(j[0]))  # pragma: no cover - orders are added at most once


def plan_transition(
    starts: FloatArray,
    goals: FloatArray,
    limits: LegLimits,
    safety_m: float,
    names: Sequence[str] | None = None,
) -> Transition:
    """Straight moves from ``starts[i]`` to ``goals[i]``, in waves, at least ``safety_m`` apart.

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
        No order of delayed starts keeps the drones apart (naming the pair and
        the time of their closest approach), or the proof finds them closer.
    """
    a = as_array("starts", starts, ndim=2)
    b = as_array("goals", goals, shape=a.shape)
    d = as_float("safety_distance", safety_m, positive=True)
    if limits.per_axis:
        raise InputError("limits: got per-axis limits, expected norms (the moves are scaled)")
    label = list(names) if names is not None else [f"drone {k}" for k in range(len(a))]
    moving = np.linalg.norm(b - a, axis=1) > STILL_M
    if not moving.any():
        return Transition(a, b, np.full(len(a), -1, dtype=np.intp), (), np.inf)
    ok = _allowed(a, b, moving, d * (1.0 + PLAN_MARGIN))
    if ok.held.any():
        i, j = (int(k) for k in np.argwhere(ok.held)[0])
        raise _unresolved(a, b, (i, j), f"{label[j]} does not move", limits, label)
    waves, pair = _waves(ok, moving)
    if waves is None:
        why = "no order of delayed starts keeps them apart"
        raise _unresolved(a, b, pair, why, limits, label)
    lengths = np.linalg.norm(b - a, axis=1)
    schedule: list[Wave] = []
    for w in range(int(waves.max()) + 1):
        start = schedule[-1].end_s if schedule else 0.0
        schedule.append(_profile(float(lengths[waves == w].max()), limits, start))
    planned = Transition(a, b, waves, tuple(schedule), np.inf)
    return _proven(planned, d, label)


def _proven(planned: Transition, d: float, label: Sequence[str]) -> Transition:
    """``planned`` with its guaranteed closest approach; refused if below ``d``."""
    horizon = planned.duration
    motions = [
        motion_of(label[k], planned.trajectory(k), horizon) for k in range(len(planned.starts))
    ]
    separation = guaranteed_separation(motions, d)
    if not separation.passed:
        e = separation.encounters[0]
        raise InfeasibleError(
            f"transition: {label[e.drones[0]]} and {label[e.drones[1]]} come within "
            f"{e.closest_m:.3f} m at t = {e.closest_time_s:.2f} s of the transition, "
            f"expected at least {d:g} m",
            ("separation",),
        )
    return Transition(
        planned.starts, planned.goals, planned.waves, planned.schedule, separation.lower_bound_m
    )


def _unresolved(  # noqa: PLR0917 - private: the pair, why, and what places them
    a: FloatArray,
    b: FloatArray,
    pair: tuple[int, int],
    why: str,
    limits: LegLimits,
    label: Sequence[str],
) -> InfeasibleError:
    """The error for a pair no order resolves: who, and when they are closest."""
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
    distance, s = _closest(a[i] - a[j], b[i] - b[j])
    wave = _profile(float(np.linalg.norm(b - a, axis=1).max()), limits, 0.0)
    t = np.arange(0.0, wave.end_s + INVERT_STEP_S, INVERT_STEP_S)
    flown = _flight(np.zeros(3), np.ones(3), wave, wave.end_s).evaluate(
        np.clip(t, 0.0, wave.end_s)
    )[:, 0]
    return float(distance), float(np.interp(float(s), flown, t))


def staggered(
    starts: FloatArray, goals: FloatArray, delays_s: FloatArray, limits: LegLimits
) -> tuple[list[PiecewisePolynomial], float]:
    """Straight moves on one profile (the longest move's), drone ``i`` leaving at ``delays_s[i]``.

    For take-off and landing: vertical moves above pads at least the safety
    distance apart keep their horizontal distances, whenever each one leaves.

    Returns
    -------
    flights
        Each drone's flight over the whole stagger (waiting, moving, holding).
    duration
        When the last one arrives, s.
    """
    a = as_array("starts", starts, ndim=2)
    b = as_array("goals", goals, shape=a.shape)
    delays = as_array("delays_s", delays_s, shape=(len(a),))
    wave = _profile(float(np.linalg.norm(b - a, axis=1).max()), limits, 0.0)
    total = float(delays.max()) + wave.end_s
    flights = [
        _flight(a[k], b[k], Wave(float(delays[k]), wave.durations, wave.profile), total)
        for k in range(len(a))
    ]
    return flights, total
