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
"""

from __future__ import annotations

import itertools
import logging
import math
import time
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.brush import Brush
from skyquill.calligraphy.fidelity import (
    BOARD_MARGIN_M,
    BOARD_THICKNESS_M,
    GRAVITY,
    Contact,
    Deviation,
    contact_runs,
    measure_deviation,
    planned_ink,
    swung_tip,
)
from skyquill.errors import InfeasibleError, InputError
from skyquill.io.trajectory_json import pen_down
from skyquill.limits import DerivativeLimit, VehicleLimits
from skyquill.optimize import (
    Boundary,
    PlaneDeviation,
    PointDeviation,
    SmoothingProblem,
    resegment,
    solve,
)
from skyquill.optimize.solve import FitResult
from skyquill.optimize.timing import allocate_path_times
from skyquill.optimize.workspace import Workspace
from skyquill.strokes import Strokes, turning_points
from skyquill.strokes.model import MAX_STROKES
from skyquill.targets import Strategy as TargetStrategy
from skyquill.targets import UploadTarget
from skyquill.trajectory import RestToRestSequence, SplineTrajectory, Trajectory
from skyquill.validation import FloatArray, as_array, as_float, as_int
from skyquill.verify import Verification, verify

if TYPE_CHECKING:  # the simulator is imported only to fly
    from skyquill.calligraphy.budget import TargetPlan
    from skyquill.sim import ContactBoard

#: One DEBUG record per solve of a route (a progress display listens: the studio).
logger = logging.getLogger(__name__)

#: Spacing of the samples that hold lifts and transits near their straight lines, m.
TRANSIT_SPACING_M = 0.01
#: Route roles of the samples that are not on a stroke (those carry the stroke's
#: index): the brush going straight down to a stroke or up from it, and the
#: moves between, above the board.
LIFT, TRANSIT = -2, -1
#: Largest input a mission takes, points: a tablet at 200 Hz for 15 minutes.
MAX_INPUT_POINTS = 200_000
#: Character sizes accepted, m. Below 1 cm a character is narrower than a brush
#: stroke and its 1 % tolerance (0.1 mm) is finer than a quadrotor's position
#: estimate (motion capture: ~1 mm), so "within tolerance" would mean nothing;
#: above 20 m the route (sampled every TRANSIT_SPACING_M) and the flight grow
#: past a board and a battery: that is sky writing, not calligraphy.
SIZE_RANGE_M = (0.01, 20.0)
#: Most route samples (stroke points plus lifts and transits every
#: TRANSIT_SPACING_M), estimated from the route's length before it is built:
#: each is a row of the QP's deviation block (~1 kB with its factors).
MAX_ROUTE_SAMPLES = 400_000
#: Most knot spans of one solve, checked before each assembly: 3 x (spans + 5)
#: unknowns and a hull block per span and limit; 20 000 spans is 1000 s of
#: flight at the default 0.05 s, and ~1 GB of KKT factors.
MAX_SPANS = 20_000
#: How far the vehicle's frame and propellers reach below its centre (on a
#: wall: in front of it), m. A shorter brush cannot reach the board: the
#: frame would touch it first.
FRAME_CLEARANCE_M = 0.05
#: The flight volume's ceiling, m above the ground (z = 0): the 120 m of the
#: small-drone rules (EU open category, FAA part 107).
MAX_ALTITUDE_M = 120.0
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
#: Plans whose first-order tip is beyond this many tolerances are not polished.
POLISH_WITHIN = 1.2
#: Solves after the first that take the swung tip's second-order part off the
#: targets (``follow="tip"``): the part is ~1e-4 m horizontally and the tip's
#: rise (<= L amax^2 / 2 g^2) vertically, and each pass shrinks what is left by
#: about that ratio again, so two leave well under 0.1 mm.
TIP_POLISH_PASSES = 2
#: How fast the pen-down deviation falls with the timing stretch, ``deviation ~ scale^-p``,
#: taken on the fast side of what is measured (p ~ 3.1) so that a predicted stretch never
#: overshoots (:func:`_stretches_needed`).
DEVIATION_EXPONENT = 3.5
#: Weight of the plane-deviation cost on a sky board (paper 003 §5.3), per control
#: point active from the first stroke to the last, against the jerk cost and the
#: stroke samples' 1e4 each (~5 per knot span at 1 m/s). Measured
#: (bench/sky_distortion.py, bench/results/sky_distortion.json): on "light" on a
#: board at yaw 30°, tilt 20°, the largest distance off the plane falls from
#: 1.43 mm (0) to 1.28, 0.79, 0.34, 0.12 mm at 1e3, 1e4, 1e5, 1e6, with the same
#: flight time and in-plane fidelity; on paper 003's M with per-axis limits from
#: 48.8 mm to 30, 20, 5.8, 0.9 mm, but above 1e5 the M misses its vertices by
#: more (82.7 -> 84.8 mm): 1e5 keeps the drawing within a millimetre of the
#: plane without trading the strokes for it.
PLANE_WEIGHT = 1e5
#: The ways to fit a vehicle's upload budget (:mod:`skyquill.calligraphy.budget`).
TARGET_STRATEGIES: tuple[TargetStrategy, ...] = ("one-upload", "split")


@dataclass(frozen=True)
class WritingOptions:
    """Knobs of :func:`plan_writing` (SI units).

    Attributes
    ----------
    size_m
        The strokes' larger side is scaled to this, m, within
        :data:`SIZE_RANGE_M` (paper 000: 0.5 m boards).
    limits
        The vehicle's limits (``vmax`` the speed, ``amax`` and ``jmax`` the
        norms; per-axis boxes only as ``*_axis``).
    norm_sides
        ``None``: norms held exactly (second-order cones); an integer ``m``: by
        the inscribed polytope with ``m`` sides.
    tolerance_m
        Fidelity tolerance; ``None``: 1 % of ``size_m``.
    turning_threshold_m
        Split-and-merge threshold; ``None``: a quarter of the tolerance.
    data_weight, turning_weight, transit_weight, lift_weight
        Weights of the stroke samples, turning points, transit samples and
        (fitting the tip) the samples of the brush's lifts onto and off the
        board, against the jerk cost.
    knot_interval
        Seconds per knot span.
    degree
        Spline degree.
    brush
        The brush: its length (tip to vehicle, along the board normal when
        level), the bearing's travel and the pressing depth that sets the
        stroke width (:class:`~skyquill.calligraphy.brush.Brush`).
    follow
        What is fitted to the strokes on a horizontal board: ``"tip"`` (the
        default) the swung brush tip, which leaves the ink (module
        docstring); ``"path"`` the untilted tip, i.e. the vehicle's path
        offset by the brush (paper 000), which is faster to plan and leaves
        the ink up to a few centimetres off at these limits. A wall is
        always written by the path (the brush is not hanging there).
    resegment
        Time re-segmentation after the first feasible, faithful plan (paper
        000 §5.4): ``"fixed"`` keeps the total time, ``"free"`` lets it move
        at a time penalty that makes the initial total time stationary under
        uniform scaling (without a penalty the jerk cost falls for ever as
        time grows); ``"off"`` skips it.
    resegment_iterations
        Descent steps at most (each is one solve and one analytic gradient).
    stretch_factor, max_stretches
        Timing stretch when infeasible or unfaithful.
    best_effort
        Return the last plan even when its pen-down path is beyond the
        tolerance (``Mission.faithful`` is then False); by default that is an
        :class:`~skyquill.errors.InfeasibleError` with the measured deviation.
    target
        Plan for a vehicle's trajectory memory (``--target``): splines of the
        target's degree (``degree`` is then ignored), at most
        :attr:`~skyquill.targets.UploadTarget.max_pieces` knot spans per
        upload, uploads changed at rest with a hover between them
        (:mod:`skyquill.calligraphy.budget`). ``None``: one spline at
        ``knot_interval``.
    target_strategies
        The ways to fit ``target`` tried, in order (default
        :data:`TARGET_STRATEGIES`, cheapest flight first): ``"one-upload"`` and
        ``"split"``; one alone measures it (the budget benchmark).
    plane_weight
        On a sky board, the weight of paper 003's plane-deviation cost (§3.3.3,
        §5.3) that keeps the flight on the board's plane from the first stroke
        to the last, so the drawing is not distorted seen from the side
        (default :data:`PLANE_WEIGHT`); 0 disables it. Unused on other boards.
    """

    size_m: float = 0.5
    limits: VehicleLimits = field(default_factory=lambda: VehicleLimits(1.0, 2.0, 10.0))
    norm_sides: int | None = None
    tolerance_m: float | None = None
    turning_threshold_m: float | None = None
    data_weight: float = 1e4
    turning_weight: float = 1e5
    transit_weight: float = 1e2
    lift_weight: float = 1e4
    knot_interval: float = 0.05
    degree: int = 5
    brush: Brush = field(default_factory=Brush)
    follow: Literal["tip", "path"] = "tip"
    resegment: Literal["off", "fixed", "free"] = "fixed"
    resegment_iterations: int = 8
    stretch_factor: float = 1.25
    max_stretches: int = 8
    best_effort: bool = False
    target: UploadTarget | None = None
    target_strategies: tuple[TargetStrategy, ...] = TARGET_STRATEGIES
    plane_weight: float = PLANE_WEIGHT

    def __post_init__(self) -> None:
        if not isinstance(self.limits, VehicleLimits):
            raise InputError(f"limits: got {type(self.limits).__name__}, expected VehicleLimits")
        if not isinstance(self.brush, Brush):
            raise InputError(f"brush: got {type(self.brush).__name__}, expected Brush")
        if self.follow not in ("tip", "path"):
            raise InputError(f"follow: got {self.follow!r}, expected 'tip' or 'path'")
        if self.target is not None and not isinstance(self.target, UploadTarget):
            raise InputError(
                f"target: got {type(self.target).__name__}, expected UploadTarget or None"
            )
        strategies = tuple(self.target_strategies)
        if (
            not strategies
            or len(set(strategies)) < len(strategies)
            or not set(strategies) <= set(TARGET_STRATEGIES)
        ):
            raise InputError(
                f"target_strategies: got {strategies!r}, expected some of "
                f"{TARGET_STRATEGIES!r}, each once"
            )
        self.limits.timing_bounds()  # the route is timed with a speed and an acceleration
        for name in ("size_m", "knot_interval", "stretch_factor"):
            as_float(name, getattr(self, name), positive=True)
        weights = ("data_weight", "turning_weight", "transit_weight", "lift_weight", "plane_weight")
        for name in weights:
            as_float(name, getattr(self, name), nonneg=True)
        low, high = SIZE_RANGE_M
        if not low <= self.size_m <= high:
            raise InputError(
                f"size_m: got {self.size_m:g} m, expected {low:g} to {high:g} m (a character "
                "legible with a brush, within the position accuracy, on one board)"
            )
        for name in ("tolerance_m", "turning_threshold_m"):
            if getattr(self, name) is not None:
                as_float(name, getattr(self, name), positive=True)
        if self.norm_sides is not None:
            as_int("norm_sides", self.norm_sides, low=3, high=1024)
        as_int("degree", self.degree, low=3, high=7)
        # Each stretch and each descent step is one more solve (bounded work).
        as_int("max_stretches", self.max_stretches, low=0, high=50)
        as_int("resegment_iterations", self.resegment_iterations, low=0, high=100)
        if self.resegment not in ("off", "fixed", "free"):
            raise InputError(
                f"resegment: got {self.resegment!r}, expected 'off', 'fixed' or 'free'"
            )
        if self.stretch_factor <= 1.0:
            raise InputError(f"stretch_factor: got {self.stretch_factor:g}, expected > 1")

    @property
    def tolerance(self) -> float:
        """Fidelity tolerance, m."""
        return self.tolerance_m if self.tolerance_m is not None else 0.01 * self.size_m

    def derivative_limits(self) -> tuple[DerivativeLimit, ...]:
        """The vehicle limits in 3-D, as the engine imposes them."""
        return self.limits.derivative_limits(3, sides=self.norm_sides)

    def follows_tip(self, board: Board) -> bool:
        """Whether the swung tip is fitted on ``board`` (``follow="tip"``, horizontal, a brush)."""
        return self.follow == "tip" and board.kind == "horizontal" and self.brush.length_m > 0

    def tip_gain(self, board: Board) -> FloatArray | None:
        """The swung tip's acceleration gain ``(-L/g, -L/g, 0)``, s^2; ``None`` for the path."""
        if not self.follows_tip(board):
            return None
        c = -self.brush.length_m / GRAVITY
        return np.array([c, c, 0.0])


@dataclass(frozen=True)
class Mission:
    """A planned writing flight.

    Attributes
    ----------
    fits
        The engine's results, one per planned part of the flight in flight
        order (one unless the plan was split into uploads).
    trajectory
        The brush-tip trajectory: the one fit's spline, or, split into
        uploads, a :class:`~skyquill.trajectory.RestToRestSequence` of the
        fits' splines with hovers between them.
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
    raise InputError(
        f"traj: got a {type(traj).__name__}, expected a SplineTrajectory or a "
        "RestToRestSequence of them"
    )


def _segment(a: FloatArray, b: FloatArray) -> FloatArray:
    """Samples of the straight line from ``a`` to ``b`` (excluding ``a``), every 1 cm."""
    n = max(1, math.ceil(float(np.linalg.norm(b - a)) / TRANSIT_SPACING_M))
    return np.asarray(a + np.outer(np.arange(1, n + 1) / n, b - a))


def densify(polyline: FloatArray, spacing: float = TRANSIT_SPACING_M) -> FloatArray:
    """``polyline`` (K, 3) with points inserted so no gap exceeds ``spacing``; vertices kept.

    Sparse input (a straight stroke given by its two ends) would leave the
    spline free between samples; dense samples hold it to the line.
    """
    out = [polyline[:1]]
    for a, b in itertools.pairwise(polyline):
        out.append(_segment(a, b) if np.linalg.norm(b - a) > spacing else b[None, :])
    return np.vstack(out)


@dataclass
class _Route:
    """The mission polyline with a role per sample: stroke index, ``TRANSIT`` or ``LIFT``."""

    points: list[FloatArray] = field(default_factory=list)
    role: list[FloatArray] = field(default_factory=list)

    def add(self, points: FloatArray, role: int) -> None:
        self.points.append(points)
        self.role.append(np.full(len(points), role))

    def add_stroke(self, points: FloatArray, role: int) -> None:
        """Add a stroke's samples; with no lift (a sky board) the transit ends on its
        first point, and that sample becomes the stroke's (times must increase)."""
        if np.linalg.norm(points[0] - self.points[-1][-1]) < 1e-9:
            self.points[-1], self.role[-1] = self.points[-1][:-1], self.role[-1][:-1]
        self.add(points, role)

    def go_to(self, target: FloatArray, include_target: bool = True, role: int = -1) -> None:
        if np.linalg.norm(target - self.points[-1][-1]) < 1e-9:
            return  # already there: no repeated sample (times must increase)
        line = _segment(self.points[-1][-1], target)
        self.add(line if include_target else line[:-1], role)


def _route(
    strokes_world: tuple[FloatArray, ...], board: Board, home: FloatArray | None
) -> tuple[FloatArray, FloatArray]:
    """All samples (N, 3) and their roles (N,): take-off, strokes with lifts, landing."""
    lift = board.lift_m * board.normal
    route = _Route()
    first = strokes_world[0][0] + lift
    if home is not None:
        route.add(home[None, :], -1)
        route.go_to(np.array([home[0], home[1], first[2]]))  # climb straight up
        route.go_to(first)
    else:
        route.add(first[None, :], -1)
    for i, stroke in enumerate(strokes_world):
        route.go_to(stroke[0] + lift)
        # Touch down on the stroke's first point, lift straight up from its last.
        route.go_to(stroke[0], include_target=False, role=LIFT)
        route.add_stroke(densify(stroke), i)
        route.go_to(stroke[-1] + lift, role=LIFT)
    if home is not None:
        route.go_to(np.array([home[0], home[1], route.points[-1][-1][2]]))
        route.go_to(home)
    return np.vstack(route.points), np.concatenate(route.role)


def route_length(
    strokes_world: tuple[FloatArray, ...], board: Board, home: FloatArray | None
) -> float:
    """An upper estimate of the route's length, m, without building it.

    Strokes, two lifts per stroke, the transits between strokes and, with a
    ``home`` (3,), the legs to and from it (taxicab: climb, then fly).
    """
    ends = [(s[0], s[-1]) for s in strokes_world]
    drawn = sum(float(np.linalg.norm(np.diff(s, axis=0), axis=1).sum()) for s in strokes_world)
    moves = sum(float(np.linalg.norm(b[0] - a[1])) for a, b in itertools.pairwise(ends))
    legs = 0.0
    if home is not None:
        legs = float(np.abs(ends[0][0] - home).sum() + np.abs(ends[-1][1] - home).sum())
    return drawn + moves + legs + 2.0 * len(strokes_world) * board.lift_m


def initial_flight_time(
    strokes: Strokes, board: Board, opts: WritingOptions, home: FloatArray | None = None
) -> float:
    """The flight time :func:`plan_writing` starts from, s, in milliseconds and without a solve.

    The route of ``strokes`` (scaled to ``opts.size_m``) on ``board`` from and to
    the vehicle's ``home`` (3,), m, timed by :func:`route_times`: the plan's
    duration when the first timing needs no stretch (a pre-plan estimate: the
    studio's). A route above :data:`MAX_ROUTE_SAMPLES` is refused as by
    :func:`plan_writing`.
    """
    home_pos = None if home is None else as_array("home", home, shape=(3,))
    if home_pos is not None:
        home_pos = home_pos - tip_offset(board, opts)  # the tip's home
    scaled = strokes.scaled(opts.size_m)
    strokes_world = tuple(board.to_world(path) for path in scaled.paths)
    _check_route_size(strokes_world, board, home_pos)
    points, roles = _route(strokes_world, board, home_pos)
    return float(route_times(points, roles, board, opts)[-1])


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


def _check_route_size(
    strokes_world: tuple[FloatArray, ...], board: Board, home: FloatArray | None
) -> None:
    """Refuse a route of more than :data:`MAX_ROUTE_SAMPLES` samples before building it."""
    length = route_length(strokes_world, board, home)
    n_points = sum(len(s) for s in strokes_world)
    samples = length / TRANSIT_SPACING_M + n_points
    if samples > MAX_ROUTE_SAMPLES:
        raise InputError(
            f"strokes: got a route of about {length:.4g} m ({samples:.3g} samples, one every "
            f"{100 * TRANSIT_SPACING_M:g} cm), expected at most {MAX_ROUTE_SAMPLES:,} samples, "
            f"i.e. about {MAX_ROUTE_SAMPLES * TRANSIT_SPACING_M / 1e3:g} km (a smaller size_m, "
            "lift_m, a home nearer the board or fewer strokes)"
        )


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
    _check_route_size(strokes_world, board, home_pos)
    points, roles = _route(strokes_world, board, home_pos)
    times = route_times(points, roles, board, opts)
    threshold = opts.turning_threshold_m or 0.25 * opts.tolerance
    corners = _turning_samples(strokes_world, board, points, roles, threshold)
    samples = RouteSamples(points, roles, corners, strokes_world)
    if opts.target is not None:
        # budget builds on this module's route planning, hence imported here.
        from skyquill.calligraphy.budget import plan_for_target

        return plan_for_target(samples, times, board, opts, start)
    plan = plan_route(samples, times, board, opts)
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
    )


@dataclass(frozen=True)
class RouteSamples:
    """A route to fly: samples (N, 3), roles (N,), corner indices, the input strokes.

    ``roles[i]`` is the index into ``strokes_world`` of the stroke sample ``i``
    belongs to, or -1 for lifts and transits; ``max_spans`` caps the knot spans
    of its spline (``None``: as many as ``knot_interval`` asks). ``workspace``
    carries the assembly and the QP setup from one solve of the route to the
    next (stretches, re-segmentation steps): only the times change between them.
    """

    points: FloatArray
    roles: FloatArray
    corners: FloatArray
    strokes_world: tuple[FloatArray, ...]
    max_spans: int | None = None
    workspace: Workspace = field(default_factory=Workspace, compare=False, repr=False)


@dataclass(frozen=True)
class RoutePlan:
    """One spline along a route and how well it writes.

    Attributes
    ----------
    fit
        The engine's result.
    windows
        Pen-down ``(t_start, t_end)`` per stroke, s.
    deviation, contact
        Fidelity (:func:`fidelity`); ``contact`` is ``None`` unless the swung
        tip is fitted.
    scale
        Stretch of the initial timing.
    times
        Sample times, (N,), s.
    targets
        What the samples were fitted to, (N, 3), m: the route itself, or with
        the swung tip fitted, the route pressed into the board and polished
        against the swing's second-order part.
    """

    fit: FitResult
    windows: tuple[tuple[float, float], ...]
    deviation: Deviation
    scale: float
    times: FloatArray
    targets: FloatArray
    contact: Contact | None

    def faithful(self, opts: WritingOptions) -> bool:
        """Whether the pen-down path is within ``opts.tolerance`` (and the contact holds)."""
        held = self.contact is None or self.contact.holds
        return self.deviation.max_m <= opts.tolerance and held


def plan_route(
    samples: RouteSamples, times: FloatArray, board: Board, opts: WritingOptions
) -> RoutePlan:
    """One rest-to-rest spline along ``samples`` at ``times`` over ``board``, stretched to fit.

    The timing is stretched by ``opts.stretch_factor`` while the limits cannot
    be met or the plan is not faithful (:meth:`RoutePlan.faithful`), at most
    ``opts.max_stretches`` times; the last plan is returned even if it is not
    faithful (the caller decides). No re-segmentation (:func:`resegmented`).

    Raises
    ------
    InfeasibleError
        The limits cannot be met even after ``max_stretches`` stretches.
    """
    scale, stretches = 1.0, 0
    while True:
        last = stretches >= opts.max_stretches
        logger.debug("solving at %.3gx the first timing (stretch %d)", scale, stretches)
        try:
            plan = _plan_at(samples, times * scale, board, opts, scale)
        except InfeasibleError:
            if last:
                raise
            scale, stretches = scale * opts.stretch_factor, stretches + 1
            continue
        if plan.faithful(opts) or last:
            return plan
        # Slower: less tracking error and less brush swing. Skip the stretches
        # that cannot reach the tolerance (a contact that fails: one at a time).
        off = plan.deviation.max_m
        k = _stretches_needed(off, opts) if off > opts.tolerance else 1
        k = min(k, opts.max_stretches - stretches)
        scale, stretches = scale * opts.stretch_factor**k, stretches + k


def _stretches_needed(deviation_m: float, opts: WritingOptions) -> int:
    """Stretches predicted to bring ``deviation_m`` within the tolerance (at least 1).

    The pen-down deviation falls about as ``scale^-p`` with ``p ~ 3.1`` (it
    halves per x1.25 on the bundled characters: 永 12.3 -> 6.1 -> 4.2 mm). The
    prediction uses :data:`DEVIATION_EXPONENT` = 3.5, a faster fall than seen,
    so it predicts too few stretches rather than too many: the plan lands on
    the same stretch as one step at a time, with the attempts between skipped.
    """
    per_stretch = DEVIATION_EXPONENT * math.log(opts.stretch_factor)
    return max(1, math.ceil(math.log(deviation_m / opts.tolerance) / per_stretch))


def fidelity_error(plan: RoutePlan, opts: WritingOptions) -> InfeasibleError:
    """The error for a plan that stays unfaithful (beyond the tolerance, or out of contact)."""
    what = "the swung brush tip" if plan.contact is not None else "the pen-down path"
    if plan.deviation.max_m > opts.tolerance or plan.contact is None:
        problem = (
            f"{what} stays {1e3 * plan.deviation.max_m:.3g} mm from the input, expected "
            f"within the tolerance of {1e3 * opts.tolerance:.3g} mm (1 % of the size "
            "unless tolerance_m is given)"
        )
    else:
        c = plan.contact
        problem = (
            f"{what} leaves {c.ink_strokes} ink strokes for {c.strokes} strokes, pressed up "
            f"to {1e3 * c.max_depth_m:.3g} mm, expected one ink stroke per stroke within the "
            f"brush's travel of {1e3 * c.travel_m:.3g} mm"
        )
    return InfeasibleError(
        f"strokes: {problem}, after {opts.max_stretches} stretches ({plan.scale:.3g}x slower) "
        f"within {opts.limits.describe()}; a larger size, a lower speed limit (the route is "
        "timed by it) or best_effort",
        ("fidelity",),
    )


def resegmented(
    samples: RouteSamples, plan: RoutePlan, board: Board, opts: WritingOptions
) -> RoutePlan:
    """``plan`` after time re-segmentation (paper 000 §5.4), if that keeps it faithful.

    The targets stay those of ``plan`` (the polish's corrections are of second
    order in the swing and move little with the times); fidelity and contact
    are measured again, and ``plan`` is kept if the result is less faithful.
    """
    n_ctrl = plan.fit.trajectory.control_points.shape[0]
    gain = opts.tip_gain(board)

    def make(ts: FloatArray) -> SmoothingProblem:
        return _problem(samples, plan.targets, ts, opts, gain=gain, n_ctrl=n_ctrl, board=board)

    penalty = 0.0
    if opts.resegment == "free":
        # Uniform scaling by k multiplies the jerk energy by k^-5: this rho
        # makes the current total time stationary, so the descent trades time
        # between segments and moves the total only where that pays.
        penalty = 5.0 * plan.fit.cost_terms["smoothness"] / float(plan.times[-1])
    logger.debug("re-segmenting the times (up to %d steps)", opts.resegment_iterations)
    try:
        result = resegment(
            samples.points,
            plan.times,
            make,
            mode="free" if opts.resegment == "free" else "fixed",
            time_penalty=penalty,
            max_iter=opts.resegment_iterations,
            initial_result=plan.fit,  # the plan just made at these times: not solved again
            workspace=samples.workspace,
            interior=True,  # each conic solve costs 10-50 closed forms
        )
    except InfeasibleError:
        return plan
    new = _measured(
        samples, result.result, result.times, plan.targets, board=board, opts=opts, scale=plan.scale
    )
    if not new.faithful(opts) and plan.faithful(opts):
        return plan  # never trade fidelity for smoothness
    if new.deviation.max_m > max(opts.tolerance, plan.deviation.max_m):
        return plan
    return new


def _plan_at(
    samples: RouteSamples, times: FloatArray, board: Board, opts: WritingOptions, scale: float
) -> RoutePlan:
    """Solve at ``times``; with the swung tip fitted, polish the targets against the swing."""
    gain = opts.tip_gain(board)
    if gain is None:
        problem = _problem(samples, samples.points, times, opts, board=board)
        fit = solve(problem, workspace=samples.workspace)
        return _measured(samples, fit, times, samples.points, board=board, opts=opts, scale=scale)
    pressed = samples.points - _press(samples, board, opts)
    targets = pressed
    fit = solve(_problem(samples, targets, times, opts, gain=gain), workspace=samples.workspace)
    windows = _pen_windows(samples.roles, times, len(samples.strokes_world))
    first = measure_deviation(
        fit.trajectory, windows, samples.strokes_world, opts.brush.length_m, plane=board
    )
    # The polish moves the tip by the model's second-order part (~0.1 mm in the
    # plane): a plan this far off is stretched without it.
    if first.max_m <= POLISH_WITHIN * opts.tolerance:
        # Each pass takes what the first-order model misses (measured on the
        # last fit) off the pressed targets.
        n_ctrl = fit.trajectory.control_points.shape[0]
        for _ in range(TIP_POLISH_PASSES):
            targets = pressed - _model_error(fit.trajectory, times, gain, opts.brush.length_m)
            problem = _problem(samples, targets, times, opts, gain=gain, n_ctrl=n_ctrl)
            fit = solve(problem, workspace=samples.workspace)
    return _measured(samples, fit, times, targets, board=board, opts=opts, scale=scale)


def _press(samples: RouteSamples, board: Board, opts: WritingOptions) -> FloatArray:
    """How far each target goes into the board (N, 3): the pressing depth on stroke samples."""
    depth = np.where(samples.roles >= 0, opts.brush.press_depth_m, 0.0)
    return np.asarray(depth[:, None] * board.normal)


def _model_error(traj: Trajectory, t: FloatArray, gain: FloatArray, length: float) -> FloatArray:
    """The swung tip minus its first-order model ``P + c a`` at times ``t`` (N, 3), m."""
    model = traj.evaluate(t) + gain * traj.evaluate(t, 2)
    return np.asarray(swung_tip(traj, t, length) - model)


def _measured(
    samples: RouteSamples,
    fit: FitResult,
    times: FloatArray,
    targets: FloatArray,
    *,
    board: Board,
    opts: WritingOptions,
    scale: float,
) -> RoutePlan:
    windows = _pen_windows(samples.roles, times, len(samples.strokes_world))
    deviation, contact = fidelity(fit.trajectory, windows, samples.strokes_world, board, opts)
    return RoutePlan(fit, windows, deviation, scale, times, targets, contact)


def fidelity(
    traj: Trajectory,
    windows: tuple[tuple[float, float], ...],
    strokes_world: tuple[FloatArray, ...],
    board: Board,
    opts: WritingOptions,
) -> tuple[Deviation, Contact | None]:
    """How well ``traj`` (the untilted tip) writes the strokes.

    With the swung tip fitted (``opts.follows_tip``): the ink the plan leaves
    (:func:`planned_ink`) against the strokes, in the board's plane, and its
    :class:`Contact`. Otherwise the planned tip's 3-D distance over the pen
    windows, and no contact.
    """
    if not opts.follows_tip(board):
        return measure_deviation(traj, windows, strokes_world), None
    return planned_ink(traj, windows, strokes_world, board, brush=opts.brush, size_m=opts.size_m)


def _turning_samples(
    strokes_world: tuple[FloatArray, ...],
    board: Board,
    points: FloatArray,
    roles: FloatArray,
    threshold: float,
) -> FloatArray:
    """Indices into the route of every stroke's turning points (paper 000 §4)."""
    picked = []
    for i, stroke in enumerate(strokes_world):
        corners = stroke[turning_points(board.to_board(stroke)[:, :2], threshold)]
        where = np.flatnonzero(roles == i)
        # Densifying keeps the vertices: find each corner among the stroke's samples.
        gaps = np.linalg.norm(points[where][:, None, :] - corners[None, :, :], axis=2)
        picked.append(where[np.argmin(gaps, axis=0)])
    return np.concatenate(picked)


def _problem(
    samples: RouteSamples,
    targets: FloatArray,
    times: FloatArray,
    opts: WritingOptions,
    *,
    gain: FloatArray | None = None,
    n_ctrl: int | None = None,
    board: Board | None = None,
) -> SmoothingProblem:
    """The smoothing problem of ``samples`` fitted to ``targets`` (N, 3) at ``times`` (N,).

    ``gain``: the deviation is of ``p + gain * a`` (the swung tip's first-order
    model) instead of ``p``; ``n_ctrl``: the control points (re-segmentation
    keeps them), else from ``opts.knot_interval`` up to ``samples.max_spans``;
    ``board``: a sky board adds its plane's deviation cost (:func:`_plane_terms`).
    """
    duration = float(times[-1])
    spans = n_ctrl - opts.degree if n_ctrl else max(1, math.ceil(duration / opts.knot_interval))
    if samples.max_spans is not None:
        spans = min(spans, samples.max_spans)
    if spans > MAX_SPANS:
        raise InputError(
            f"knot_interval: got {opts.knot_interval:g} s for a {duration:.4g} s flight, i.e. "
            f"{spans:,} knot spans, expected at most {MAX_SPANS:,} (a longer knot_interval, "
            "a smaller size_m or fewer strokes)"
        )
    stroke, lift = samples.roles >= 0, samples.roles == LIFT
    # Fitting the tip, the lifts are held (lift_weight): a lift the smoothing
    # cuts short leaves the brush on the board between strokes, and the ink
    # joins them. Fitting the path (paper 000) they are transits.
    transit = ~stroke if gain is None else samples.roles == TRANSIT
    terms = [
        (stroke, opts.data_weight),
        (samples.corners, opts.turning_weight),
        (transit, opts.transit_weight),
        (lift if gain is not None else np.zeros_like(lift), opts.lift_weight),
    ]
    deviations = tuple(
        PointDeviation(times[which], targets[which], weight, gain)
        for which, weight in terms
        if weight > 0 and np.any(which)
    )
    return SmoothingProblem(
        dim=3,
        degree=opts.degree,
        n_ctrl=spans + opts.degree,
        duration=duration,
        smoothness={3: 1.0},
        deviations=deviations + _plane_terms(samples.roles, times, board, opts),
        boundary=Boundary.rest(targets[0], targets[-1], 3),
        limits=opts.derivative_limits(),
    )


def _plane_terms(
    roles: FloatArray, times: FloatArray, board: Board | None, opts: WritingOptions
) -> tuple[PlaneDeviation, ...]:
    """Paper 003 §5.3 on a sky board: the plane's deviation from the first stroke's
    start to the last one's end, transits included (they stay in the plane, lift 0).
    Off the board (take-off, landing) the flight leaves the plane on purpose."""
    if board is None or board.has_contact or opts.plane_weight == 0:
        return ()
    pen = np.flatnonzero(roles >= 0)
    if pen.size == 0 or times[pen[-1]] <= times[pen[0]]:
        return ()
    t0, t1 = float(times[pen[0]]), float(times[pen[-1]])
    return (PlaneDeviation(board.normal, board.origin, t0, t1, opts.plane_weight),)


def _pen_windows(roles: FloatArray, times: FloatArray, n: int) -> tuple[tuple[float, float], ...]:
    windows = []
    for i in range(n):
        where = np.flatnonzero(roles == i)
        windows.append((float(times[where[0]]), float(times[where[-1]])))
    return tuple(windows)


def check_separation(
    trajectories: list[Trajectory], minimum_m: float = 1.0, rate_hz: float = 50.0
) -> float:
    """Guaranteed smallest pairwise distance over the whole flight, m; raise if below ``minimum_m``.

    Not sampled: :func:`skyquill.show.separation_of` bounds the distance between
    samples, so a show that passes here passes ``skyquill check --min-distance``.
    Drones that finish early hold their last position (landed at home).
    ``rate_hz`` is kept for callers and no longer used.
    """
    from skyquill.show import ShowDrone, require_separation

    minimum = as_float("minimum_m", minimum_m, positive=True)
    as_float("rate_hz", rate_hz, positive=True)
    drones = [ShowDrone(tr, f"drone {i}") for i, tr in enumerate(trajectories)]
    return require_separation(drones, minimum, "separation").lower_bound_m


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
