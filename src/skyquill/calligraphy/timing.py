"""The timing of a writing route: when the flight reaches each of its samples.

:func:`route_times` is the first timing, one rest-to-rest profile along the
whole route within the limits (paper 003 §3.5's allocation run along the arc
length, :func:`~skyquill.optimize.timing.allocate_path_times`), with the lifts
timed for the jerk limit and the legs from and to a home kept off the speed
limit.
"""

from __future__ import annotations

import numpy as np

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.fidelity import contact_runs
from skyquill.calligraphy.options import WritingOptions
from skyquill.calligraphy.route import LIFT
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


def route_times(
    points: FloatArray, roles: FloatArray, board: Board, opts: WritingOptions
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
    """
    vmax, amax = opts.limits.timing_bounds()
    share = TIP_TIMING_ACC if opts.follows_tip(board) else 0.5
    steps = np.diff(allocate_path_times(points, vmax, share * amax))
    lifts = contact_runs(roles == LIFT)
    # Where the legs from and to home end and start: above the first and last
    # stroke, or with no lifts (a sky board) on them.
    if lifts:
        first, last = lifts[0][0] - 1, lifts[-1][1]
    else:
        pen = contact_runs(roles >= 0)
        first, last = pen[0][0], pen[-1][1] - 1
    from_home = first > 0  # else the route starts right above the first stroke
    if from_home:
        # The legs from and to home are long and straight, timed at the speed
        # limit: the smoothed spline would brush past it there and make every
        # solve a conic one. A margin keeps them off it.
        steps[:first] /= HOME_LEG_SPEED
        steps[last:] /= HOME_LEG_SPEED
    jmax = opts.limits.jmax or opts.limits.jmax_axis
    if not opts.follows_tip(board) or jmax is None:
        return np.concatenate([[0.0], np.cumsum(steps)])
    lengths = np.linalg.norm(np.diff(points, axis=0), axis=1)
    for start, stop in lifts:
        legs = slice(max(start - 1, 0), stop)  # into the lift's first sample, out of its last
        needed = (LIFT_JERK_FACTOR * float(lengths[legs].sum()) / jmax) ** (1.0 / 3.0)
        steps[legs] *= max(1.0, needed / max(float(steps[legs].sum()), 1e-12))
    if from_home:  # settle above the first stroke
        steps[lifts[0][0] - 1] += SETTLE_S
    return np.concatenate([[0.0], np.cumsum(steps)])
