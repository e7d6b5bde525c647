"""The timing of a writing route: when the flight reaches each of its samples.

:func:`route_times` is one rest-to-rest profile along the whole route (paper
003 §3.5's allocation run along the arc length,
:func:`~skyquill.optimize.timing.allocate_path_times`), with the lifts timed
for the jerk limit and the legs from and to a home kept off the speed limit.
It is timed with the vehicle's limits, or, for the writing between the legs,
with those limits capped at a *pace* (:class:`TimingBounds`): the one knob
the time allocation (:mod:`skyquill.calligraphy.allocation`) turns to find
the fastest faithful flight. Every step of the timing is non-increasing in
every limit and in the pace, which is what makes looser limits never slower.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.fidelity import contact_runs
from skyquill.calligraphy.options import WritingOptions
from skyquill.calligraphy.route import LIFT
from skyquill.limits import VehicleLimits
from skyquill.optimize.timing import allocate_path_times
from skyquill.validation import FloatArray

#: A rest-to-rest move of length d within jerk J takes at least (32 d / J)^(1/3)
#: (bang-bang jerk); a minimum-jerk (quintic) one peaks at 60 d / T^3.
LIFT_JERK_FACTOR = 32.0
#: Fraction of the acceleration limit the route is timed with when the tip is
#: fitted (0.5 for the path). Measured (bench/calligraphy.py, 87 characters):
#: at 0.6 the writing took at most 1.148x the path's on the bundled characters
#: but up to 1.169x on many-stroke KanjiVG ones (語 読 橋 ...); 0.65 brings those
#: to 1.13x at 2-5 conic solves a plan (0.75: 1.02-1.09x, 7-11 solves).
TIP_TIMING_ACC = 0.65
#: Fraction of the speed limit the legs from and to home are timed at.
HOME_LEG_SPEED = 0.9
#: Pause above the first stroke after the approach from home, s. The approach
#: is the flight's fastest leg; paper 000's outer loop (w_n ~ 1.8 rad/s,
#: zeta 0.5) is still ~3 mm off after it, and the tip, swinging forward as the
#: vehicle stops, would touch down that far past the stroke's start (simulated:
#: 5.2 mm on 中 without the pause, 4.4 mm with 0.5 s, 3.2 mm with 1 s).
SETTLE_S = 1.0


#: The shape of the caps on the writing's timing (:meth:`TimingBounds.at_pace`):
#: (speed, acceleration, jerk) = (1 m/s, 2 m/s^2, 10 m/s^3) at pace 1 -- the
#: CLI's default limits -- and (p, 2 p^2, 10 p^3) at pace p, as one motion
#: played p times faster. One shape for every vehicle: below a vehicle's limits
#: the timing at a pace is the same whatever the limits, so a plan found there
#: is found again at looser limits (docs/calligraphy-timing.md).
PACE_SHAPE = (1.0, 2.0, 10.0)


@dataclass(frozen=True)
class TimingBounds:
    """What a route is timed with: speed m/s, acceleration m/s^2, jerk m/s^3 (``None``: none).

    The vehicle's (:meth:`of`), or those capped at a pace (:meth:`at_pace`).
    """

    vmax: float
    amax: float
    jmax: float | None

    @classmethod
    def of(cls, limits: VehicleLimits) -> TimingBounds:
        """The limits a time allocation may plan with (norms, else per-axis bounds)."""
        vmax, amax = limits.timing_bounds()
        return cls(vmax, amax, limits.jmax if limits.jmax is not None else limits.jmax_axis)

    def at_pace(self, pace: float) -> TimingBounds:
        """These bounds capped at ``pace`` (:data:`PACE_SHAPE` played ``pace`` times faster)."""
        v, a, j = PACE_SHAPE
        jmax = None if self.jmax is None else min(self.jmax, j * pace**3)
        return TimingBounds(min(self.vmax, v * pace), min(self.amax, a * pace**2), jmax)

    @property
    def full_pace(self) -> float:
        """The slowest pace at which :meth:`at_pace` gives these bounds back."""
        v, a, j = PACE_SHAPE
        paces = [self.vmax / v, math.sqrt(self.amax / a)]
        if self.jmax is not None:
            paces.append((self.jmax / j) ** (1.0 / 3.0))
        # A cube root cubed can come back an ulp short of the limit: a hair faster, so
        # that this pace gives the limits back exactly.
        return max(paces) * (1.0 + 1e-12)


def route_times(
    points: FloatArray,
    roles: FloatArray,
    board: Board,
    opts: WritingOptions,
    pace: float | None = None,
    *,
    legs: tuple[int, int] | None = None,
    lead_in: FloatArray | None = None,
) -> FloatArray:
    """Times (N,), s, for the route ``points`` (N, 3) with ``roles`` (N,).

    One rest-to-rest profile within the speed and half the acceleration limit
    (:func:`~skyquill.optimize.timing.allocate_path_times`); fitting the tip,
    :data:`TIP_TIMING_ACC` of it: the swung tip is fitted to ~2 mm where the
    path is to ~4.5 mm (of 5), and the flown lifts cost time the corners can
    give back. Fitting the tip,
    each lift (down onto a stroke, up from it) also takes at least the time a
    rest-to-rest move of its length needs within the jerk limit,
    ``(32 d / jmax)^(1/3)`` (:data:`LIFT_JERK_FACTOR`): the profile knows no
    jerk, and a lift that must be flown (the brush leaves the board) but is
    timed faster makes the jerk limit bind there and every solve a conic one.
    Coming from a home, the legs from and to it are flown at
    :data:`HOME_LEG_SPEED` of the speed limit, and fitting the tip the vehicle
    pauses :data:`SETTLE_S` above the first stroke before it touches down.

    With a ``pace``, the writing -- everything between the legs from and to
    home -- is timed with the limits capped at it (:meth:`TimingBounds.at_pace`);
    the legs keep the speed limit (far from the board, the brush's swing leaves
    no ink) but accelerate as the writing does: at 50 m/s^2 the smoothed start
    of the leg home pulled the last stroke 15-30 mm off (巡 at 20 m/s, 50 m/s^2).

    ``legs``: the samples ``(first, last)`` between which the route writes (the
    legs from and to home outside them); ``None``: found from the roles, the
    leg from home ending above the first stroke, the leg home starting above
    the last. A route with no leg from home (``first == 0``) does not settle.

    ``lead_in``: the times of the route's first samples (n,), fixed -- a
    continuing flight braking from its motion
    (:mod:`skyquill.calligraphy.incremental`); the rest is timed from rest at
    the last of them.
    """
    if lead_in is not None:
        n = lead_in.size
        shifted = None if legs is None else (max(legs[0] - n + 1, 0), legs[1] - n + 1)
        rest = route_times(points[n - 1 :], roles[n - 1 :], board, opts, pace, legs=shifted)
        return np.concatenate([lead_in, lead_in[-1] + rest[1:]])
    full = TimingBounds.of(opts.limits)
    writing = full if pace is None else full.at_pace(pace)
    share = TIP_TIMING_ACC if opts.follows_tip(board) else 0.5
    steps = np.diff(allocate_path_times(points, writing.vmax, share * writing.amax))
    lifts = contact_runs(roles == LIFT)
    first, last = legs if legs is not None else _legs(roles, lifts)
    from_home = first > 0  # else the route starts right above the first stroke
    if from_home or last < steps.size:
        if writing.vmax != full.vmax:
            # Cruising at the speed limit, but accelerating as the writing does: the
            # smoothing carries a leg's acceleration into the first and last stroke.
            home_legs = np.diff(allocate_path_times(points, full.vmax, share * writing.amax))
            steps[:first], steps[last:] = home_legs[:first], home_legs[last:]
        # The legs from and to home are long and straight, timed at the speed
        # limit: the smoothed spline would brush past it there and make every
        # solve a conic one. A margin keeps them off it.
        steps[:first] /= HOME_LEG_SPEED
        steps[last:] /= HOME_LEG_SPEED
    if not opts.follows_tip(board) or writing.jmax is None:
        return np.concatenate([[0.0], np.cumsum(steps)])
    lengths = np.linalg.norm(np.diff(points, axis=0), axis=1)
    for down, up in lifts:
        moves = slice(max(down - 1, 0), up)  # into the lift's first sample, out of its last
        needed = (LIFT_JERK_FACTOR * float(lengths[moves].sum()) / writing.jmax) ** (1.0 / 3.0)
        steps[moves] *= max(1.0, needed / max(float(steps[moves].sum()), 1e-12))
    if from_home:  # settle above the first stroke
        steps[lifts[0][0] - 1] += SETTLE_S
    return np.concatenate([[0.0], np.cumsum(steps)])


def writing_span(roles: FloatArray, legs: tuple[int, int] | None = None) -> tuple[int, int]:
    """The samples ``(first, last)`` between which a route writes: ``legs`` if given,
    else found from the roles (:func:`route_times`); before and after, the legs."""
    return legs if legs is not None else _legs(roles, contact_runs(roles == LIFT))


def _legs(roles: FloatArray, lifts: list[tuple[int, int]]) -> tuple[int, int]:
    """Where the legs from and to home end and start: above the first and last
    stroke, or with no lifts (a sky board) on them."""
    if lifts:
        return lifts[0][0] - 1, lifts[-1][1]
    pen = contact_runs(roles >= 0)
    return pen[0][0], pen[-1][1] - 1
