"""Straight rest-to-rest moves of many drones on shared time-optimal profiles.

The drones of one *wave* share one Ruckig profile ``s(t)`` from 0 to 1, that
of the wave's longest move (:func:`skyquill.optimize.legs.leg_pieces`): drone
``i`` is at ``a_i + s(t) (b_i - a_i)``. A shorter move is the longest one
scaled down, so every drone keeps the speed, acceleration and jerk limits
(norms), and two drones of one wave are two points moving along straight
lines with one parameter (:mod:`skyquill.show.waves`). Waves are flown one
after another. Every flight is a cubic
:class:`~skyquill.trajectory.PiecewisePolynomial`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from skyquill.optimize.legs import LegLimits, leg_pieces
from skyquill.trajectory import PiecewisePolynomial
from skyquill.validation import FloatArray, as_array

#: Moves shorter than this are "stays", m.
STILL_M = 1e-9

IntArray = NDArray[np.intp]


@dataclass(frozen=True)
class Wave:
    """Drones that move together on one profile.

    Attributes
    ----------
    start_s
        When they leave, s from the start of the moves.
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
class Moves:
    """Every drone's straight move from its start to its goal, in waves.

    Attributes
    ----------
    starts, goals
        Each drone's start and goal (N, 3), m (a drone that stays has both equal).
    waves
        Each drone's wave (N,); -1 for a drone that stays.
    schedule
        The waves, flown one after another.
    """

    starts: FloatArray
    goals: FloatArray
    waves: IntArray
    schedule: tuple[Wave, ...]

    @property
    def duration(self) -> float:
        """Length of the moves, s (0 when nobody moves)."""
        return self.schedule[-1].end_s if self.schedule else 0.0

    def trajectory(self, i: int) -> PiecewisePolynomial:
        """Drone ``i``'s flight over all the waves (waiting, moving, holding), cubic."""
        wave = None if self.waves[i] < 0 else self.schedule[int(self.waves[i])]
        return flight(self.starts[i], self.goals[i], wave, self.duration)


def scheduled(starts: FloatArray, goals: FloatArray, waves: IntArray, limits: LegLimits) -> Moves:
    """The moves of ``starts`` to ``goals`` with each drone in its wave (-1: stays)."""
    lengths = np.linalg.norm(goals - starts, axis=1)
    schedule: list[Wave] = []
    for w in range(int(waves.max()) + 1):
        start = schedule[-1].end_s if schedule else 0.0
        schedule.append(profile(float(lengths[waves == w].max()), limits, start))
    return Moves(starts, goals, waves, tuple(schedule))


def hold(p: FloatArray, duration: float) -> tuple[FloatArray, FloatArray]:
    """Durations (1,) and coefficients (1, 4, 3) of staying at ``p`` for ``duration`` s."""
    coeffs = np.zeros((1, 4, 3))
    coeffs[0, 0] = p
    return np.array([duration]), coeffs


def flight(a: FloatArray, b: FloatArray, wave: Wave | None, total: float) -> PiecewisePolynomial:
    """From ``a`` to ``b`` in ``wave`` (``None``: stay at ``a``), held to ``total`` s."""
    parts = []
    if wave is None:
        parts.append(hold(a, max(total, STILL_M)))
    else:
        if wave.start_s > 0.0:
            parts.append(hold(a, wave.start_s))
        parts.append((wave.durations, moved(wave.profile, a, b)))
        if total - wave.end_s > STILL_M:
            parts.append(hold(b, total - wave.end_s))
    durations = np.concatenate([d for d, _ in parts])
    return PiecewisePolynomial(
        np.concatenate([[0.0], np.cumsum(durations)]), np.concatenate([c for _, c in parts])
    )


def moved(profile: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """Position coefficients (P, 4, 3) of ``a + s (b - a)`` for ``s``'s coefficients (P, 4)."""
    coeffs = profile[:, :, None] * (b - a)[None, None, :]
    coeffs[:, 0, :] += a
    return np.asarray(coeffs)


def profile(length: float, limits: LegLimits, start_s: float) -> Wave:
    """The time-optimal rest-to-rest profile over ``length``, normalised to ``s`` in [0, 1]."""
    durations, coeffs = leg_pieces(np.zeros(1), np.array([length]), limits)
    return Wave(start_s, durations, coeffs[:, :, 0] / length)


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
    wave = profile(float(np.linalg.norm(b - a, axis=1).max()), limits, 0.0)
    total = float(delays.max()) + wave.end_s
    flights = [
        flight(a[k], b[k], Wave(float(delays[k]), wave.durations, wave.profile), total)
        for k in range(len(a))
    ]
    return flights, total
