"""Straight rest-to-rest legs, each time-optimal under speed, acceleration and jerk limits.

Each leg is a move along its own direction ``d`` (a unit vector). From rest to rest
its time-optimal jerk-limited profile is the closed-form seven-phase "double S"
(:mod:`skyquill.optimize.double_s`, the profile Ruckig returns, checked against it in
the tests), computed for all legs at once; a leg that starts or ends moving (a coverage
lane entered at speed) is timed by Ruckig (Berscheid & Kröger, RSS 2021). A profile is
piecewise cubic in time (constant jerk per phase), so a chain of legs is exactly a
:class:`~skyquill.trajectory.PiecewisePolynomial`: stop-and-go coverage, transits,
approaches.

Limits: ``vmax`` is the speed (a norm: along a straight leg the speed is the
scalar speed along it). Acceleration and jerk limits are either norms (the
scalar profile's own limits) or per-axis boxes, which along ``d`` become
``min_k amax_k / |d_k|``.
"""

from __future__ import annotations

import functools
import math
import threading
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray
from ruckig import InputParameter, Profile, Result, Ruckig, Synchronization, Trajectory

from skyquill.errors import InputError, SolverError
from skyquill.optimize.double_s import JERK_SIGNS, MIN_PHASE_S, Cruise, cruise, rest_to_rest
from skyquill.trajectory import PiecewisePolynomial
from skyquill.validation import FloatArray, as_array, as_float, largest_magnitude

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
        (for legs timed one by one a transposed view of a (4, d, P) array, as it was
        computed: not C-contiguous).
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
    """Time ``K`` straight legs at once.

    Legs from rest to rest (no ``speeds``, or all zero) take the closed-form profile of
    :func:`~skyquill.optimize.double_s.rest_to_rest`, all in a few numpy calls; under one
    norm limit that every leg reaches, one shared profile mixed into every leg's pieces
    (:func:`_cruising`), cheaper still; in chains of :data:`PARTLY_CRUISING_FROM` legs or
    more also where some are too short to cruise (:func:`_partly_cruising`). Legs that
    start or end moving are timed by Ruckig, one degree of freedom per leg in its
    unsynchronised mode (``Synchronization.No``, the same as ``K`` one-dimensional calls),
    in blocks of up to :data:`BLOCK` legs per call on objects kept per thread
    (:func:`_ruckig`): up to :data:`READ_UP_TO` legs their whole profiles are read back
    (:func:`_read_block`), beyond only the phase durations and jerks, the states
    integrated here (:func:`_states`).

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
        A leg longer than Ruckig times (:class:`UntimeableLegError`: over
        :data:`RUCKIG_MAX_DURATION_S` at its limits), whether or not Ruckig times it.
    """
    starts, ends = np.asarray(starts, dtype=float), np.asarray(ends, dtype=float)
    delta = ends - starts
    lengths = np.sqrt(np.vecdot(delta, delta))  # numpy.linalg.norm(axis=1), cheaper
    if speeds is None or not np.any(speeds):
        cruising = _cruising(
            starts, ends, delta, lengths, shortest=float(lengths.min()), limits=limits
        )
        if cruising is not None:
            durations = cruising.durations[1:]
            leg_durations = durations.reshape(-1, cruising.phases).sum(axis=1)
            cruising.check(lengths, float(np.maximum.reduce(leg_durations)))
            return Legs(durations, cruising.coeffs, leg_durations)
        return _not_all_cruising(starts, ends, delta, lengths, limits)
    return _legs(starts, delta, lengths, limits, speeds)


#: Chains of fewer legs than this, some too short to cruise, are timed leg by leg
#: (:func:`_legs`), longer ones by the shared profile with the short legs' own phases
#: written over it (:func:`_partly_cruising`). Measured (``stop_and_go``, limits 2, 3,
#: 10, random legs in a 20 m cube, every fifth too short or a few): leg by leg took
#: 0.63-0.90x the time at 10-1,000 legs; at 2,000 and 3,000 legs with a few short it took
#: 3.3-3.7x (its arrays come from fresh pages, where the shared profile is mixed a block
#: at a time, :func:`_mixed`).
PARTLY_CRUISING_FROM = 1024


def _not_all_cruising(
    starts: FloatArray,
    ends: FloatArray,
    delta: FloatArray,
    lengths: FloatArray,
    limits: LegLimits | Sequence[LegLimits],
) -> Legs:
    """Legs from rest to rest that do not all cruise under one norm limit (some too short,
    or limits per leg or per axis), by the cheaper way for their number."""
    legs = None
    if lengths.size >= PARTLY_CRUISING_FROM:
        legs = _partly_cruising(starts, ends, delta, lengths, limits)
    if legs is None:
        legs = _legs(starts, delta, lengths, limits, None)
        _refuse_long(lengths, limits, legs.leg_durations)
    return legs


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


class _Cruising(NamedTuple):
    """Legs that all cruise at one speed limit, timed (:func:`_cruising`).

    Attributes
    ----------
    durations
        0, then the phase durations of every leg in turn, shape (K n + 1,), s: its running
        sum is the breaks of the legs flown back to back.
    coeffs
        Power-basis coefficients of each phase in local time, lowest first, (K n, 4, d).
    phases, at_cruise
        ``n``, the phases of each leg, and the index of its cruise among them.
    limits
        The limits, whose speed every leg reaches.
    ramp_s
        How long speeding up to ``limits.vmax`` takes, s (and slowing down): a leg of
        length ``L`` takes ``L / vmax + ramp_s``.
    """

    durations: FloatArray
    coeffs: FloatArray
    phases: int
    at_cruise: int
    limits: LegLimits
    ramp_s: float

    def leg_durations(self, lengths: FloatArray) -> FloatArray:
        """How long the legs of ``lengths`` (K,), m, take, s."""
        return lengths / self.limits.vmax + self.ramp_s

    def check(self, lengths: FloatArray, total_s: float) -> None:
        """Refuse a leg over :data:`RUCKIG_MAX_DURATION_S`, the legs of ``lengths`` (K,)
        taking ``total_s`` together (only then can one of them be too long)."""
        if total_s > RUCKIG_MAX_DURATION_S:
            _refuse_long(lengths, self.limits, self.leg_durations(lengths))


def _cruising(
    starts: FloatArray,
    ends: FloatArray,
    delta: FloatArray,
    lengths: FloatArray,
    *,
    shortest: float,
    limits: LegLimits | Sequence[LegLimits],
) -> _Cruising | None:
    """Legs from rest to rest under one norm limit that all reach its speed: the cheap case.

    All such legs share one profile but for its cruise (:func:`double_s.cruise`), so the
    pieces are that profile's, mixed from each leg's direction, start and end, in a handful
    of numpy calls whatever the number of legs (no phase to drop, each quantity one call).
    None if the limits are per leg or per axis, or a leg (the ``shortest``, m) is too short
    to cruise (then :func:`_not_all_cruising` times them). The caller checks the legs'
    durations (:meth:`_Cruising.check`).
    """
    if not isinstance(limits, LegLimits) or limits.per_axis:
        return None
    vmax = limits.vmax
    dim = delta.shape[1]
    shared = _shared(vmax, float(limits.amax), float(limits.jmax), dim)  # (norms: numbers)
    if shared is None:
        return None
    profile = shared.profile
    # (The same float operations as on every leg in durations: the shortest cruises least.)
    if shortest / vmax - profile.ramp_s <= MIN_PHASE_S:
        return None
    durations = shared.durations(lengths)
    coeffs = shared.mixed(starts, ends, delta, lengths)
    n = profile.durations.size
    return _Cruising(
        durations, coeffs.reshape(lengths.size * n, 4, dim), n, profile.at_cruise, limits,
        profile.ramp_s,
    )  # fmt: skip


class _Shared:
    """What every chain of legs under one norm limit in ``dim`` axes reuses (:func:`_shared`).

    Attributes
    ----------
    profile
        :func:`double_s.cruise` of the limits.
    vmax
        Their speed limit, m/s.
    mixer
        Its :attr:`~double_s.Cruise.mix` for legs in ``dim`` axes: ``kron(mix.T, eye(dim))``,
        (3 dim, 4 n dim), so that a leg's direction, start and end in a row (3 dim,) times it
        are its phases' coefficients (4 n dim,).
    """

    def __init__(self, profile: Cruise, vmax: float, dim: int) -> None:
        self.profile = profile
        self.vmax = vmax
        self.mixer = np.asarray(np.kron(profile.mix.T, np.eye(dim)), dtype=np.float64)
        self.mixer.setflags(write=False)
        self._kept = np.zeros(1)

    def durations(self, lengths: FloatArray) -> FloatArray:
        """0, then the phase durations of legs of ``lengths`` (K,), m, each as if it cruised
        (``L / vmax - ramp_s``: negative for a leg too short to), (K n + 1,), s: a new array,
        for the caller to sum.

        Up to :data:`KEPT_LEGS` legs, copied from an array kept for the longest chain so far
        (grown by doubling): one numpy call instead of the five that fill it in (about 1 us
        of the 15-20 us a chain of ten legs takes). Longer chains tile their own (the copy
        saves nothing there).
        """
        profile = self.profile
        k, n = lengths.size, profile.durations.size
        if k > KEPT_LEGS:
            durations = np.concatenate(([0.0], np.tile(profile.durations, k)))
        else:
            kept = self._kept
            if kept.size < k * n + 1:
                legs = min(KEPT_LEGS, max(k, 2 * (kept.size - 1) // n))
                kept = np.concatenate(([0.0], np.tile(profile.durations, legs)))
                kept.setflags(write=False)
                self._kept = kept  # (one reference replaced: safe between threads)
            durations = kept[: k * n + 1].copy()
        # (One ufunc writes each cruise into its strided slot: dividing there, then
        # subtracting in place, cost 0.3 us more, numpy's overlap check.)
        np.subtract(lengths / self.vmax, profile.ramp_s, out=durations[1 + profile.at_cruise :: n])
        return durations

    def mixed(
        self, starts: FloatArray, ends: FloatArray, delta: FloatArray, lengths: FloatArray
    ) -> FloatArray:
        """The profile's coefficients for legs ``delta`` (K, d) of ``lengths`` (K,) from
        ``starts`` to ``ends``, m, each as if it cruised, (K, 4 n d): each leg's unit
        direction, start and end, (K, 3 d), mixed into every phase's coefficients by one
        matrix product."""
        basis = np.concatenate((delta / lengths[:, None], starts, ends), axis=1)
        coeffs: FloatArray = np.dot(basis, self.mixer)  # (the matmul operator's costs more)
        return coeffs


#: The longest chain whose phase durations are copied from an array kept per shared profile
#: (:meth:`_Shared.durations`): at most 1,793 numbers, 14 kB, for each of the 256 kept.
KEPT_LEGS = 256


@functools.lru_cache(maxsize=256)
def _shared(vmax: float, amax: float, jmax: float, dim: int) -> _Shared | None:
    """The :class:`_Shared` profile of the limits (m/s, m/s^2, m/s^3) for legs in ``dim`` axes,
    or None where :func:`double_s.cruise` has none."""
    profile = cruise(vmax, amax, jmax)
    return None if profile is None else _Shared(profile, vmax, dim)


def _partly_cruising(
    starts: FloatArray,
    ends: FloatArray,
    delta: FloatArray,
    lengths: FloatArray,
    limits: LegLimits | Sequence[LegLimits],
) -> Legs | None:
    """Legs from rest to rest under one norm limit, some too short to cruise.

    Every leg is timed through the shared profile (:meth:`_Shared.durations`), then the
    phases of those too short to cruise are replaced by their own (the closed form, in the
    same phase slots), and the phases of no length dropped. The pieces are mixed
    :data:`MIX_BLOCK` legs at a time straight into the result (:func:`_mixed`). None if the
    limits are per leg or per axis.
    """
    if not isinstance(limits, LegLimits) or limits.per_axis:
        return None
    shared = _shared(limits.vmax, float(limits.amax), float(limits.jmax), delta.shape[1])
    if shared is None:
        return None
    phases = shared.durations(lengths)[1:]  # (the leading 0 is for a running sum)
    k, n = lengths.size, shared.profile.durations.size
    durations = phases.reshape(k, n)
    short = np.flatnonzero(durations[:, shared.profile.at_cruise] <= MIN_PHASE_S)
    bounds = np.array([[limits.vmax, limits.amax, limits.jmax]])
    ph = _rest_to_rest(lengths.take(short), np.repeat(bounds, short.size, axis=0))
    if n < 7 and np.any(ph.t[:, [1, 5]] > MIN_PHASE_S):  # (a hold the profile has not)
        return None
    durations[short] = ph.t[:, _SLOTS[n]]
    leg_durations = durations.sum(axis=1)
    _refuse_long(lengths, limits, leg_durations)
    kept = np.flatnonzero(phases > MIN_PHASE_S)
    coeffs = _mixed(starts, ends, delta, lengths, shared=shared, short_legs=(short, ph), kept=kept)
    return Legs(phases.take(kept), coeffs, leg_durations)


def _mixed(
    starts: FloatArray,
    ends: FloatArray,
    delta: FloatArray,
    lengths: FloatArray,
    *,
    shared: _Shared,
    short_legs: tuple[NDArray[np.intp], _Phases],
    kept: NDArray[np.intp],
) -> FloatArray:
    """The coefficients (P, 4, d) of the phases ``kept`` (P,) of legs ``delta`` (K, d) that
    all fly the ``shared`` profile but the ``short_legs`` (their indices and own phases).

    The shared profile is mixed for :data:`MIX_BLOCK` legs at a time, the short legs' own
    phases written over theirs, and the phases kept taken straight into the result: each
    block's array stays small. Mixed for all legs at once (two arrays of ``56 K d`` bytes),
    a chain of 1,000 legs took 0.3 ms or 0.9 ms by how the C library's allocator had last
    returned memory: the kernel zeroing fresh pages for both, call after call.
    """
    k, dim = delta.shape
    n = shared.profile.durations.size
    short, ph = short_legs
    slots = _SLOTS[n]
    # p, v, a/2, j/6 at each slot's start, (k_short, n, 4), along each leg's direction.
    scalar = np.stack(
        (ph.p[:, slots], ph.v[:, slots], ph.a[:, slots] / 2.0, ph.j[:, slots] / 6.0), axis=-1
    )
    own = (
        scalar[..., None]
        * (delta.take(short, axis=0) / lengths.take(short)[:, None])[:, None, None, :]
    )
    own[:, :, 0] += starts.take(short, axis=0)[:, None, :]
    out = np.empty((kept.size, 4, dim))
    edges = np.arange(0, k + MIX_BLOCK, MIX_BLOCK)
    at_short = np.searchsorted(short, edges).tolist()
    at_kept = np.searchsorted(kept, edges * n).tolist()
    blocks = [
        (lo, min(k, lo + MIX_BLOCK), slice(at_short[b], at_short[b + 1]),
         slice(at_kept[b], at_kept[b + 1]))
        for b, lo in enumerate(range(0, k, MIX_BLOCK))
    ]  # fmt: skip
    for lo, hi, mine, rows in blocks:
        legs = slice(lo, hi)
        mixed = shared.mixed(starts[legs], ends[legs], delta[legs], lengths[legs])
        coeffs = mixed.reshape(hi - lo, n, 4, dim)
        coeffs[short[mine] - lo] = own[mine]
        # ("clip": the rows are in range by construction; "raise" copies through a buffer.)
        local = kept[rows] - lo * n
        coeffs.reshape(-1, 4, dim).take(local, axis=0, out=out[rows], mode="clip")
    return out


#: Legs whose pieces :func:`_mixed` mixes at a time: 128 legs of seven phases in three axes
#: are 86 kB, below the C library's threshold for memory of its own (128 kB).
MIX_BLOCK = 128


#: The phases of the seven-phase profile in the slots of a shared profile of n phases
#: (:func:`double_s.cruise`: without its hold phases when it has none).
_SLOTS = {7: np.arange(7), 5: np.array([0, 2, 3, 4, 6])}


def _legs(
    starts: FloatArray,
    delta: FloatArray,
    lengths: FloatArray,
    limits: LegLimits | Sequence[LegLimits],
    speeds: FloatArray | None,
) -> Legs:
    """:func:`legs_pieces` of legs ``delta`` (K, d) of ``lengths`` (K,) from ``starts``, each
    leg timed on its own.

    At a few legs the cost is the number of numpy calls (a fraction of a microsecond or
    more each, whatever their size), at many the passes over memory: each quantity is one
    call over all legs and phases, on arrays whose last axis is long (numpy's loops over a
    last axis of length 3 or 4 are several times slower).
    """
    directions = delta / lengths[:, None]
    bounds = _bounds(limits, directions)
    if speeds is None or not np.any(speeds):
        ph = _rest_to_rest(lengths, bounds)
    else:
        v_ends = np.asarray(speeds, dtype=float)
        if lengths.size <= READ_UP_TO:
            ph = _read_block(lengths, v_ends, bounds)
        else:
            t, jerk = _timed(lengths, v_ends, bounds)
            ph = _states(t, jerk, v_ends[:, 0])
    # The phases kept (sub-picosecond ones only add round-off), as flat positions in the
    # (K, 7) and (K, 8) arrays, in flight order.
    at7 = np.flatnonzero(ph.t > MIN_PHASE_S)
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


def _rest_to_rest(lengths: FloatArray, bounds: FloatArray) -> _Phases:
    """The phases of legs from rest to rest under ``bounds`` (K, 3): the closed form (the
    caller refuses legs too long, :func:`_refuse_long`)."""
    vmax, amax, jmax = bounds.T
    t = rest_to_rest(lengths, vmax, amax, jmax)
    return _states(t, JERK_SIGNS * jmax[:, None])


def _refuse_long(
    lengths: FloatArray, limits: LegLimits | Sequence[LegLimits], durations: FloatArray
) -> None:
    """Refuse the first leg longer than :data:`RUCKIG_MAX_DURATION_S`, if any, as Ruckig
    would refuse it (lengths, durations (K,)), so that whether a leg is timed does not
    depend on the speeds at its ends."""
    too_long = np.flatnonzero(durations > RUCKIG_MAX_DURATION_S)
    if too_long.size:
        i = int(too_long[0])
        raise UntimeableLegError(
            i,
            float(lengths[i]),
            (limits if isinstance(limits, LegLimits) else limits[i]).vmax,
            float(durations[i]),
            argument="starts, ends",
            what=f"leg {i},",
        )


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


#: Divisors from a phase's start state (p, v, a, j) to its power-basis coefficients.
_TAYLOR = np.array([1.0, 1.0, 2.0, 6.0])
#: ``_BEFORE[m, i] = 1`` for phases ``m < i``: running sums over phases as one product.
_BEFORE = np.triu(np.ones((7, 8)), k=1)
#: Sums over a leg's seven phases, as one product.
_ONES = np.ones(7)


def _timed(
    lengths: FloatArray, v_ends: FloatArray, bounds: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Phase durations and jerks (K, 7) of ``K`` legs, in calls of up to :data:`BLOCK` legs."""
    k = lengths.size
    if k <= BLOCK:
        return _time_block(lengths, v_ends, bounds)
    t, jerk = np.empty((k, 7)), np.empty((k, 7))
    for first in range(0, k, BLOCK):
        block = slice(first, min(first + BLOCK, k))
        t[block], jerk[block] = _time_block(lengths[block], v_ends[block], bounds[block])
    return t, jerk


def _time_block(
    lengths: FloatArray, v_ends: FloatArray, bounds: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Phase durations and jerks (k, 7) of up to :data:`BLOCK` legs, in one Ruckig call.

    Reading a profile back through the Python binding costs more than Ruckig's own
    calculation, about half a microsecond per array of a leg: only these two are read.
    """
    k = lengths.size
    phases = _calculate(lengths, v_ends, bounds)
    read: list[float] = []
    for profile in phases:
        read += profile.t
    for profile in phases:
        read += profile.j
    values = np.array(read).reshape(2, k, 7)
    return values[0], values[1]


#: Up to this many legs timed by Ruckig their states are read from its profiles
#: (:func:`_read_block`): three more arrays a leg through the binding cost less than the
#: dozen numpy calls that integrate them (:func:`_states`), whatever the number of legs.
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
            f"{argument}: got {what} {length:.6g} m long, which takes {_seconds(duration)} s at a "
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


def _states(t: FloatArray, jerk: FloatArray, v0: FloatArray | None = None) -> _Phases:
    """The phases of legs of durations ``t`` and jerks ``jerk`` (K, 7), integrated.

    Each leg starts at position 0 with speed ``v0`` (K,) (at rest without it) and no
    acceleration. The
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
    if v0 is not None:
        v += v0[:, None]
    p = (t * (v[:, :7] + t * (before / 2 + tj / 6))) @ _BEFORE
    return _Phases(t, jerk, p, v, a)


class StopAndGo(NamedTuple):
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
    if type(waypoints) is np.ndarray and waypoints.dtype == np.float64 and waypoints.ndim == 2:
        pts = waypoints  # (not copied: nothing here writes it, nothing returned holds it)
    else:
        pts = as_array("waypoints", waypoints, ndim=2, finite=False)  # (checked finite below)
    if pts.shape[0] < 2:
        largest_magnitude("waypoints", pts)  # (a coordinate that is not finite named first)
        raise InputError(f"waypoints: got {pts.shape[0]} point(s), expected at least 2")
    if isinstance(limits, LegLimits):
        if limits.per_axis:
            _check(limits, pts.shape[1])
    else:
        if len(limits) != pts.shape[0] - 1:
            raise InputError(
                f"limits: got {len(limits)}, expected one per leg ({pts.shape[0] - 1})"
            )
        for lim in {id(lim): lim for lim in limits}.values():
            _check(lim, pts.shape[1])
    # The sum of squares bounds every coordinate and every step's square (by twice itself):
    # below _SAFE_SQUARES no step's square overflows.
    squares = float(np.vdot(pts, pts))
    if squares < _SAFE_SQUARES:
        delta = pts[1:] - pts[:-1]
        steps = np.sqrt(np.vecdot(delta, delta))  # numpy.linalg.norm(axis=1), cheaper
    else:
        delta, steps = _huge_steps(pts)
    idx = None  # the legs flown, if not all: repeated points are skipped
    starts, ends = pts[:-1], pts[1:]
    # (Python's min is cheaper on a short list, numpy's past about 20 numbers.)
    shortest = min(steps.tolist()) if steps.size <= 16 else float(np.minimum.reduce(steps))
    repeat = _repeat_threshold(pts, squares, shortest)
    if shortest <= repeat:
        idx = np.flatnonzero(steps > repeat)
        if not idx.size:
            raise InputError("waypoints: got coincident points, expected a path of positive length")
        delta, steps, starts, ends = delta[idx], steps[idx], pts[idx], pts[idx + 1]
        shortest = float(steps.min())
        if not isinstance(limits, LegLimits):
            limits = [limits[k] for k in idx.tolist()]
    try:
        trajectory, arrived = _flown(starts, ends, delta, steps, shortest=shortest, limits=limits)
    except UntimeableLegError as exc:
        first = exc.leg if idx is None else int(idx[exc.leg])
        raise exc.naming("waypoints", f"the leg from waypoint {first} to {first + 1},") from None
    return StopAndGo(trajectory, arrived if idx is None else _arrivals(pts.shape[0], idx, arrived))


#: A sum of squares of the waypoints below which no step's square overflows (twice it is
#: below the largest float, 1.8e308).
_SAFE_SQUARES = 1e300


def _huge_steps(pts: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The steps between the waypoints ``pts`` (K, d), m, and their lengths (K - 1,), m,
    where their squares could overflow (coordinates of 1e150 m and more); refuses
    waypoints that are not finite, and a step longer than the largest float."""
    largest_magnitude("waypoints", pts)
    with np.errstate(over="ignore"):
        delta = pts[1:] - pts[:-1]
        steps = np.hypot.reduce(delta, axis=1)
    if not np.all(np.isfinite(steps)):
        k = int(np.flatnonzero(~np.isfinite(steps))[0])
        raise InputError(
            f"waypoints: got the leg from waypoint {k} to {k + 1} longer than the largest "
            "number (1.8e308 m), expected legs a flight can take: bring the waypoints closer"
        )
    return delta, steps


def _seconds(duration: float) -> str:
    """A duration, s, for a message: grouped digits up to a billion seconds, else e-notation
    (a leg 1e156 m long took 157 digits)."""
    return f"{duration:,.0f}" if duration < 1e9 else f"{duration:.3g}"


def _repeat_threshold(pts: FloatArray, squares: float, shortest: float) -> float:
    """How short a step between the waypoints ``pts`` (K, d), m, must be to be a repeat, m,
    their sum of squares being ``squares``, m², and their shortest step ``shortest``;
    refuses waypoints that are not finite.

    :data:`REPEAT_TOLERANCE` times their largest magnitude (at least 1 m). Their sum of
    squares, one dot product, bounds that magnitude from above and is finite only if every
    waypoint is: the largest magnitude itself (a reduction, 0.8 us more on a ten-leg chain)
    is computed only when the shortest step is within the bound's threshold, so the
    threshold returned is exact whenever a step is within it.
    """
    if squares < math.inf:
        bound = REPEAT_TOLERANCE * max(1.0, math.sqrt(squares))
        if shortest > bound:
            return bound
    return REPEAT_TOLERANCE * max(1.0, largest_magnitude("waypoints", pts))


def _flown(
    starts: FloatArray,
    ends: FloatArray,
    delta: FloatArray,
    lengths: FloatArray,
    *,
    shortest: float,
    limits: LegLimits | Sequence[LegLimits],
) -> tuple[PiecewisePolynomial, FloatArray]:
    """The legs flown back to back from rest to rest, and when each ends, (K + 1,), s (from 0).

    ``starts``, ``ends``, ``delta`` (K, d), m; ``lengths`` (K,) and the ``shortest``, m.
    """
    cruising = _cruising(starts, ends, delta, lengths, shortest=shortest, limits=limits)
    if cruising is None:
        legs = _not_all_cruising(starts, ends, delta, lengths, limits)
        arrived = np.zeros(lengths.size + 1)
        np.cumsum(legs.leg_durations, out=arrived[1:])
        return _chain(legs.durations, legs.coeffs), arrived
    # (Not in place, which costs 0.25 us more; numpy.cumsum's wrapper costs as much again.)
    breaks = np.add.accumulate(cruising.durations)
    cruising.check(lengths, float(breaks[-1]))
    return _trusted(breaks, cruising.coeffs), breaks[:: cruising.phases]


def _arrivals(n_points: int, idx: NDArray[np.intp], arrived: FloatArray) -> FloatArray:
    """Arrival time at each of ``n_points`` waypoints, the legs ``idx`` flown arriving at
    ``arrived[1:]`` (a repeated waypoint arrives when the previous one did)."""
    leg_time = np.zeros(n_points - 1)
    leg_time[idx] = np.diff(arrived)
    arrivals = np.zeros(n_points)
    np.cumsum(leg_time, out=arrivals[1:])
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
    return _trusted(breaks, coeffs)


def _trusted(breaks: FloatArray, coeffs: FloatArray) -> PiecewisePolynomial:
    """The pieces ``coeffs`` (P, 4, d) between ``breaks`` (P + 1,), s, as :func:`_chain`
    builds them (pieces lost in the clock's round-off dropped)."""
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
