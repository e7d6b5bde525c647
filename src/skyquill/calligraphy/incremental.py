"""Writing while someone draws: one more stroke appended to a planned flight.

:func:`append_stroke` keeps the flight as planned up to the moment its
writing ends (:attr:`Mission.join_s <skyquill.calligraphy.mission.Mission.join_s>`:
the brush back up after the last stroke) and plans only what follows: the
transit to the new stroke, the lift down, the stroke, the lift up and, from a
home, the leg home. That part is its own smoothing problem (paper 003), whose
boundary conditions at the start (eqs. 40-42) are the flight's position,
velocity, acceleration and jerk at the join, so the appended flight is
continuous to the jerk there; it ends at rest like every writing flight. Its
timing is found as a whole flight's is (:mod:`skyquill.calligraphy.allocation`:
the fastest faithful pace within the same limits), on a route of one stroke,
so the work does not grow with the strokes already planned
(``bench/calligraphy_append.py``).

The flight up to the join is kept exactly, polynomial piece by polynomial
piece, so the strokes already written -- and, on a vehicle, already flown --
do not move; the appended flight is a
:class:`~skyquill.trajectory.PiecewisePolynomial` with one fit per part.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np

from skyquill.calligraphy.allocation import plan_route
from skyquill.calligraphy.fidelity import BOARD_MARGIN_M, Contact, Deviation
from skyquill.calligraphy.mission import Mission
from skyquill.calligraphy.planning import RoutePlan, fidelity_error, resegmented
from skyquill.calligraphy.route import BRAKE, RouteSamples, build_route, writing_end
from skyquill.errors import InputError
from skyquill.limits import VehicleLimits
from skyquill.trajectory import PiecewisePolynomial, SplineTrajectory, Trajectory
from skyquill.validation import FloatArray, as_array, as_int

#: Derivatives continuous where an appended part joins the flight: position to jerk.
JOIN_ORDERS = 4
#: Most points in one appended stroke (a tablet at 200 Hz for 50 s).
MAX_STROKE_POINTS = 10_000
#: The flight brakes from its motion at the join within this share of the limits
#: (:func:`braking`), over at least :data:`MIN_BRAKE_S` and at most
#: :data:`MAX_BRAKE_S` (then whatever it takes), sampled every :data:`BRAKE_STEP_S`.
BRAKE_SHARE = 0.75
MIN_BRAKE_S = 0.2
MAX_BRAKE_S = 5.0
BRAKE_STEP_S = 0.05


def append_stroke(
    mission: Mission, stroke: FloatArray, *, resegment_iterations: int = 0
) -> Mission:
    """``mission`` with ``stroke`` written after its last stroke (module docstring).

    Parameters
    ----------
    mission
        A writing flight from :func:`~skyquill.calligraphy.mission.plan_writing`
        or from this function (not one split into uploads for a target).
    stroke
        The new stroke on the board, shape (K, 2), K >= 2, in the board's
        coordinates ``(u, v)``, m -- those of the strokes already planned
        (``mission.board.to_board``), within the character's square
        ``[0, size_m]`` (the ink lands on the board only there).
    resegment_iterations
        Re-segmentation steps for the appended part (paper 000 §5.4, as
        ``options.resegment`` asks). None by default: a step costs about
        what the whole part's planning does (~10 ms), and it smooths the
        part's timing without shortening it.

    Returns
    -------
    Mission
        The flight with one more stroke: its trajectory equal to ``mission``'s
        up to ``mission.join_s`` and continuous to the jerk there, its pen
        windows, fits, deviation and contact extended, and ``join_s`` at the
        end of the new stroke's lift.

    Raises
    ------
    InputError
        A mission split into uploads, or a stroke that is not a (K, 2) array of
        at least two points on the board.
    InfeasibleError
        The new stroke cannot be written within the limits and the tolerance
        (unless ``options.best_effort``).
    """
    start = time.perf_counter()
    if not isinstance(mission, Mission):
        raise InputError(f"mission: got {type(mission).__name__}, expected a Mission")
    if mission.join_s is None or mission.target is not None:
        raise InputError(
            "mission: got a flight split into uploads for a target, expected one planned "
            "without a target (plan_writing with target=None)"
        )
    opts, board = mission.options, mission.board
    world = board.to_world(_board_stroke(stroke, opts.size_m))
    join = mission.join_s
    state = tuple(mission.trajectory.evaluate(np.array([join]), n)[0] for n in range(JOIN_ORDERS))
    samples = _route(mission, world, state)
    plan = plan_route(samples, board, opts)
    if not plan.faithful(opts) and not opts.best_effort:
        raise fidelity_error(plan, opts)
    steps = as_int("resegment_iterations", resegment_iterations, low=0, high=100)
    if opts.resegment != "off" and steps > 0:
        plan = resegmented(samples, plan, board, replace(opts, resegment_iterations=steps))
    return _joined(mission, world, plan, samples, time.perf_counter() - start)


def _board_stroke(stroke: FloatArray, size_m: float) -> FloatArray:
    """The validated stroke (K, 2), m, on the character's square."""
    uv = as_array("stroke", stroke, ndim=2)
    if uv.shape[1] != 2 or not 2 <= uv.shape[0] <= MAX_STROKE_POINTS:
        raise InputError(
            f"stroke: got shape {uv.shape}, expected (K, 2) with 2 <= K <= "
            f"{MAX_STROKE_POINTS:,}: the stroke's points (u, v) on the board, m"
        )
    if float(np.linalg.norm(np.diff(uv, axis=0), axis=1).sum()) == 0.0:
        raise InputError("stroke: got all points equal, expected a stroke of non-zero length")
    low, high = float(uv.min()), float(uv.max())
    if low < 0.0 or high > size_m:
        raise InputError(
            f"stroke: got coordinates from {low:.4g} to {high:.4g} m, expected within the "
            f"character's square, 0 to size_m = {size_m:g} m (the board ends "
            f"{BOARD_MARGIN_M:g} m beyond it)"
        )
    return uv


def _route(mission: Mission, world: FloatArray, state: tuple[FloatArray, ...]) -> RouteSamples:
    """The route from the join to the new stroke, through it and, from a home, back home.

    It begins with the flight braking from its motion at the join
    (:func:`braking`), then runs from where that stops as a route from rest.
    """
    opts = mission.options
    threshold = opts.turning_threshold_m or 0.25 * opts.tolerance
    lead_times, lead_points = braking(state, opts.limits)
    rest = build_route((world,), mission.board, mission.home, threshold, start=lead_points[-1])
    n = lead_times.size - 1  # samples before the rest route's first (the stop)
    legs = rest.legs if rest.legs is not None else (0, len(rest.points) - 1)
    return replace(
        rest,
        points=np.vstack([lead_points[:-1], rest.points]),
        roles=np.concatenate([np.full(n, BRAKE), rest.roles]),
        corners=rest.corners + n,
        start=state,
        legs=(0, legs[1] + n),
        lead_in=lead_times,
    )


def braking(state: tuple[FloatArray, ...], limits: VehicleLimits) -> tuple[FloatArray, FloatArray]:
    """How a flight in ``state`` (position, velocity, acceleration, jerk, each (3,)) comes
    to rest: times (n,), s, from 0, and positions (n, 3), m, the last where it stops.

    The quintic from the state's position, velocity, acceleration and jerk to
    rest (no velocity, no acceleration) at ``tau``, sampled every
    :data:`BRAKE_STEP_S`, ``tau`` growing by a quarter from :data:`MIN_BRAKE_S`
    until its acceleration and jerk stay within :data:`BRAKE_SHARE` of the
    limits (or of the state's own); where none up to :data:`MAX_BRAKE_S` does
    (a fast flight whose acceleration keeps growing), the minimum-jerk quartic
    from the state's position, velocity and acceleration instead (the quintic
    of the Euler-Lagrange equation with a free end, whose fifth derivative
    vanishes there), at the first ``tau`` that keeps within them.

    The appended route starts with these samples, held as firmly as the lifts
    (the ``BRAKE`` role), and continues from where they stop: a route through
    the join point itself has the flight turn back against its own motion
    (13.7 m/s^3 in the first knot span against a limit of 10, 永 from a home),
    and a loosely held start lets the smoothing drop the flight's jerk within
    one knot span (11 m/s^3 on its hull from 7.2 at the end of a flight): either
    sends every solve to the conic QP, ten times the closed form's time.
    """
    amax = BRAKE_SHARE * limits.timing_bounds()[1]
    jmax = BRAKE_SHARE * (limits.jmax or limits.jmax_axis or math.inf)
    for keep_jerk in (True, False):
        tau = MIN_BRAKE_S
        while tau <= MAX_BRAKE_S:
            t, points, gentle = _brake(state, tau, keep_jerk, amax, jmax)
            if gentle:
                return t, points
            tau *= 1.25
    return t, points


def _brake(
    state: tuple[FloatArray, ...], tau: float, keep_jerk: bool, amax: float, jmax: float
) -> tuple[FloatArray, FloatArray, bool]:
    """Samples of a braking polynomial over ``tau`` (:func:`braking`), and whether it keeps
    within ``amax`` and ``jmax`` (or the state's own acceleration and jerk)."""
    p0, v0, a0, j0 = state
    c3 = j0 / 6.0 if keep_jerk else None
    if c3 is not None:  # c4, c5 of p = ... + c3 t^3 + c4 t^4 + c5 t^5, at rest at tau
        A = np.array([[4 * tau**3, 5 * tau**4], [12 * tau**2, 20 * tau**3]])
        b = -np.vstack([v0 + a0 * tau + 3 * c3 * tau**2, a0 + 6 * c3 * tau])
        c4, c5 = np.linalg.solve(A, b)
    else:  # c3, c4 of the quartic, at rest at tau
        A = np.array([[3 * tau**2, 4 * tau**3], [6 * tau, 12 * tau**2]])
        c3, c4 = np.linalg.solve(A, -np.vstack([v0 + a0 * tau, a0]))
        c5 = np.zeros(3)
    t = np.linspace(0.0, tau, max(2, math.ceil(tau / BRAKE_STEP_S) + 1))
    tt = t[:, None]
    acc = a0 + 6 * c3 * tt + 12 * c4 * tt**2 + 20 * c5 * tt**3
    jerk = 6 * c3 + 24 * c4 * tt + 60 * c5 * tt**2
    gentle = bool(
        np.linalg.norm(acc, axis=1).max() <= max(amax, float(np.linalg.norm(a0)))
        and np.linalg.norm(jerk, axis=1).max() <= max(jmax, float(np.linalg.norm(j0)))
    )
    points = p0 + v0 * tt + a0 * tt**2 / 2 + c3 * tt**3 + c4 * tt**4 + c5 * tt**5
    return t, points, gentle


def _joined(
    mission: Mission, world: FloatArray, plan: RoutePlan, samples: RouteSamples, elapsed: float
) -> Mission:
    """``mission`` up to its join, then ``plan``: the appended flight."""
    join = mission.join_s
    assert join is not None
    n_old = len(mission.strokes_world)
    windows = tuple((join + a, join + b) for a, b in plan.windows)
    return replace(
        mission,
        fits=(*mission.fits, plan.fit),
        trajectory=_concatenated(mission.trajectory, join, plan.fit.trajectory),
        strokes_world=(*mission.strokes_world, world),
        pen_windows=(*mission.pen_windows, *windows),
        deviation=_deviation(mission, plan),
        time_scale=max(mission.time_scale, plan.scale),
        planning_time_s=mission.planning_time_s + elapsed,
        contact=_contact(mission.contact, plan.contact, n_old),
        join_s=join + float(plan.times[writing_end(samples.roles)]),
    )


def _pieces(traj: Trajectory) -> tuple[FloatArray, FloatArray]:
    """Breaks (P + 1,) and power-basis coefficients (P, K, d) of a spline or polynomial."""
    if isinstance(traj, SplineTrajectory):
        return traj.to_piecewise_polynomial()
    if isinstance(traj, PiecewisePolynomial):
        return traj.breaks, traj.coeffs
    raise InputError(
        f"mission: got a {type(traj).__name__} trajectory, expected a spline or a piecewise "
        "polynomial (a flight planned by plan_writing)"
    )


def _concatenated(before: Trajectory, join: float, after: SplineTrajectory) -> PiecewisePolynomial:
    """``before`` on ``[0, join]``, then ``after`` from ``join``: exact pieces of both."""
    breaks, coeffs = _pieces(before)
    # The pieces that start before the join; the last one is cut there. A join at the
    # flight's end can round a few ulps past its last break (the breaks are L / alpha):
    # then every piece is kept, the last one ending at the join.
    keep = min(int(np.searchsorted(breaks, join, side="left")), coeffs.shape[0])
    head_breaks = np.concatenate([breaks[:keep], [join]])
    tail_breaks, tail_coeffs = after.to_piecewise_polynomial()
    return PiecewisePolynomial(
        np.concatenate([head_breaks, join + tail_breaks[1:]]),
        np.concatenate([coeffs[:keep], tail_coeffs]),
    )


def _deviation(mission: Mission, plan: RoutePlan) -> Deviation:
    """The flight's deviation: the worst of both parts, the mean weighted by pen-down time
    (the ink is sampled uniformly in time, so that is its sample count)."""
    old, new = mission.deviation, plan.deviation
    w_old = sum(b - a for a, b in mission.pen_windows)
    w_new = sum(b - a for a, b in plan.windows)
    mean = (old.mean_m * w_old + new.mean_m * w_new) / max(w_old + w_new, 1e-12)
    return Deviation(
        max(old.path_to_input_max_m, new.path_to_input_max_m),
        max(old.input_to_path_max_m, new.input_to_path_max_m),
        mean,
    )


def _contact(old: Contact | None, new: Contact | None, n_old: int) -> Contact | None:
    """Both parts' contact with the board as one (``None`` when the path is fitted)."""
    if old is None or new is None:
        return None
    return Contact(
        min_depth_m=min(old.min_depth_m, new.min_depth_m),
        max_depth_m=max(old.max_depth_m, new.max_depth_m),
        clearance_m=min(old.clearance_m, new.clearance_m),
        travel_m=old.travel_m,
        ink_strokes=old.ink_strokes + new.ink_strokes,
        strokes=n_old + new.strokes,
    )


__all__ = ["JOIN_ORDERS", "MAX_STROKE_POINTS", "append_stroke"]
