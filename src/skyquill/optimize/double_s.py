"""Time-optimal jerk-limited rest-to-rest moves in closed form (the "double S" profile).

A 1-D move of length ``L`` from rest to rest under speed, acceleration and jerk limits
``v``, ``a``, ``j`` is fastest along the symmetric seven-phase profile (Biagiotti &
Melchiorri, *Trajectory Planning for Automatic Machines and Robots*, Springer 2008,
sec. 3.4, with zero boundary speeds): jerk ``+j`` for ``T1``, none for ``T2`` (at the peak
acceleration ``j T1``), ``-j`` for ``T1`` (reaching the peak speed ``w``), a cruise ``T4``
at ``w``, and the mirror image to stop. Which limits it reaches depends on ``L``:

* the jerk phases last ``T1 = min(a/j, sqrt(v/j), cbrt(L / 2j))``: the acceleration limit,
  the speed limit, or the move's length, whichever is reached first;
* the constant-acceleration phase ``T2`` is the shorter of what the speed limit leaves,
  ``v / (j T1) - T1``, and what the length leaves (the root of
  ``L = j T1 (T1 + T2) (2 T1 + T2)``), never negative;
* the cruise ``T4 = L / w - (2 T1 + T2)``, never negative.

This is the profile Ruckig (Berscheid & Kröger, RSS 2021) returns for such a move, phase
for phase and in its layout (``tests/optimize/test_double_s.py`` checks it against Ruckig to
round-off), computed for many moves at once in a few numpy calls instead of one Ruckig call
and binding round trip each.
"""

from __future__ import annotations

import functools
import math
from typing import NamedTuple

import numpy as np

from skyquill.validation import FloatArray

#: Phases at most this long (s) add only round-off: callers drop them, and a profile
#: whose constant-acceleration and cruise phases are all that short is the jerk-only one.
MIN_PHASE_S = 1e-12
#: Jerk of each phase over the jerk limit: up, hold, down, cruise, down, hold, up.
JERK_SIGNS = np.array([1.0, 0.0, -1.0, 0.0, -1.0, 0.0, 1.0])
#: Phase durations over ``T1`` of a jerk-only profile, in Ruckig's layout: its two middle
#: phases of jerk ``-j`` are one of ``2 T1`` (the fourth and fifth phases are empty).
_JERK_ONLY = np.array([1.0, 0.0, 2.0, 0.0, 0.0, 0.0, 1.0])


def rest_to_rest(
    lengths: FloatArray,
    vmax: float | FloatArray,
    amax: float | FloatArray,
    jmax: float | FloatArray,
) -> FloatArray:
    """Phase durations of the time-optimal rest-to-rest moves of ``lengths``.

    Parameters
    ----------
    lengths : numpy.ndarray, shape (K,)
        Move lengths, m, each > 0.
    vmax, amax, jmax : float or numpy.ndarray of shape (K,)
        Speed (m/s), acceleration (m/s^2) and jerk (m/s^3) limits, each > 0: one for
        every move or one per move.

    Returns
    -------
    numpy.ndarray, shape (K, 7)
        Each move's seven phase durations, s, jerks ``JERK_SIGNS * jmax`` (the phases not
        reached are 0).
    """
    t1 = np.minimum(np.cbrt(lengths / (2.0 * jmax)), _ramp_cap(vmax, amax, jmax))
    peak_acc = jmax * t1
    t2 = _hold(lengths / peak_acc, t1, vmax / peak_acc - t1)
    peak_speed = peak_acc * (t1 + t2)
    t4 = lengths / peak_speed - (2.0 * t1 + t2)
    np.maximum(t4, 0.0, out=t4)
    t = np.empty((lengths.size, 7))
    t[:, 0::2] = t1[:, None]
    t[:, 1::4] = t2[:, None]
    t[:, 3] = t4
    jerk_only = np.flatnonzero(t2 + t4 <= MIN_PHASE_S)
    if jerk_only.size:
        t[jerk_only] = t1[jerk_only, None] * _JERK_ONLY
    return t


def _ramp_cap(
    vmax: float | FloatArray, amax: float | FloatArray, jmax: float | FloatArray
) -> float | FloatArray:
    """The longest a jerk phase can last, s: until the acceleration limit (``a / j``) or,
    if sooner, the speed limit with no constant-acceleration phase (``sqrt(v / j)``)."""
    if isinstance(vmax, float) and isinstance(amax, float) and isinstance(jmax, float):
        return min(amax / jmax, math.sqrt(vmax / jmax))  # shared limits: Python floats
    return np.minimum(np.divide(amax, jmax), np.sqrt(np.divide(vmax, jmax)))


def _hold(s: FloatArray, t1: FloatArray, by_speed: FloatArray) -> FloatArray:
    """The constant-acceleration phase ``T2`` (K,), s.

    ``s = L / (j T1)``, so the length allows the root of ``T2^2 + 3 T1 T2 + 2 T1^2 = s``,
    written ``2 (s - 2 T1^2) / (3 T1 + sqrt(T1^2 + 4 s))`` (no cancellation when ``T2`` is
    small); the speed limit allows ``by_speed``. The shorter, or 0.
    """
    t1_sq = t1 * t1
    by_length = 2.0 * (s - 2.0 * t1_sq) / (3.0 * t1 + np.sqrt(t1_sq + 4.0 * s))
    t2 = np.minimum(by_length, by_speed)
    return np.maximum(t2, 0.0, out=t2)


class Cruise(NamedTuple):
    """The moves that reach the speed limit under one set of limits, all alike but for
    their cruise phase (:func:`cruise`).

    Attributes
    ----------
    durations
        Phase durations, shape (n,), s: seven phases, or five when the speed limit is
        reached before the acceleration limit (no constant-acceleration phases); the
        cruise phase's entry is 0, to be set per move to ``L / vmax - ramp_s``.
    at_cruise
        Index of the cruise phase in ``durations``.
    ramp_s
        Speeding up to ``vmax`` takes this long, s, and so does slowing down: a move of
        length ``L`` cruises for ``L / vmax - ramp_s`` and lasts ``L / vmax + ramp_s``.
    mix
        The power-basis coefficients of each phase in local time (position, speed, half
        the acceleration and a sixth of the jerk at its start, phase by phase: 4 n rows)
        as weights of the move's unit direction, start point and end point (3 columns):
        up to the cruise a position is the start plus a distance along the direction,
        after it the end minus one (the profile's mirror image).
    """

    durations: FloatArray
    at_cruise: int
    ramp_s: float
    mix: FloatArray


@functools.lru_cache(maxsize=256)
def cruise(vmax: float, amax: float, jmax: float) -> Cruise | None:
    """The profile of every rest-to-rest move long enough to cruise at ``vmax``.

    Such a move of length ``L`` cruises for ``L / vmax - ramp_s`` s, if that is more than
    :data:`MIN_PHASE_S`; its other phases are the same for every length: computed once
    per limits (m/s, m/s^2, m/s^3), in Python floats. None where a jerk phase would last
    :data:`MIN_PHASE_S` or less (limits too extreme for a profile without dropped phases).
    """
    t1 = min(amax / jmax, math.sqrt(vmax / jmax))
    if t1 <= MIN_PHASE_S:
        return None
    peak_acc = jmax * t1
    t2 = vmax / peak_acc - t1
    if t2 <= MIN_PHASE_S:  # the speed limit first: no hold at the peak acceleration
        t2 = 0.0
    v1 = peak_acc * t1 / 2.0  # speed after the first jerk phase
    p1 = v1 * t1 / 3.0
    v2 = vmax - v1  # speed after the hold
    p2 = p1 + t2 * vmax / 2.0  # (the hold's mean speed is vmax / 2)
    p3 = vmax * (t1 + t2 / 2.0)  # half the ramp at a mean speed of vmax / 2
    j6, a2 = jmax / 6.0, peak_acc / 2.0
    durations = [t1, t2, t1, 0.0, t1, t2, t1]
    states = [
        [0.0, 0.0, 0.0, j6],
        [p1, v1, a2, 0.0],
        [p2, v2, a2, -j6],
        [p3, vmax, 0.0, 0.0],
        [-p3, vmax, 0.0, -j6],  # from here on, positions from the end (the mirror image)
        [-p2, v2, -a2, 0.0],
        [-p1, v1, -a2, j6],
    ]
    if t2 == 0.0:
        del durations[5], durations[1], states[5], states[1]
    at_cruise = 3 if t2 else 2
    mix = np.zeros((len(states), 4, 3))
    mix[:, :, 0] = states
    mix[: at_cruise + 1, 0, 1] = 1.0  # positions from the start up to the cruise
    mix[at_cruise + 1 :, 0, 2] = 1.0  # from the end after it
    shared = np.array(durations), mix.reshape(-1, 3)  # cached: shared by every caller
    for array in shared:
        array.setflags(write=False)
    return Cruise(shared[0], at_cruise, 2.0 * t1 + t2, shared[1])
