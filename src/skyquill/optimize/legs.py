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

import threading
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import chain

import numpy as np
from ruckig import InputParameter, Result, Ruckig, Synchronization, Trajectory

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
    rest by default; a coverage lane enters and leaves at speed). One leg of
    :func:`legs_pieces`, which times many legs in one call.

    Returns
    -------
    durations : numpy.ndarray, shape (P,)
        Phase durations (zero-length phases dropped), s.
    coeffs : numpy.ndarray, shape (P, 4, d)
        Power-basis coefficients of each phase in local time, lowest first.
    """
    legs = legs_pieces(
        np.asarray(start, dtype=float)[None],
        np.asarray(end, dtype=float)[None],
        [limits],
        np.asarray([speeds], dtype=float),
    )
    return legs.durations, legs.coeffs


@dataclass(frozen=True)
class Legs:
    """Straight legs, each time-optimal, as the cubic phases of their profiles.

    Attributes
    ----------
    durations
        Phase durations of every leg in turn, shape (P,), s (zero-length phases dropped).
    coeffs
        Power-basis coefficients of each phase in its local time, lowest first, (P, 4, d).
    leg_durations
        Each leg's duration, shape (K,), s.
    """

    durations: FloatArray
    coeffs: FloatArray
    leg_durations: FloatArray


def legs_pieces(
    starts: FloatArray,
    ends: FloatArray,
    limits: LegLimits | Sequence[LegLimits],
    speeds: FloatArray | None = None,
) -> Legs:
    """Time ``K`` straight legs at once: Ruckig calls with a degree of freedom per leg.

    Each leg is a scalar move along its own direction; Ruckig's unsynchronised mode
    (``Synchronization.No``) gives every degree of freedom its own time-optimal profile,
    the same as ``K`` one-dimensional calls. Crossing into Ruckig and building its objects
    is what cost 24 us a leg when legs were timed one by one: here the objects are built
    once per thread and block size (:func:`_ruckig`) and reused, and a block of up to
    :data:`BLOCK` legs is one call. What is read back through the Python binding is
    what dominates the cost, so as little is read as the result needs (:func:`_time_block`);
    the phases are integrated from Ruckig's durations and jerks as Ruckig integrates them
    (:func:`_states`).

    Parameters
    ----------
    starts, ends
        ``(K, d)`` leg ends, m; every leg of positive length.
    limits
        One :class:`LegLimits` for every leg, or one per leg (checked by the caller).
    speeds
        ``(K, 2)`` speeds along each leg at its start and end, m/s (rest by default).
    """
    starts, ends = np.asarray(starts, dtype=float), np.asarray(ends, dtype=float)
    k = starts.shape[0]
    delta = ends - starts
    lengths = np.linalg.norm(delta, axis=1)
    directions = delta / lengths[:, None]
    bounds = _bounds(limits, directions)
    v_ends = np.zeros((k, 2)) if speeds is None else np.asarray(speeds, dtype=float)
    t, jerk = _timed(lengths, v_ends, bounds, read_jerk=speeds is not None)
    states = _states(t, jerk, v_ends[:, 0])
    if speeds is None:
        # Jerks taken from Ruckig's rest-to-rest profile (:func:`_time_block`) are kept only
        # where that profile ends where Ruckig's own check demands; any other leg is timed
        # again with its jerks read.
        miss = np.abs(states[:3, 7] - np.stack([lengths, v_ends[:, 1], np.zeros(k)]))
        other = np.flatnonzero(np.any(miss >= _END_TOLERANCE[:, None], axis=0))
        if other.size:
            t[:, other], jerk[:, other] = _timed(
                lengths[other], v_ends[other], bounds[other], read_jerk=True
            )
            states[:, :, other] = _states(t[:, other], jerk[:, other], v_ends[other, 0])
    leg, phase = np.nonzero(t.T > 1e-12)  # sub-picosecond phases only add round-off
    # p, v, a/2, j/6 at each kept phase's start in the leg's own coordinate, (4, P); then
    # times the leg's direction, plus its start. One pass per coefficient and axis: numpy's
    # broadcasting over a last axis of length d is several times slower.
    scalar = states.reshape(4, -1)[:, phase * k + leg] / np.array([[1.0], [1.0], [2.0], [6.0]])
    along, origin = directions.T[:, leg], starts.T[:, leg]
    coeffs = np.empty((leg.size, 4, starts.shape[1]))
    for axis, (u, o) in enumerate(zip(along, origin, strict=True)):
        np.multiply(scalar, u, out=coeffs[:, :, axis].T)
        coeffs[:, 0, axis] += o
    return Legs(t[phase, leg], coeffs, t.sum(axis=0))


#: Most legs timed in one Ruckig call (the objects of each power-of-two size up to it are kept).
BLOCK = 256
_SOLVERS = threading.local()


def _ruckig(size: int) -> tuple[InputParameter, Trajectory, Ruckig]:
    """Ruckig's input, output and generator for ``size`` legs, built once per thread."""
    cache: dict[int, tuple[InputParameter, Trajectory, Ruckig]] = _SOLVERS.__dict__.setdefault(
        "by_size", {}
    )
    if size not in cache:
        inp = InputParameter(size)
        inp.synchronization = Synchronization.No
        cache[size] = (inp, Trajectory(size), Ruckig(size))
    return cache[size]


#: Jerk signs of Ruckig's "up, down, down, up" profile (``ControlSigns::UDDU``), per phase.
_UDDU = np.array([[1.0], [0.0], [-1.0], [0.0], [-1.0], [0.0], [1.0]])
#: Ruckig's own tolerances on a profile's end position, speed and acceleration
#: (``Profile::p_precision``, ``v_precision``, ``a_precision``).
_END_TOLERANCE = np.array([1e-8, 1e-8, 1e-10])


def _timed(
    lengths: FloatArray, v_ends: FloatArray, bounds: FloatArray, *, read_jerk: bool
) -> tuple[FloatArray, FloatArray]:
    """Phase durations and jerks (7, K) of ``K`` legs, in calls of up to :data:`BLOCK` legs."""
    k = lengths.size
    t, jerk = np.empty((7, k)), np.empty((7, k))
    for first in range(0, k, BLOCK):
        block = slice(first, min(first + BLOCK, k))
        t[:, block], jerk[:, block] = _time_block(
            lengths[block], v_ends[block], bounds[block], read_jerk=read_jerk
        )
    return t, jerk


def _time_block(
    lengths: FloatArray, v_ends: FloatArray, bounds: FloatArray, *, read_jerk: bool
) -> tuple[FloatArray, FloatArray]:
    """Phase durations and jerks (7, k) of up to :data:`BLOCK` legs, in one Ruckig call.

    The call is sized to the next power of two; the spare degrees of freedom carry a
    unit move that is timed and dropped.

    Reading a profile back through the Python binding costs more than Ruckig's own
    calculation, about half a microsecond per array of a leg, so unless ``read_jerk`` only
    the phase durations are read, and the jerks are those of a time-optimal rest-to-rest
    move in the positive direction: Ruckig's up-down-down-up profile, ``+j, 0, -j, 0, -j,
    0, +j`` on its phases of positive length (``Profile::check``). The caller checks that
    the profile then ends where it must (:func:`legs_pieces`).
    """
    k = lengths.size
    size = 1 << (k - 1).bit_length()
    pad = size - k
    inp, out, otg = _ruckig(size)
    inp.current_position = [0.0] * size
    inp.target_position = lengths.tolist() + [1.0] * pad
    inp.current_velocity = v_ends[:, 0].tolist() + [0.0] * pad
    inp.target_velocity = v_ends[:, 1].tolist() + [0.0] * pad
    inp.max_velocity = bounds[:, 0].tolist() + [1.0] * pad
    inp.max_acceleration = bounds[:, 1].tolist() + [1.0] * pad
    inp.max_jerk = bounds[:, 2].tolist() + [1.0] * pad
    result = otg.calculate(inp, out)
    if result != Result.Working:
        raise SolverError(f"Ruckig failed on a leg of {lengths.min():.3g} m or more: {result}")
    phases = out.profiles[0][:k] if pad else out.profiles[0]
    t = _by_phase([p.t for p in phases])
    if read_jerk:
        return t, _by_phase([p.j for p in phases])
    return t, np.where(t > 0.0, _UDDU * bounds[:, 2], 0.0)


def _by_phase(per_leg: list[list[float]]) -> FloatArray:
    """Seven values per leg, as read from Ruckig, phase by phase: (7, k)."""
    return np.array(list(chain.from_iterable(per_leg))).reshape(-1, 7).T.copy()


def _bounds(limits: LegLimits | Sequence[LegLimits], directions: FloatArray) -> FloatArray:
    """Speed, acceleration and jerk limits along each leg, (K, 3).

    :meth:`LegLimits.along` for every leg, vectorised over the legs that share one
    :class:`LegLimits` (usually all of them).
    """
    out = np.empty((directions.shape[0], 3))
    if isinstance(limits, LegLimits):
        _fill_bounds(out, slice(None), limits, directions)
        return out
    groups: dict[int, list[int]] = {}
    for i, lim in enumerate(limits):
        groups.setdefault(id(lim), []).append(i)
    for rows in groups.values():
        _fill_bounds(out, rows, limits[rows[0]], directions[rows])
    return out


def _fill_bounds(
    out: FloatArray, rows: slice | list[int], lim: LegLimits, directions: FloatArray
) -> None:
    """``out[rows]`` = speed, acceleration, jerk limits of ``lim`` along ``directions``."""
    out[rows, 0] = lim.vmax
    if lim.per_axis:
        with np.errstate(divide="ignore"):
            mag = np.abs(directions)
            out[rows, 1] = np.min(np.asarray(lim.amax) / mag, axis=1)
            out[rows, 2] = np.min(np.asarray(lim.jmax) / mag, axis=1)
    else:
        out[rows, 1], out[rows, 2] = np.min(lim.amax), np.min(lim.jmax)


def _states(t: FloatArray, jerk: FloatArray, v0: FloatArray) -> FloatArray:
    """Position, speed, acceleration at each phase boundary and each phase's jerk, (4, 8, K).

    ``t`` and ``jerk`` are (7, K), phase by phase. Each leg starts at position 0 with speed
    ``v0`` (K,) and no acceleration. The recurrence is Ruckig's (``Profile::check``), term
    for term, summed in the order of its loop, so the states are Ruckig's own to round-off
    (its compiled loop may fuse multiply-adds)::

        a[i+1] = a[i] + t[i] * j[i]
        v[i+1] = v[i] + t[i] * (a[i] + t[i] * j[i] / 2)
        p[i+1] = p[i] + t[i] * (v[i] + t[i] * (a[i] / 2 + t[i] * j[i] / 6))

    (The phases run down the first axis so that each sum is one pass over all legs.)
    """
    out = np.zeros((4, 8, t.shape[1]))
    p, v, a = out[0], out[1], out[2]
    out[3, :7] = jerk
    tj = t * jerk
    a[1:] = tj
    _running_sum(a)
    v[0] = v0
    v[1:] = t * (a[:7] + tj / 2)
    _running_sum(v)
    p[1:] = t * (v[:7] + t * (a[:7] / 2 + tj / 6))
    _running_sum(p)
    return out


def _running_sum(rows: FloatArray) -> None:
    """``rows[i] += rows[i - 1]`` down the first axis, in place: ``cumsum(axis=0)``, same order.

    ``numpy.cumsum`` walks each column separately, ten times slower here than one vector
    add per row for a few rows of many legs.
    """
    for i in range(1, rows.shape[0]):
        rows[i] += rows[i - 1]


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
    if isinstance(limits, LegLimits):
        shared: LegLimits | None = limits
        per_leg: list[LegLimits] = []
        _check(limits, pts.shape[1])
    else:
        shared, per_leg = None, list(limits)
        if len(per_leg) != pts.shape[0] - 1:
            raise InputError(
                f"limits: got {len(per_leg)}, expected one per leg ({pts.shape[0] - 1})"
            )
        for lim in {id(lim): lim for lim in per_leg}.values():
            _check(lim, pts.shape[1])
    steps = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    moving = steps > REPEAT_TOLERANCE * max(1.0, float(np.abs(pts).max()))
    if not np.any(moving):
        raise InputError("waypoints: got coincident points, expected a path of positive length")
    idx = np.flatnonzero(moving)
    legs = legs_pieces(pts[idx], pts[idx + 1], shared or [per_leg[k] for k in idx])
    leg_time = np.zeros(pts.shape[0] - 1)
    leg_time[idx] = legs.leg_durations
    breaks = np.concatenate([[0.0], np.cumsum(legs.durations)])
    arrivals = np.concatenate([[0.0], np.cumsum(leg_time)])
    return StopAndGo(PiecewisePolynomial(breaks, legs.coeffs), arrivals)


def _check(limits: LegLimits, dim: int) -> None:
    as_float("vmax", limits.vmax, positive=True)
    if limits.per_axis:
        per_axis("amax", limits.amax, dim)
        per_axis("jmax", limits.jmax, dim)
    else:
        as_float("amax", limits.amax, positive=True)
        as_float("jmax", limits.jmax, positive=True)
