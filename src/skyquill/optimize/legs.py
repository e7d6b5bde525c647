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
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray
from ruckig import InputParameter, Profile, Result, Ruckig, Synchronization, Trajectory

from skyquill.errors import InputError, SolverError
from skyquill.trajectory import PiecewisePolynomial
from skyquill.validation import FloatArray, as_array, as_float

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

    Checked once, here (a chain of ten legs costs less than checking its limits again):
    each limit is a finite number > 0, or with ``per_axis`` a number or a 1-D array of
    them (its length is checked against the waypoints by :func:`stop_and_go`).
    """

    vmax: float
    amax: float | FloatArray
    jmax: float | FloatArray
    per_axis: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "vmax", as_float("vmax", self.vmax, positive=True))
        for name in ("amax", "jmax"):
            value = getattr(self, name)
            if self.per_axis:
                value = as_array(name, value)
                if value.ndim > 1 or np.any(value <= 0.0):
                    raise InputError(
                        f"{name}: got {value.tolist()}, expected a positive limit per axis"
                    )
                value.setflags(write=False)
            else:
                value = as_float(name, value, positive=True)
            object.__setattr__(self, name, value)

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
        Power-basis coefficients of each phase in its local time, lowest first, (P, 4, d)
        (a transposed view of a (4, d, P) array, as it was computed: not C-contiguous).
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
    what dominates the cost, so as little is read as the result needs: up to
    :data:`READ_UP_TO` legs their whole profiles (:func:`_read_block`), beyond only the
    phase durations (:func:`_time_block`), the states integrated here (:func:`_states`).

    Parameters
    ----------
    starts, ends
        ``(K, d)`` leg ends, m; every leg of positive length.
    limits
        One :class:`LegLimits` for every leg, or one per leg (checked by the caller).
    speeds
        ``(K, 2)`` speeds along each leg at its start and end, m/s (rest by default).

    Raises
    ------
    InputError
        A leg Ruckig cannot time (:class:`UntimeableLegError`: longer than
        :data:`RUCKIG_MAX_DURATION_S` at its speed).
    """
    starts, ends = np.asarray(starts, dtype=float), np.asarray(ends, dtype=float)
    delta = ends - starts
    lengths = np.sqrt(np.add.reduce(delta * delta, axis=1))  # numpy.linalg.norm(axis=1)
    return _legs(starts, delta, lengths, limits, speeds)


class _Phases(NamedTuple):
    """The seven phases of ``K`` legs' profiles, leg by leg along the first axis.

    ``t`` and ``j`` (K, 7): each phase's duration (s) and jerk; ``p``, ``v``, ``a`` (K, 8):
    position, speed and acceleration along the leg at each phase boundary.
    """

    t: FloatArray
    j: FloatArray
    p: FloatArray
    v: FloatArray
    a: FloatArray


def _legs(
    starts: FloatArray,
    delta: FloatArray,
    lengths: FloatArray,
    limits: LegLimits | Sequence[LegLimits],
    speeds: FloatArray | None,
) -> Legs:
    """:func:`legs_pieces` of legs ``delta`` (K, d) of ``lengths`` (K,) from ``starts``.

    At a few legs the cost is the number of numpy calls (a microsecond or more each,
    whatever their size), at many the passes over memory: each quantity is one call over
    all legs and phases, on arrays whose last axis is long (numpy's loops over a last axis
    of length 3 or 4 are several times slower).
    """
    directions = delta / lengths[:, None]
    bounds = _bounds(limits, directions)
    v_ends = np.zeros((lengths.size, 2)) if speeds is None else np.asarray(speeds, dtype=float)
    if lengths.size <= READ_UP_TO:
        ph = _read_block(lengths, v_ends, bounds)
    else:
        ph = _integrated(lengths, v_ends, bounds, rest=speeds is None)
    # The phases kept (sub-picosecond ones only add round-off), as flat positions in the
    # (K, 7) and (K, 8) arrays, in flight order.
    at7 = np.flatnonzero(ph.t > 1e-12)
    leg = at7 // 7
    at8 = at7 + leg
    # p, v, a/2, j/6 at each kept phase's start along its leg, (4, P); times the leg's
    # direction, plus its start, (4, d, P): one pass each over long rows. The pieces'
    # coefficients (P, 4, d) are a transposed view of it, not a copy.
    scalar = np.empty((4, at7.size))
    ph.p.take(at8, out=scalar[0])  # (the methods: numpy.take's wrapper costs as much again)
    ph.v.take(at8, out=scalar[1])
    ph.a.take(at8, out=scalar[2])
    ph.j.take(at7, out=scalar[3])
    scalar[2:] /= _TAYLOR[2:, None]
    per_axis = scalar[:, None, :] * directions.T.take(leg, axis=1)
    per_axis[0] += starts.T.take(leg, axis=1)
    return Legs(ph.t.take(at7), per_axis.transpose(2, 0, 1), ph.t @ _ONES)


def _integrated(
    lengths: FloatArray, v_ends: FloatArray, bounds: FloatArray, *, rest: bool
) -> _Phases:
    """The phases of many legs: Ruckig's durations and jerks (:func:`_timed`), the states
    integrated here (:func:`_states`), cheaper than reading them through the binding."""
    t, jerk = _timed(lengths, v_ends, bounds, read_jerk=not rest)
    ph = _states(t, jerk, v_ends[:, 0])
    if rest:
        # Jerks taken from Ruckig's rest-to-rest profile (:func:`_time_block`) are kept only
        # where that profile ends where Ruckig's own check demands; any other leg is timed
        # again with its jerks read.
        tol_p, tol_v, tol_a = _END_TOLERANCE
        miss = np.abs(ph.p[:, 7] - lengths) >= tol_p
        miss |= np.abs(ph.v[:, 7]) >= tol_v
        miss |= np.abs(ph.a[:, 7]) >= tol_a
        if miss.any():
            other = np.flatnonzero(miss)
            t[other], jerk[other] = _timed(
                lengths[other], v_ends[other], bounds[other], read_jerk=True
            )
            again = _states(t[other], jerk[other], v_ends[other, 0])
            for whole, part in zip(ph, again, strict=True):
                whole[other] = part
    return ph


#: Most legs timed in one Ruckig call (the objects of each power-of-two size up to it are kept).
BLOCK = 256
#: Longest move Ruckig times, s: beyond it ``calculate`` returns ``ErrorTrajectoryDuration``
#: (-101), which Ruckig's Python binding (0.19) cannot convert to its ``Result`` (a bare
#: ``ValueError``); with one degree of freedom it skips the check, so a lone leg is held
#: to the same limit here (whether a leg is timed must not depend on its company).
RUCKIG_MAX_DURATION_S = 7.6e3
_SOLVERS = threading.local()


def _ruckig(size: int) -> tuple[InputParameter, Trajectory, Ruckig]:
    """Ruckig's input, output and generator for ``size`` legs, built once per thread.

    Every leg starts at position 0 along itself: set here, once.
    """
    cache: dict[int, tuple[InputParameter, Trajectory, Ruckig]] = _SOLVERS.__dict__.setdefault(
        "by_size", {}
    )
    if size not in cache:
        inp = InputParameter(size)
        inp.synchronization = Synchronization.No
        inp.current_position = [0.0] * size
        cache[size] = (inp, Trajectory(size), Ruckig(size))
    return cache[size]


#: Jerk signs of Ruckig's "up, down, down, up" profile (``ControlSigns::UDDU``), per phase.
_UDDU = np.array([1.0, 0.0, -1.0, 0.0, -1.0, 0.0, 1.0])
#: Ruckig's own tolerances on a profile's end position, speed and acceleration
#: (``Profile::p_precision``, ``v_precision``, ``a_precision``).
_END_TOLERANCE = np.array([1e-8, 1e-8, 1e-10])
#: Divisors from a phase's start state (p, v, a, j) to its power-basis coefficients.
_TAYLOR = np.array([1.0, 1.0, 2.0, 6.0])
#: ``_BEFORE[m, i] = 1`` for phases ``m < i``: running sums over phases as one product.
_BEFORE = np.triu(np.ones((7, 8)), k=1)
#: Sums over a leg's seven phases, as one product.
_ONES = np.ones(7)


def _timed(
    lengths: FloatArray, v_ends: FloatArray, bounds: FloatArray, *, read_jerk: bool
) -> tuple[FloatArray, FloatArray]:
    """Phase durations and jerks (K, 7) of ``K`` legs, in calls of up to :data:`BLOCK` legs."""
    k = lengths.size
    if k <= BLOCK:
        return _time_block(lengths, v_ends, bounds, read_jerk=read_jerk)
    t, jerk = np.empty((k, 7)), np.empty((k, 7))
    for first in range(0, k, BLOCK):
        block = slice(first, min(first + BLOCK, k))
        t[block], jerk[block] = _time_block(
            lengths[block], v_ends[block], bounds[block], read_jerk=read_jerk
        )
    return t, jerk


def _time_block(
    lengths: FloatArray, v_ends: FloatArray, bounds: FloatArray, *, read_jerk: bool
) -> tuple[FloatArray, FloatArray]:
    """Phase durations and jerks (k, 7) of up to :data:`BLOCK` legs, in one Ruckig call.

    Reading a profile back through the Python binding costs more than Ruckig's own
    calculation, about half a microsecond per array of a leg, so unless ``read_jerk`` only
    the phase durations are read, and the jerks are those of a time-optimal rest-to-rest
    move in the positive direction: Ruckig's up-down-down-up profile, ``+j, 0, -j, 0, -j,
    0, +j`` on its phases of positive length (``Profile::check``). The caller checks that
    the profile then ends where it must (:func:`_integrated`).
    """
    k = lengths.size
    phases = _calculate(lengths, v_ends, bounds)
    read: list[float] = []
    for profile in phases:
        read += profile.t
    if read_jerk:
        for profile in phases:
            read += profile.j
    values = np.array(read).reshape(-1, k, 7)
    if read_jerk:
        return values[0], values[1]
    t = values[0]
    return t, np.where(t > 0.0, _UDDU * bounds[:, 2:], 0.0)


#: Up to this many legs the states are read from Ruckig's profiles (:func:`_read_block`):
#: four more arrays a leg through the binding cost less than the fifteen or so numpy calls
#: that integrate them (:func:`_integrated`), 1-3 us each whatever the number of legs.
READ_UP_TO = 16


def _read_block(lengths: FloatArray, v_ends: FloatArray, bounds: FloatArray) -> _Phases:
    """The phases of a few legs, all read from Ruckig's profiles (one call)."""
    k = lengths.size
    phases = _calculate(lengths, v_ends, bounds)
    read: list[float] = []
    for name in ("t", "j", "p", "v", "a"):  # each as one block, so each is contiguous
        for profile in phases:
            read += getattr(profile, name)
    values = np.array(read)
    t, j = values[: 7 * k].reshape(k, 7), values[7 * k : 14 * k].reshape(k, 7)
    p, v, a = values[14 * k :].reshape(3, k, 8)
    return _Phases(t, j, p, v, a)


def _calculate(lengths: FloatArray, v_ends: FloatArray, bounds: FloatArray) -> list[Profile]:
    """Ruckig's profiles of up to :data:`BLOCK` legs, from one call.

    The call is sized to the next power of two; the spare degrees of freedom carry a
    unit move that is timed and dropped.
    """
    k = lengths.size
    size = 1 << (k - 1).bit_length()
    pad = [1.0] * (size - k)
    inp, out, otg = _ruckig(size)
    inp.target_position = lengths.tolist() + pad
    v0, v1 = v_ends.T.tolist()
    inp.current_velocity = v0 + [0.0] * len(pad)
    inp.target_velocity = v1 + [0.0] * len(pad)
    vmax, amax, jmax = bounds.T.tolist()
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = vmax + pad, amax + pad, jmax + pad
    try:
        result = otg.calculate(inp, out)
    except ValueError:  # a code the binding's Result does not know (-101: too long a move)
        result = None
    if result != Result.Working or (size == 1 and out.duration > RUCKIG_MAX_DURATION_S):
        raise _refusal(lengths, v_ends, bounds, result)
    phases: list[Profile] = out.profiles[0]
    return phases[:k] if pad else phases


class UntimeableLegError(InputError):
    """A leg Ruckig will not time: longer than :data:`RUCKIG_MAX_DURATION_S` at its limits.

    Attributes
    ----------
    leg
        Its index among the legs of the call.
    """

    def __init__(
        self, leg: int, length: float, vmax: float, duration: float, *, argument: str, what: str
    ) -> None:
        self.leg, self.length, self.vmax, self.duration = leg, length, vmax, duration
        super().__init__(
            f"{argument}: got {what} {length:.6g} m long, which takes {duration:,.0f} s at a "
            f"speed limit of {vmax:g} m/s, expected moves of at most "
            f"{RUCKIG_MAX_DURATION_S:,.0f} s (the longest Ruckig times): add waypoints along "
            "it or raise vmax"
        )

    def naming(self, argument: str, what: str) -> UntimeableLegError:
        """The same refusal in the words of the caller's ``argument``."""
        return UntimeableLegError(
            self.leg, self.length, self.vmax, self.duration, argument=argument, what=what
        )


def _refusal(
    lengths: FloatArray, v_ends: FloatArray, bounds: FloatArray, result: object
) -> InputError | SolverError:
    """Why Ruckig failed on a block of legs: the first leg too long for it, if any.

    Ruckig refuses a call whose longest degree of freedom takes more than
    :data:`RUCKIG_MAX_DURATION_S` (``ErrorTrajectoryDuration``), except with one degree of
    freedom, which it times anyway: so each leg is timed again on its own, on fresh
    objects (rare), and its duration compared.
    """
    inp, out, otg = InputParameter(1), Trajectory(1), Ruckig(1)
    for i, length in enumerate(lengths.tolist()):
        inp.target_position = [length]
        inp.current_velocity, inp.target_velocity = [v_ends[i, 0]], [v_ends[i, 1]]
        inp.max_velocity, inp.max_acceleration, inp.max_jerk = ([b] for b in bounds[i])
        if otg.calculate(inp, out) != Result.Working:
            break
        if out.duration > RUCKIG_MAX_DURATION_S:
            vmax = float(bounds[i, 0])
            return UntimeableLegError(
                i, length, vmax, out.duration, argument="starts, ends", what=f"leg {i},"
            )
    code = "an error code its Python binding does not know" if result is None else result
    return SolverError(f"Ruckig failed on a leg of {lengths.min():.3g} m or more: {code}")


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
    if lim.per_axis:
        out[rows, 0] = lim.vmax
        with np.errstate(divide="ignore"):
            mag = np.abs(directions)
            out[rows, 1] = np.min(np.asarray(lim.amax) / mag, axis=1)
            out[rows, 2] = np.min(np.asarray(lim.jmax) / mag, axis=1)
    else:
        out[rows] = (lim.vmax, _smallest(lim.amax), _smallest(lim.jmax))


def _smallest(bound: float | FloatArray) -> float:
    """A norm limit given as a number, or the smallest of an array of them."""
    return bound if isinstance(bound, float) else float(np.min(bound))


def _states(t: FloatArray, jerk: FloatArray, v0: FloatArray) -> _Phases:
    """The phases of legs of durations ``t`` and jerks ``jerk`` (K, 7), integrated.

    Each leg starts at position 0 with speed ``v0`` (K,) and no acceleration. The
    recurrence is Ruckig's (``Profile::check``)::

        a[i+1] = a[i] + t[i] * j[i]
        v[i+1] = v[i] + t[i] * (a[i] + t[i] * j[i] / 2)
        p[i+1] = p[i] + t[i] * (v[i] + t[i] * (a[i] / 2 + t[i] * j[i] / 6))

    with each running sum over the phases one matrix product (:data:`_BEFORE`), so the
    states agree with Ruckig's to round-off (the additions may come in another order).
    """
    tj = t * jerk
    a = tj @ _BEFORE
    before = a[:, :7]
    v = (t * (before + tj / 2)) @ _BEFORE
    if np.any(v0):
        v += v0[:, None]
    p = (t * (v[:, :7] + t * (before / 2 + tj / 6))) @ _BEFORE
    return _Phases(t, jerk, p, v, a)


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

    Raises
    ------
    InputError
        Bad waypoints or limits, or a leg Ruckig cannot time (longer than
        :data:`RUCKIG_MAX_DURATION_S` at its speed limit).
    """
    pts = as_array("waypoints", waypoints, ndim=2)
    if pts.shape[0] < 2:
        raise InputError(f"waypoints: got {pts.shape[0]} point(s), expected at least 2")
    if isinstance(limits, LegLimits):
        _check(limits, pts.shape[1])
    else:
        if len(limits) != pts.shape[0] - 1:
            raise InputError(
                f"limits: got {len(limits)}, expected one per leg ({pts.shape[0] - 1})"
            )
        for lim in {id(lim): lim for lim in limits}.values():
            _check(lim, pts.shape[1])
    delta = pts[1:] - pts[:-1]
    steps = np.sqrt(np.add.reduce(delta * delta, axis=1))  # numpy.linalg.norm(axis=1)
    moving = steps > REPEAT_TOLERANCE * max(1.0, float(np.abs(pts).max()))
    every = bool(moving.all())
    idx = np.arange(steps.size) if every else np.flatnonzero(moving)
    if not idx.size:
        raise InputError("waypoints: got coincident points, expected a path of positive length")
    if not every:
        delta, steps = delta[idx], steps[idx]
        if not isinstance(limits, LegLimits):
            limits = [limits[k] for k in idx.tolist()]
    try:
        legs = _legs(pts[:-1] if every else pts[idx], delta, steps, limits, None)
    except UntimeableLegError as exc:
        first = int(idx[exc.leg])
        raise exc.naming("waypoints", f"the leg from waypoint {first} to {first + 1},") from None
    return StopAndGo(
        _chain(legs.durations, legs.coeffs), _arrivals(pts.shape[0], idx, legs.leg_durations)
    )


def _arrivals(n_points: int, idx: NDArray[np.intp], leg_durations: FloatArray) -> FloatArray:
    """Arrival time at each of ``n_points`` waypoints, the legs ``idx`` taking ``leg_durations``
    (a repeated waypoint arrives when the previous one did)."""
    arrivals = np.zeros(n_points)
    if idx.size < n_points - 1:
        leg_time = np.zeros(n_points - 1)
        leg_time[idx] = leg_durations
        leg_durations = leg_time
    np.cumsum(leg_durations, out=arrivals[1:])
    return arrivals


def _chain(durations: FloatArray, coeffs: FloatArray) -> PiecewisePolynomial:
    """The pieces flown one after another from time 0 (durations (P,), s; coeffs (P, 4, d)).

    Built through :meth:`PiecewisePolynomial.trusted`: every duration is positive and the
    coefficients finite, since both were just computed. Only past
    :data:`_ROUND_OFF_HORIZON_S` can a positive duration vanish into the clock's round-off
    (a phase of 1e-12 s after 9,000 s): such pieces are dropped (they move by less).
    """
    breaks = np.empty(durations.size + 1)
    breaks[0] = 0.0
    np.cumsum(durations, out=breaks[1:])
    if breaks[-1] > _ROUND_OFF_HORIZON_S:
        grows = breaks[1:] > breaks[:-1]
        if not grows.all():
            breaks, coeffs = np.concatenate([[0.0], breaks[1:][grows]]), coeffs[grows]
    return PiecewisePolynomial.trusted(breaks, coeffs)


#: Below this total, s, adding a phase longer than 1e-12 s always moves the clock
#: (1e-12 s exceeds half the spacing of doubles up to 2**53 * 1e-12 s, about 9,007 s).
_ROUND_OFF_HORIZON_S = 9.0e3


def _check(limits: LegLimits, dim: int) -> None:
    """Per-axis limits of one number or one per axis of the ``dim``-axis waypoints (the rest
    was checked when ``limits`` was made)."""
    if limits.per_axis:
        for name, value in (("amax", limits.amax), ("jmax", limits.jmax)):
            if np.ndim(value) and np.shape(value) != (dim,):
                raise InputError(
                    f"{name}: got shape {np.shape(value)}, expected a number or shape ({dim},)"
                )
