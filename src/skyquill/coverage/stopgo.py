"""Stop-and-go timing of a polyline: rest at every waypoint, time-optimal in between.

The paper's zigzag baseline (``001_61beb0e01a19013a`` §4) flies straight legs and
stops at every corner. Each leg is a rest-to-rest move along its own direction
``d`` (a unit vector), so the per-axis limits become scalar limits along the
leg, ``a <= min_k amax_k / |d_k|`` and ``j <= min_k jmax_k / |d_k|`` (norm
limits are the leg's limits as they are); the speed limit is the norm
``vmax``. The time-optimal jerk-limited rest-to-rest profile of each leg comes
from Ruckig (Berscheid & Kröger, RSS 2021), the reference implementation of
such profiles, rather than from a hand-written seven-phase S-curve.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from ruckig import InputParameter, Result, Ruckig, Trajectory

from skyquill.coverage.speed import Setpoints
from skyquill.errors import InputError, SolverError
from skyquill.validation import as_array, as_float, per_axis

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class Leg:
    """One straight rest-to-rest leg: start (d,), unit direction (d,), length (m), profile."""

    start: FloatArray
    direction: FloatArray
    length: float
    profile: Trajectory

    @property
    def duration(self) -> float:
        """Time of the leg, s."""
        return float(self.profile.duration)


def _leg(
    start: FloatArray,
    end: FloatArray,
    limits: tuple[float, FloatArray, FloatArray],
    *,
    norm: bool,
) -> Leg:
    vmax, amax, jmax = limits
    length = float(np.linalg.norm(end - start))
    d = (end - start) / length
    if norm:
        a, j = float(amax[0]), float(jmax[0])
    else:
        with np.errstate(divide="ignore"):
            a = float(np.min(amax / np.abs(d)))
            j = float(np.min(jmax / np.abs(d)))
    inp = InputParameter(1)
    inp.current_position = [0.0]
    inp.target_position = [length]
    inp.max_velocity = [vmax]
    inp.max_acceleration = [a]
    inp.max_jerk = [j]
    profile = Trajectory(1)
    result = Ruckig(1).calculate(inp, profile)
    if result != Result.Working:
        raise SolverError(f"Ruckig failed on a {length:.3g} m leg: {result}")
    return Leg(start, d, length, profile)


def stop_and_go_legs(
    waypoints: FloatArray,
    vmax: float,
    amax: float | FloatArray,
    jmax: float | FloatArray,
    *,
    norm: bool = False,
) -> list[Leg]:
    """Time-optimal rest-to-rest legs between consecutive waypoints.

    Parameters
    ----------
    waypoints
        ``(K, d)`` polyline, m, K >= 2; repeated points are skipped.
    vmax
        Speed limit, m/s.
    amax, jmax
        Per-axis acceleration (m/s^2) and jerk (m/s^3) limits, scalar or (d,);
        with ``norm`` the Euclidean norm limits (scalars).
    norm
        Hold ``amax`` and ``jmax`` as norms (along a straight leg the norm is
        the leg's own acceleration/jerk) instead of per axis.

    Returns
    -------
    list of Leg
    """
    pts = as_array("waypoints", waypoints, ndim=2)
    if pts.shape[0] < 2:
        raise InputError(f"waypoints: got {pts.shape[0]} point(s), expected at least 2")
    d = pts.shape[1]
    v = as_float("vmax", vmax, positive=True)
    if norm:
        a = np.full(d, as_float("amax", amax, positive=True))
        j = np.full(d, as_float("jmax", jmax, positive=True))
    else:
        a = per_axis("amax", amax, d)
        j = per_axis("jmax", jmax, d)
    steps = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    keep = np.concatenate([[True], steps > 1e-9 * max(1.0, float(np.abs(pts).max()))])
    pts = pts[keep]
    if pts.shape[0] < 2:
        raise InputError("waypoints: got coincident points, expected a path of positive length")
    return [_leg(p, q, (v, a, j), norm=norm) for p, q in itertools.pairwise(pts)]


def _leg_samples(leg: Leg, tau: FloatArray) -> FloatArray:
    """Distance, speed, acceleration and jerk along the leg at local times ``tau``: (N, 4)."""
    prof = leg.profile.profiles[0][0]
    phase_end = np.cumsum(prof.t)
    jerk_1d = np.asarray(prof.j, dtype=np.float64)
    out = np.empty((tau.size, 4))
    for i, ti in enumerate(tau):
        pos, vel, acc = leg.profile.at_time(float(ti))
        phase = min(int(np.searchsorted(phase_end, ti, side="right")), len(jerk_1d) - 1)
        out[i] = pos[0], vel[0], acc[0], jerk_1d[phase]
    return out


def stop_and_go_setpoints(legs: list[Leg], period: float) -> Setpoints:
    """The legs flown one after the other, sampled every ``period`` seconds.

    Returns
    -------
    Setpoints
        Samples ``(N, d)``; ``u`` is the fraction of the path length travelled.
    """
    T = as_float("period", period, positive=True)
    starts = np.concatenate([[0.0], np.cumsum([leg.duration for leg in legs])])
    t = T * np.arange(int(np.floor(starts[-1] / T)) + 1, dtype=np.float64)
    if starts[-1] - t[-1] > 1e-12:
        t = np.append(t, starts[-1])
    which = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(legs) - 1)
    along = np.vstack(
        [
            _leg_samples(leg, np.clip(t[which == k] - starts[k], 0.0, leg.duration))
            for k, leg in enumerate(legs)
        ]
    )
    origin = np.array([leg.start for leg in legs])[which]
    direction = np.array([leg.direction for leg in legs])[which]
    travelled = np.concatenate([[0.0], np.cumsum([leg.length for leg in legs])])
    p = origin + along[:, :1] * direction
    v, a, j = (along[:, k : k + 1] * direction for k in (1, 2, 3))
    u = (travelled[which] + along[:, 0]) / travelled[-1]
    return Setpoints(t=t, u=np.clip(u, 0.0, 1.0), p=p, v=v, a=a, j=j, period=T)
