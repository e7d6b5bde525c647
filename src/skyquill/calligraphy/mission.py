"""Writing missions: strokes on a board to one continuous pen-up / pen-down flight.

Paper 000 §4-5: the strokes are sampled densely, their turning points found
by split-and-merge, and one minimum-jerk B-spline is fitted through them with
the vehicle's limits. Here the whole mission -- take-off, approach, every
stroke, the lifts between strokes, retreat and landing -- is *one* smoothing
problem, so the trajectory is continuous up to jerk everywhere and starts and
ends at rest:

* stroke samples: point deviation with a high weight, the turning points with
  a higher one (corners stay sharp);
* lifts and transits: straight lines sampled every centimetre with a lower
  weight, so the smoothed path stays near them and never dips into the board;
* timing: one rest-to-rest profile along the whole polyline that slows to a
  stop at corners (:func:`~skyquill.optimize.timing.allocate_path_times`);
* if the limits cannot be met, or the pen-down path strays beyond the
  tolerance, the timing is stretched and the problem solved again -- the
  factor is reported.

With ``WritingOptions.target`` the flight is planned to fit a vehicle's
trajectory memory instead (:mod:`skyquill.calligraphy.budget`): one spline of
few long knot spans, or several flown one after another with hovers between.

The plan is of the brush tip; the vehicle flies it offset by the brush
(:meth:`Mission.vehicle_trajectory`). The pen is down (``pen = 1``) from a stroke's first
sample time to its last.

On a horizontal board the brush hangs along the thrust axis, so the tip swings
as the vehicle tilts to accelerate: it is at ``P + L (e_z - b3)`` for the
untilted tip ``P``, ``b3 = (a + g e_z) / |a + g e_z|`` (:func:`swung_tip`).
By default (``follow="tip"``) the strokes are fitted by that swung tip, which
is what leaves the ink: to first order its horizontal part is
``P_xy - (L / g) a_xy``, linear in the control points, so the QP's point
deviation carries that acceleration term
(:class:`~skyquill.optimize.PointDeviation`'s ``accel_gain``); the rest (the
second-order part, and the tip's rise ``L (1 - cos tilt)``, up to 6 mm at
2 m/s^2 with a 0.3 m brush) is taken off the targets by a fixed-point polish
(:data:`TIP_POLISH_PASSES` more solves). The pen-down targets lie the brush's
pressing depth below the surface; the lifts onto and off the board are held
and timed for the jerk limit (:func:`route_times`). The plan is kept only if
the ink it predicts -- one run of contact per stroke, pressed within the
bearing's travel -- is within the tolerance of the strokes
(:func:`~skyquill.calligraphy.fidelity.planned_ink`). ``follow="path"`` fits
the untilted tip (paper 000: the vehicle's path, offset by the brush), as on a
wall.

On a sky board (light painting) there is no brush: the pen is the vehicle's
light, so the tip is the vehicle (:func:`tip_offset` is zero), the lift is 0
(the transits stay in the plane) and paper 003 §5.3's plane-deviation cost
(``WritingOptions.plane_weight``) holds the flight on the plane from the first
stroke to the last, so the drawing keeps its shape seen from the side.

The work is split by job: :mod:`~skyquill.calligraphy.options` (the knobs),
:mod:`~skyquill.calligraphy.route` (the samples and their roles),
:mod:`~skyquill.calligraphy.timing` (when each sample is reached),
:mod:`~skyquill.calligraphy.allocation` (the fastest faithful timing),
:mod:`~skyquill.calligraphy.problem` (the smoothing problem),
:mod:`~skyquill.calligraphy.planning` (solve, measure, stretch, re-segment) and
:mod:`~skyquill.calligraphy.separation` (drones writing at once); this module
holds the flight (:class:`Mission`) and :func:`plan_writing`, and re-exports
the names users import from here.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np

from skyquill.calligraphy.allocation import plan_route
from skyquill.calligraphy.board import Board
from skyquill.calligraphy.fidelity import (
    BOARD_MARGIN_M,
    BOARD_THICKNESS_M,
    Contact,
    Deviation,
    swung_tip,
)
from skyquill.calligraphy.options import (
    PLANE_WEIGHT,
    SIZE_RANGE_M,
    TARGET_STRATEGIES,
    WritingOptions,
)
from skyquill.calligraphy.planning import (
    RoutePlan,
    fidelity,
    fidelity_error,
    logger,
    resegmented,
)
from skyquill.calligraphy.problem import MAX_SPANS
from skyquill.calligraphy.route import (
    LIFT,
    MAX_ROUTE_SAMPLES,
    TRANSIT,
    TRANSIT_SPACING_M,
    RouteSamples,
    build_route,
    check_route_size,
    densify,
    route_length,
    route_points,
    writing_end,
)
from skyquill.calligraphy.separation import check_separation
from skyquill.calligraphy.timing import (
    HOME_LEG_SPEED,
    LIFT_JERK_FACTOR,
    SETTLE_S,
    TIP_TIMING_ACC,
    route_times,
)
from skyquill.errors import InputError
from skyquill.io.trajectory_json import pen_down
from skyquill.limits import DerivativeLimit
from skyquill.optimize.solve import FitResult
from skyquill.strokes import Strokes
from skyquill.strokes.model import MAX_STROKES
from skyquill.trajectory import (
    PiecewisePolynomial,
    RestToRestSequence,
    SplineTrajectory,
    Trajectory,
)
from skyquill.validation import FloatArray, as_array
from skyquill.verify import Verification, verify

if TYPE_CHECKING:  # the simulator is imported only to fly
    from skyquill.calligraphy.budget import TargetPlan
    from skyquill.sim import ContactBoard

#: The names users import from here (the planning moved to modules by job).
__all__ = [
    "HOME_LEG_SPEED",
    "LIFT",
    "LIFT_JERK_FACTOR",
    "MAX_ALTITUDE_M",
    "MAX_INPUT_POINTS",
    "MAX_ROUTE_SAMPLES",
    "MAX_SPANS",
    "MAX_STROKES",
    "PLANE_WEIGHT",
    "PRESS_M",
    "SETTLE_S",
    "SIZE_RANGE_M",
    "TARGET_STRATEGIES",
    "TIP_TIMING_ACC",
    "TRANSIT",
    "TRANSIT_SPACING_M",
    "Mission",
    "RoutePlan",
    "RouteSamples",
    "WritingOptions",
    "check_reach",
    "check_separation",
    "contact_board",
    "densify",
    "fidelity",
    "fidelity_error",
    "initial_flight_time",
    "logger",
    "offset_trajectory",
    "plan_route",
    "plan_writing",
    "resegmented",
    "route_length",
    "route_times",
    "tip_offset",
]

#: Largest input a mission takes, points: a tablet at 200 Hz for 15 minutes.
MAX_INPUT_POINTS = 200_000
#: How far the vehicle's frame and propellers reach below its centre (on a
#: wall: in front of it), m. A shorter brush cannot reach the board: the
#: frame would touch it first.
FRAME_CLEARANCE_M = 0.05
#: The flight volume's ceiling, m above the ground (z = 0): the 120 m of the
#: small-drone rules (EU open category, FAA part 107).
MAX_ALTITUDE_M = 120.0


@dataclass(frozen=True)
class Mission:
    """A planned writing flight.

    Attributes
    ----------
    fits
        The engine's results, one per planned part of the flight in flight
        order (one unless the plan was split into uploads or strokes were
        appended).
    trajectory
        The brush-tip trajectory: the one fit's spline, or, split into
        uploads, a :class:`~skyquill.trajectory.RestToRestSequence` of the
        fits' splines with hovers between them, or, with strokes appended
        (:func:`~skyquill.calligraphy.incremental.append_stroke`), a
        :class:`~skyquill.trajectory.PiecewisePolynomial` continuous to the
        jerk where each part joins the last.
    board
        Where it writes.
    strokes_world
        The input strokes on the board, world frame, each (K, 3), m.
    pen_windows
        ``(t_start, t_end)`` of every stroke, s.
    deviation
        Fidelity of the pen-down path: of the swung tip in the board's plane
        when it is fitted (``options.follows_tip``), else of the planned tip
        in 3-D.
    time_scale
        Stretch applied to the initial timing (the largest over the parts).
    planning_time_s
        Wall time of the whole planning.
    options
        The options it was planned with.
    target
        How the plan fits ``options.target`` (strategy and uploads); ``None``
        without a target.
    contact
        The swung tip against the board when it is fitted; ``None`` otherwise.
    home
        Where the brush tip takes off and lands (3,), m; ``None`` when the
        flight starts and ends above the strokes.
    join_s
        When the writing ends -- the brush back up after the last stroke --
        where :func:`~skyquill.calligraphy.incremental.append_stroke` joins the
        next stroke; ``None`` for a flight split into uploads.
    """

    fits: tuple[FitResult, ...]
    trajectory: Trajectory
    board: Board
    strokes_world: tuple[FloatArray, ...]
    pen_windows: tuple[tuple[float, float], ...]
    deviation: Deviation
    time_scale: float
    planning_time_s: float
    options: WritingOptions
    target: TargetPlan | None = None
    contact: Contact | None = None
    home: FloatArray | None = None
    join_s: float | None = None

    @property
    def limits(self) -> tuple[DerivativeLimit, ...]:
        """The limits the engine imposed (the same on every part)."""
        return self.fits[0].problem.limits

    @cached_property
    def verification(self) -> Verification:
        """The dense check of the whole trajectory against :attr:`limits`."""
        if self.trajectory is self.fits[0].trajectory:
            return self.fits[0].verification
        return verify(self.trajectory, self.limits)

    def pen(self, t: FloatArray) -> FloatArray:
        """1.0 where the pen is down at times ``t`` (N,), else 0.0."""
        return pen_down(t, self.pen_windows)

    @property
    def brush_offset(self) -> FloatArray:
        """Vehicle position minus tip position (3,), m (zero on a sky board)."""
        return tip_offset(self.board, self.options)

    def tip(self, t: FloatArray) -> FloatArray:
        """Where the brush tip is at times ``t`` (N,): (N, 3), m.

        The swung tip when it is fitted (:func:`swung_tip`), else the planned one.
        """
        if self.options.follows_tip(self.board):
            return swung_tip(self.trajectory, t, self.options.brush.length_m)
        return self.trajectory.evaluate(t)

    def vehicle_trajectory(self) -> Trajectory:
        """The vehicle's trajectory: the tip's, offset by the brush along the board normal.

        A constant offset of every control point offsets the curve (partition
        of unity), so limits and smoothness are unchanged.
        """
        return offset_trajectory(self.trajectory, self.brush_offset)

    @property
    def faithful(self) -> bool:
        """Whether the pen-down path is within the tolerance (and the contact holds)."""
        held = self.contact is None or self.contact.holds
        return self.deviation.max_m <= self.options.tolerance and held

    def summary(self) -> dict[str, Any]:
        """Timing, the dense check, fidelity: a drone's entry in ``summary.json`` (SI units)."""
        check = self.verification
        entry = {
            "duration_s": self.trajectory.duration,
            "planning_time_s": self.planning_time_s,
            "limits": check.limits_report(),
            "max_speed": check.max_speed,
            "max_acc": list(check.max_acc),
            "max_jerk": list(check.max_jerk),
            "max_excess": check.max_excess,
            "deviation": self.deviation.as_dict(),
            "tolerance_m": self.options.tolerance,
            "faithful": self.faithful,
            "follow": "tip" if self.options.follows_tip(self.board) else "path",
            "strokes": len(self.strokes_world),
            "time_scale": self.time_scale,
        }
        if self.contact is not None:
            entry["contact"] = self.contact.as_dict()
        if self.target is not None:
            entry["target"] = self.target.as_dict()
        return entry


def tip_offset(board: Board, opts: WritingOptions) -> FloatArray:
    """Vehicle position minus pen-tip position (3,), m: the brush along the board's
    normal, or zero on a sky board (the pen is the vehicle's light)."""
    if not board.has_contact:
        return np.zeros(3)
    return np.asarray(opts.brush.length_m * board.normal)


def offset_trajectory(traj: Trajectory, offset: FloatArray) -> Trajectory:
    """``traj`` moved by ``offset`` (d,), m: a spline or a sequence of splines."""
    if isinstance(traj, SplineTrajectory):
        return SplineTrajectory(traj.control_points + offset, traj.degree, traj.duration)
    if isinstance(traj, RestToRestSequence):
        return RestToRestSequence(tuple(offset_trajectory(p, offset) for p in traj.pieces))
    if isinstance(traj, PiecewisePolynomial):
        coeffs = traj.coeffs.copy()
        coeffs[:, 0, :] += offset  # the constant term of each piece
        return PiecewisePolynomial(traj.breaks, coeffs, traj.yaw_coeffs)
    raise InputError(
        f"traj: got a {type(traj).__name__}, expected a SplineTrajectory, a "
        "PiecewisePolynomial or a RestToRestSequence of them"
    )


def initial_flight_time(
    strokes: Strokes, board: Board, opts: WritingOptions, home: FloatArray | None = None
) -> float:
    """The flight time :func:`plan_writing` starts from, s, in milliseconds and without a solve.

    The route of ``strokes`` (scaled to ``opts.size_m``) on ``board`` from and to
    the vehicle's ``home`` (3,), m, timed with the limits
    (:func:`~skyquill.calligraphy.timing.route_times`): a lower bound of the
    planned duration -- the time allocation only slows the writing from there
    (:mod:`skyquill.calligraphy.allocation`) and re-segmentation keeps the
    total -- and the planned duration itself when the first timing is faithful
    (``Mission.time_scale == 1``: most characters at the CLI's limits). Without
    a target. A route above :data:`MAX_ROUTE_SAMPLES` is refused as by
    :func:`plan_writing`.
    """
    home_pos = None if home is None else as_array("home", home, shape=(3,))
    if home_pos is not None:
        home_pos = home_pos - tip_offset(board, opts)  # the tip's home
    scaled = strokes.scaled(opts.size_m)
    strokes_world = tuple(board.to_world(path) for path in scaled.paths)
    check_route_size(strokes_world, board, home_pos)
    points, roles = route_points(strokes_world, board, home_pos)
    return float(route_times(points, roles, board, opts)[-1])


def check_reach(board: Board, opts: WritingOptions) -> None:
    """Refuse a brush or a board the vehicle cannot write with.

    The brush must reach past the frame (:data:`FRAME_CLEARANCE_M`), and the
    writing must lie in the flight volume: above the ground, with the vehicle
    (the brush's length above a horizontal board, plus the lift) below
    :data:`MAX_ALTITUDE_M`.
    """
    length = opts.brush.length_m
    if board.has_contact and length < FRAME_CLEARANCE_M:
        raise InputError(
            f"brush length_m: got {length:g} m, expected at least {FRAME_CLEARANCE_M:g} m "
            "(a shorter brush cannot reach the board past the vehicle's frame)"
        )
    bottom = float(board.origin[2])
    # The highest the vehicle goes: a lift above a horizontal board, a wall's
    # top, a sky board's top corner (plus a lift that rises with its normal).
    if board.kind == "horizontal":
        top = bottom + length + board.lift_m
    else:
        rise = np.maximum(board.axes[:, 2], 0.0)  # how much e_u, e_v and n climb
        top = bottom + opts.size_m * float(rise[0] + rise[1]) + board.lift_m * float(rise[2])
    if bottom <= 0.0 or top > MAX_ALTITUDE_M:
        raise InputError(
            f"board: got the writing from {bottom:g} m up, the vehicle up to {top:g} m, "
            f"expected both within the flight volume, above the ground (z > 0) and below "
            f"{MAX_ALTITUDE_M:g} m"
        )


def plan_writing(
    strokes: Strokes,
    board: Board | None = None,
    options: WritingOptions | None = None,
    home: FloatArray | None = None,
) -> Mission:
    """Plan one continuous writing flight of ``strokes`` on ``board``.

    Parameters
    ----------
    strokes
        The input, any units (scaled so that its larger side is ``size_m``).
    board
        Writing surface (default: horizontal at 1 m).
    options
        :class:`WritingOptions`.
    home
        The vehicle's take-off and landing position (3,), m (the tip hangs
        ``options.brush.length_m`` below it); ``None`` starts and ends hovering above
        the first and last stroke.

    Raises
    ------
    InputError
        A brush or board the vehicle cannot write with (:func:`check_reach`),
        more than :data:`MAX_INPUT_POINTS` points or :data:`MAX_STROKES` strokes, a
        route of more than :data:`MAX_ROUTE_SAMPLES` samples (estimated by
        :func:`route_length` before it is built) or a solve of more than
        :data:`MAX_SPANS` knot spans (before it is assembled).
    InfeasibleError
        The limits cannot be met, or the pen-down path stays beyond the
        tolerance, even after ``max_stretches`` stretches; with
        ``options.target``, no way of fitting its uploads does
        (:func:`skyquill.calligraphy.budget.plan_for_target`).
    """
    start = time.perf_counter()
    if strokes.n_points > MAX_INPUT_POINTS:
        raise InputError(
            f"strokes: got {strokes.n_points:,} points, expected at most {MAX_INPUT_POINTS:,} "
            "(resample the input: a 0.5 m character needs a few hundred)"
        )
    if len(strokes.paths) > MAX_STROKES:
        raise InputError(
            f"strokes: got {len(strokes.paths):,} strokes, expected at most {MAX_STROKES:,} "
            "(split the text between drones or missions)"
        )
    opts = options or WritingOptions()
    board = board or Board()
    check_reach(board, opts)
    home_pos = None if home is None else as_array("home", home, shape=(3,))
    if home_pos is not None:
        home_pos = home_pos - tip_offset(board, opts)  # the tip's home
    scaled = strokes.scaled(opts.size_m)
    strokes_world = tuple(board.to_world(path) for path in scaled.paths)
    threshold = opts.turning_threshold_m or 0.25 * opts.tolerance
    samples = build_route(strokes_world, board, home_pos, threshold)
    if opts.target is not None:
        # budget builds on this module's route planning, hence imported here.
        from skyquill.calligraphy.budget import plan_for_target

        return plan_for_target(samples, board, opts, start)
    plan = plan_route(samples, board, opts)
    if not plan.faithful(opts) and not opts.best_effort:
        raise fidelity_error(plan, opts)
    if opts.resegment != "off" and opts.resegment_iterations > 0:
        plan = resegmented(samples, plan, board, opts)
    return Mission(
        (plan.fit,),
        plan.fit.trajectory,
        board,
        strokes_world,
        plan.windows,
        plan.deviation,
        plan.scale,
        time.perf_counter() - start,
        opts,
        contact=plan.contact,
        home=home_pos,
        join_s=float(plan.times[writing_end(samples.roles)]),
    )


#: How far the simulated board is raised into the planned tip's path when the
#: path is fitted (``follow="path"``), m: that plan touches the surface, so
#: without it tracking errors would lift the brush off.
PRESS_M = 0.002


def contact_board(mission: Mission) -> ContactBoard | None:
    """The simulator's board under a horizontal writing board (``None`` for a wall).

    With the swung tip fitted the plan presses the brush into the surface
    itself (``brush.press_depth_m``), so the simulated board is the surface;
    with the path fitted it sits :data:`PRESS_M` higher. The simulator's
    contact model is a horizontal slab only.
    """
    from skyquill.sim import ContactBoard

    if mission.board.kind != "horizontal":
        return None
    corner, size, margin = mission.board.origin, mission.options.size_m, BOARD_MARGIN_M
    raised = 0.0 if mission.options.follows_tip(mission.board) else PRESS_M
    return ContactBoard(
        height_m=float(corner[2]) + raised,
        stiffness_n_per_m=mission.options.brush.stiffness_n_per_m,
        damping_ns_per_m=mission.options.brush.damping_ns_per_m,
        thickness_m=BOARD_THICKNESS_M,
        extent=(corner[0] - margin, corner[0] + size + margin,
                corner[1] - margin, corner[1] + size + margin),
    )  # fmt: skip
