"""Straight rest-to-rest legs, each time-optimal under speed, acceleration and jerk limits.

Each leg is a move along its own direction ``d`` (a unit vector) from rest to
rest. Its time-optimal jerk-limited profile comes from Ruckig (Berscheid &
Kröger, RSS 2021), the reference implementation of such profiles, rather than
from a hand-written seven-phase S-curve. A profile is piecewise cubic in time
(constant jerk per phase), so a chain of legs is exactly a
:class:`~skyquill.trajectory.PiecewisePolynomial`: stop-and-go coverage,
transits, approaches.

Limits: ``vmax`` is the speed (a norm: along a straight leg the speed is the
scalar speed along it). Acceleration and jerk limits are either norms (the
scalar profile's own limits) or per-axis boxes, which along ``d`` become
``min_k amax_k / |d_k|``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from ruckig import InputParameter, Result, Ruckig, Trajectory

from skyquill.errors import InputError, SolverError
from skyquill.trajectory import PiecewisePolynomial
from skyquill.validation import FloatArray, as_array, as_float, per_axis

#: Legs shorter than this (relative to the coordinates' scale) are dropped as repeats.
REPEAT_TOLERANCE = 1e-9


@dataclass(frozen=True)
class LegLimits:
    """The limits one leg is timed under.

    Attributes
    ----------
    vmax
        Speed, m/s.
    amax, jmax
        Acceleration (m/s^2) and jerk (m/s^3): a scalar norm, or per-axis bounds (d,)
        when ``per_axis`` is set.
    per_axis
        Whether ``amax`` and ``jmax`` bound each axis (a box) rather than the norm.
    """

    vmax: float
    amax: float | FloatArray
    jmax: float | FloatArray
    per_axis: bool = False

    def along(self, direction: FloatArray) -> tuple[float, float, float]:
        """Scalar speed, acceleration and jerk limits along the unit vector ``direction``."""
        if not self.per_axis:
            return float(self.vmax), float(np.min(self.amax)), float(np.min(self.jmax))
        with np.errstate(divide="ignore"):
            a = float(np.min(np.asarray(self.amax) / np.abs(direction)))
            j = float(np.min(np.asarray(self.jmax) / np.abs(direction)))
        return float(self.vmax), a, j


def leg_pieces(
    start: FloatArray,
    end: FloatArray,
    limits: LegLimits,
    speeds: tuple[float, float] = (0.0, 0.0),
) -> tuple[FloatArray, FloatArray]:
    """The time-optimal straight move from ``start`` to ``end`` (d,) as cubic pieces.

    ``speeds`` are the speeds along the move at its start and end, m/s (rest to
    rest by default; a coverage lane enters and leaves at speed).

    Returns
    -------
    durations : numpy.ndarray, shape (P,)
        Phase durations (zero-length phases dropped), s.
    coeffs : numpy.ndarray, shape (P, 4, d)
        Power-basis coefficients of each phase in local time, lowest first.
    """
    length = float(np.linalg.norm(end - start))
    direction = (end - start) / length
    vmax, amax, jmax = limits.along(direction)
    inp = InputParameter(1)
    inp.current_position, inp.current_velocity = [0.0], [speeds[0]]
    inp.target_position, inp.target_velocity = [length], [speeds[1]]
    inp.max_velocity = [vmax]
    inp.max_acceleration = [amax]
    inp.max_jerk = [jmax]
    profile = Trajectory(1)
    result = Ruckig(1).calculate(inp, profile)
    if result != Result.Working:
        raise SolverError(f"Ruckig failed on a {length:.3g} m leg: {result}")
    phases = profile.profiles[0][0]
    keep = np.asarray(phases.t) > 1e-12  # sub-picosecond phases only add round-off
    scalar = np.column_stack(
        [
            np.asarray(phases.p[:-1]),
            np.asarray(phases.v[:-1]),
            np.asarray(phases.a[:-1]) / 2.0,
            np.asarray(phases.j) / 6.0,
        ]
    )[keep]
    coeffs = scalar[:, :, None] * direction[None, None, :]
    coeffs[:, 0, :] += start
    return np.asarray(phases.t)[keep], coeffs


@dataclass(frozen=True)
class StopAndGo:
    """Legs flown back to back.

    Attributes
    ----------
    trajectory
        The legs as one piecewise polynomial (cubic pieces), at rest at every waypoint.
    arrivals
        Time of arrival at each waypoint, shape (K,), s (0 for the first; a
        repeated waypoint arrives when the previous one did).
    """

    trajectory: PiecewisePolynomial
    arrivals: FloatArray


def stop_and_go(waypoints: FloatArray, limits: LegLimits | Sequence[LegLimits]) -> StopAndGo:
    """Rest at every waypoint, time-optimal straight legs in between.

    Parameters
    ----------
    waypoints
        ``(K, d)`` polyline, m, K >= 2; repeated points are skipped.
    limits
        One :class:`LegLimits` for every leg, or one per leg (K - 1, before
        repeats are skipped).
    """
    pts = as_array("waypoints", waypoints, ndim=2)
    if pts.shape[0] < 2:
        raise InputError(f"waypoints: got {pts.shape[0]} point(s), expected at least 2")
    per_leg = [limits] * (pts.shape[0] - 1) if isinstance(limits, LegLimits) else list(limits)
    if len(per_leg) != pts.shape[0] - 1:
        raise InputError(f"limits: got {len(per_leg)}, expected one per leg ({pts.shape[0] - 1})")
    for lim in per_leg:
        _check(lim, pts.shape[1])
    steps = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    moving = steps > REPEAT_TOLERANCE * max(1.0, float(np.abs(pts).max()))
    if not np.any(moving):
        raise InputError("waypoints: got coincident points, expected a path of positive length")
    durations, coeffs = [], []
    leg_time = np.zeros(pts.shape[0] - 1)
    for k in np.flatnonzero(moving):
        d, c = leg_pieces(pts[k], pts[k + 1], per_leg[k])
        durations.append(d)
        coeffs.append(c)
        leg_time[k] = d.sum()
    breaks = np.concatenate([[0.0], np.cumsum(np.concatenate(durations))])
    arrivals = np.concatenate([[0.0], np.cumsum(leg_time)])
    return StopAndGo(PiecewisePolynomial(breaks, np.concatenate(coeffs)), arrivals)


def _check(limits: LegLimits, dim: int) -> None:
    as_float("vmax", limits.vmax, positive=True)
    if limits.per_axis:
        per_axis("amax", limits.amax, dim)
        per_axis("jmax", limits.jmax, dim)
    else:
        as_float("amax", limits.amax, positive=True)
        as_float("jmax", limits.jmax, positive=True)
