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
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from skyquill.calligraphy.board import Board
from skyquill.errors import InfeasibleError, InputError
from skyquill.geometry import polyline_distance
from skyquill.io.trajectory_json import pen_down
from skyquill.limits import DerivativeLimit, VehicleLimits
from skyquill.optimize import Boundary, PointDeviation, SmoothingProblem, resegment, solve
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

#: Spacing of the samples that hold lifts and transits near their straight lines, m.
TRANSIT_SPACING_M = 0.01
#: Largest input a mission takes, points: a tablet at 200 Hz for 15 minutes.
MAX_INPUT_POINTS = 200_000
#: Character sizes accepted, m. Below 1 cm a character is narrower than a brush
#: stroke and its 1 % tolerance (0.1 mm) is finer than a quadrotor's position
#: estimate (motion capture: ~1 mm), so "within tolerance" would mean nothing;
#: above 20 m the route (sampled every TRANSIT_SPACING_M) and the flight grow
#: past a board and a battery: that is sky writing, not calligraphy.
SIZE_RANGE_M = (0.01, 20.0)
#: Longest brush accepted, m: the tip is modelled as rigid along the thrust
#: axis (``L (e_z - b3)``); a longer "brush" is a tether that swings on its own.
MAX_BRUSH_LENGTH_M = 2.0
#: Most route samples (stroke points plus lifts and transits every
#: TRANSIT_SPACING_M), estimated from the route's length before it is built:
#: each is a row of the QP's deviation block (~1 kB with its factors).
MAX_ROUTE_SAMPLES = 400_000
#: Most knot spans of one solve, checked before each assembly: 3 x (spans + 5)
#: unknowns and a hull block per span and limit; 20 000 spans is 1000 s of
#: flight at the default 0.05 s, and ~1 GB of KKT factors.
MAX_SPANS = 20_000
#: Solves of the tilt compensation's fixed-point iteration.
TILT_PASSES = 3
GRAVITY = 9.81  # m/s^2
#: How fast the pen-down deviation falls with the timing stretch, ``deviation ~ scale^-p``,
#: taken on the fast side of what is measured (p ~ 3.1) so that a predicted stretch never
#: overshoots (:func:`_stretches_needed`).
DEVIATION_EXPONENT = 3.5
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
    data_weight, turning_weight, transit_weight
        Weights of the stroke samples, turning points and transit samples
        against the jerk cost.
    knot_interval
        Seconds per knot span.
    degree
        Spline degree.
    brush_length_m
        Tip to vehicle distance along the board normal, m, at most
        :data:`MAX_BRUSH_LENGTH_M` (the default simulated vehicle's brush).
    resegment
        Time re-segmentation after the first feasible, faithful plan (paper
        000 §5.4): ``"fixed"`` keeps the total time, ``"free"`` lets it move
        at a time penalty that makes the initial total time stationary under
        uniform scaling (without a penalty the jerk cost falls for ever as
        time grows); ``"off"`` skips it.
    resegment_iterations
        Descent steps at most (each is one solve and one analytic gradient).
    tilt_compensation
        Horizontal boards: the brush hangs along the thrust axis, so tilting to
        accelerate swings the tip by ``L (e_z - b3)`` (~3 cm on a 0.5 m
        character at these limits). When on, the stroke targets are shifted
        against the swing and the plan solved again (a fixed-point iteration,
        :data:`TILT_PASSES` solves), and fidelity is measured on the swung tip.
        Off by default: on the bundled characters it needs ~1.5-2.5x the
        writing time to get the swung tip within 5 mm, and ~1 s of planning.
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
    """

    size_m: float = 0.5
    limits: VehicleLimits = field(default_factory=lambda: VehicleLimits(1.0, 2.0, 10.0))
    norm_sides: int | None = None
    tolerance_m: float | None = None
    turning_threshold_m: float | None = None
    data_weight: float = 1e4
    turning_weight: float = 1e5
    transit_weight: float = 1e2
    knot_interval: float = 0.05
    degree: int = 5
    brush_length_m: float = 0.3
    resegment: Literal["off", "fixed", "free"] = "fixed"
    resegment_iterations: int = 8
    tilt_compensation: bool = False
    stretch_factor: float = 1.25
    max_stretches: int = 8
    best_effort: bool = False
    target: UploadTarget | None = None
    target_strategies: tuple[TargetStrategy, ...] = TARGET_STRATEGIES

    def __post_init__(self) -> None:
        if not isinstance(self.limits, VehicleLimits):
            raise InputError(f"limits: got {type(self.limits).__name__}, expected VehicleLimits")
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
        for name in ("data_weight", "turning_weight", "transit_weight", "brush_length_m"):
            as_float(name, getattr(self, name), nonneg=True)
        low, high = SIZE_RANGE_M
        if not low <= self.size_m <= high:
            raise InputError(
                f"size_m: got {self.size_m:g} m, expected {low:g} to {high:g} m (a character "
                "legible with a brush, within the position accuracy, on one board)"
            )
        if self.brush_length_m > MAX_BRUSH_LENGTH_M:
            raise InputError(
                f"brush_length_m: got {self.brush_length_m:g} m, expected at most "
                f"{MAX_BRUSH_LENGTH_M:g} m (the brush is modelled as rigid)"
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


@dataclass(frozen=True)
class Deviation:
    """Two-sided distance between the pen-down path and the input strokes, m.

    ``max_m`` is the Hausdorff distance: the larger of the two one-sided maxima.
    """

    path_to_input_max_m: float
    input_to_path_max_m: float
    mean_m: float

    @property
    def max_m(self) -> float:
        """Largest of both one-sided distances (the Hausdorff distance), m."""
        return max(self.path_to_input_max_m, self.input_to_path_max_m)

    def as_dict(self) -> dict[str, float]:
        """``summary.json`` form."""
        return {
            "max_m": self.max_m,
            "mean_m": self.mean_m,
            "hausdorff_m": self.max_m,
            "path_to_input_max_m": self.path_to_input_max_m,
            "input_to_path_max_m": self.input_to_path_max_m,
        }


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
        Fidelity of the pen-down path.
    time_scale
        Stretch applied to the initial timing (the largest over the parts).
    planning_time_s
        Wall time of the whole planning.
    options
        The options it was planned with.
    target
        How the plan fits ``options.target`` (strategy and uploads); ``None``
        without a target.
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
        """Vehicle position minus tip position (3,), m."""
        return self.options.brush_length_m * self.board.normal

    def vehicle_trajectory(self) -> Trajectory:
        """The vehicle's trajectory: the tip's, offset by the brush along the board normal.

        A constant offset of every control point offsets the curve (partition
        of unity), so limits and smoothness are unchanged.
        """
        return offset_trajectory(self.trajectory, self.brush_offset)

    @property
    def faithful(self) -> bool:
        """Whether the pen-down path is within the tolerance of the input."""
        return self.deviation.max_m <= self.options.tolerance

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
            "strokes": len(self.strokes_world),
            "time_scale": self.time_scale,
        }
        if self.target is not None:
            entry["target"] = self.target.as_dict()
        return entry


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
    """The mission polyline with a role per sample: stroke index or -1 (transit)."""

    points: list[FloatArray] = field(default_factory=list)
    role: list[FloatArray] = field(default_factory=list)

    def add(self, points: FloatArray, role: int) -> None:
        self.points.append(points)
        self.role.append(np.full(len(points), role))

    def go_to(self, target: FloatArray, include_target: bool = True) -> None:
        if np.linalg.norm(target - self.points[-1][-1]) < 1e-9:
            return  # already there: no repeated sample (times must increase)
        line = _segment(self.points[-1][-1], target)
        self.add(line if include_target else line[:-1], -1)


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
        route.go_to(stroke[0], include_target=False)  # touch down: the stroke's first point
        route.add(densify(stroke), i)
        route.go_to(stroke[-1] + lift)
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
        ``brush_length_m`` below it); ``None`` starts and ends hovering above
        the first and last stroke.

    Raises
    ------
    InputError
        More than :data:`MAX_INPUT_POINTS` points or :data:`MAX_STROKES` strokes, a
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
    home_pos = None if home is None else as_array("home", home, shape=(3,))
    if home_pos is not None:
        home_pos = home_pos - opts.brush_length_m * board.normal  # the tip's home
    scaled = strokes.scaled(opts.size_m)
    strokes_world = tuple(board.to_world(path) for path in scaled.paths)
    _check_route_size(strokes_world, board, home_pos)
    points, roles = _route(strokes_world, board, home_pos)
    vmax, amax = opts.limits.timing_bounds()
    times = allocate_path_times(points, vmax, 0.5 * amax)
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
    if not plan.compensated and opts.resegment != "off" and opts.resegment_iterations > 0:
        plan = resegmented(samples, plan, opts)
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
    """One spline along a route: the fit, pen windows (s), fidelity, stretch, sample times (s)."""

    fit: FitResult
    windows: tuple[tuple[float, float], ...]
    deviation: Deviation
    scale: float
    times: FloatArray
    compensated: bool

    def faithful(self, opts: WritingOptions) -> bool:
        """Whether the pen-down path is within ``opts.tolerance``."""
        return self.deviation.max_m <= opts.tolerance


def plan_route(
    samples: RouteSamples, times: FloatArray, board: Board, opts: WritingOptions
) -> RoutePlan:
    """One rest-to-rest spline along ``samples`` at ``times`` over ``board``, stretched to fit.

    The timing is stretched by ``opts.stretch_factor`` while the limits cannot
    be met or the pen-down path is beyond the tolerance, at most
    ``opts.max_stretches`` times; the last plan is returned even if it is not
    faithful (the caller decides). No re-segmentation (:func:`resegmented`).

    Raises
    ------
    InfeasibleError
        The limits cannot be met even after ``max_stretches`` stretches.
    """
    compensate = opts.tilt_compensation and board.kind == "horizontal" and opts.brush_length_m > 0
    scale, stretches = 1.0, 0
    while True:
        last = stretches >= opts.max_stretches
        try:
            # Re-segmenting every attempt is needed only when the swung tip decides.
            fit, windows, deviation, scaled_times = _plan_at(
                samples, times * scale, opts, resegment=compensate
            )
        except InfeasibleError:
            if last:
                raise
            scale, stretches = scale * opts.stretch_factor, stretches + 1
            continue
        if compensate:
            fit, deviation = _compensate_tilt(samples, scaled_times, fit, windows, opts)
        if deviation.max_m <= opts.tolerance or last:
            break
        # Slower: less tracking error and less brush swing. Skip the stretches that
        # cannot reach the tolerance (the swung tip does not follow the model).
        k = 1 if compensate else _stretches_needed(deviation.max_m, opts)
        k = min(k, opts.max_stretches - stretches)
        scale, stretches = scale * opts.stretch_factor**k, stretches + k
    return RoutePlan(fit, windows, deviation, scale, scaled_times, compensate)


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
    """The error for a plan whose pen-down path stays beyond the tolerance."""
    return InfeasibleError(
        f"strokes: the pen-down path stays {1e3 * plan.deviation.max_m:.3g} mm from the input "
        f"after {opts.max_stretches} stretches ({plan.scale:.3g}x slower) within "
        f"{opts.limits.describe()}, expected within the "
        f"tolerance of {1e3 * opts.tolerance:.3g} mm (1 % of the size unless tolerance_m "
        "is given); a larger size, a lower speed limit (the route is timed by it) or "
        "best_effort",
        ("fidelity",),
    )


def resegmented(samples: RouteSamples, plan: RoutePlan, opts: WritingOptions) -> RoutePlan:
    """``plan`` after time re-segmentation (paper 000 §5.4), if that stays faithful."""
    fit, windows, deviation, times = _resegment(
        samples, plan.times, (plan.fit, plan.windows, plan.deviation), opts
    )
    return RoutePlan(fit, windows, deviation, plan.scale, times, plan.compensated)


def _plan_at(
    samples: RouteSamples, times: FloatArray, opts: WritingOptions, *, resegment: bool
) -> tuple[FitResult, tuple[tuple[float, float], ...], Deviation, FloatArray]:
    """Solve at ``times``, then re-segment if asked; the times it ends with."""
    fit = solve(
        _problem(
            samples.points,
            samples.roles,
            samples.corners,
            times,
            opts,
            max_spans=samples.max_spans,
        ),
        workspace=samples.workspace,
    )
    windows = _pen_windows(samples.roles, times, len(samples.strokes_world))
    deviation = measure_deviation(fit.trajectory, windows, samples.strokes_world)
    if not resegment or opts.resegment == "off" or opts.resegment_iterations == 0:
        return fit, windows, deviation, times
    return _resegment(samples, times, (fit, windows, deviation), opts)


def _resegment(
    samples: RouteSamples,
    times: FloatArray,
    current: tuple[FitResult, tuple[tuple[float, float], ...], Deviation],
    opts: WritingOptions,
) -> tuple[FitResult, tuple[tuple[float, float], ...], Deviation, FloatArray]:
    """Paper 000 §5.4 on the mission's sample times; keep the result only if still faithful."""
    fit = current[0]
    n_ctrl = fit.trajectory.control_points.shape[0]

    def make(ts: FloatArray) -> SmoothingProblem:
        return _problem(samples.points, samples.roles, samples.corners, ts, opts, n_ctrl=n_ctrl)

    penalty = 0.0
    if opts.resegment == "free":
        # Uniform scaling by k multiplies the jerk energy by k^-5: this rho
        # makes the current total time stationary, so the descent trades time
        # between segments and moves the total only where that pays.
        penalty = 5.0 * fit.cost_terms["smoothness"] / float(times[-1])
    try:
        result = resegment(
            samples.points,
            times,
            make,
            mode="free" if opts.resegment == "free" else "fixed",
            time_penalty=penalty,
            max_iter=opts.resegment_iterations,
            initial_result=fit,  # the plan just made at these times: not solved again
            workspace=samples.workspace,
        )
    except InfeasibleError:
        return (*current, times)
    strokes = samples.strokes_world
    windows = _pen_windows(samples.roles, result.times, len(strokes))
    deviation = measure_deviation(result.result.trajectory, windows, strokes)
    if deviation.max_m > max(opts.tolerance, current[2].max_m):
        return (*current, times)  # never trade fidelity for smoothness
    return result.result, windows, deviation, result.times


def swung_tip(traj: Trajectory, t: FloatArray, brush_length_m: float) -> FloatArray:
    """Where the hanging brush's tip really is (N, 3): ``P + L (e_z - b3)``.

    ``P`` is the planned (untilted) tip, ``b3`` the thrust direction the
    acceleration demands, ``(a + g e_z) / |a + g e_z|``.
    """
    thrust = traj.evaluate(t, 2) + np.array([0.0, 0.0, GRAVITY])
    b3 = thrust / np.linalg.norm(thrust, axis=1, keepdims=True)
    return np.asarray(traj.evaluate(t) + brush_length_m * (np.array([0.0, 0.0, 1.0]) - b3))


def _compensate_tilt(
    samples: RouteSamples,
    times: FloatArray,
    fit: FitResult,
    windows: tuple[tuple[float, float], ...],
    opts: WritingOptions,
) -> tuple[FitResult, Deviation]:
    """Shift stroke targets against the brush swing; keep the most faithful pass."""
    length, stroke = opts.brush_length_m, samples.roles >= 0
    n_ctrl = fit.trajectory.control_points.shape[0]
    best = (fit, measure_deviation(fit.trajectory, windows, samples.strokes_world, length))
    targets = samples.points.copy()
    for _ in range(TILT_PASSES):
        t = times[stroke]
        swing = swung_tip(fit.trajectory, t, length) - fit.trajectory.evaluate(t)
        targets[stroke] = samples.points[stroke] - swing
        try:
            fit = solve(
                _problem(targets, samples.roles, samples.corners, times, opts, n_ctrl=n_ctrl)
            )
        except InfeasibleError:
            break
        deviation = measure_deviation(fit.trajectory, windows, samples.strokes_world, length)
        if deviation.max_m < best[1].max_m:
            best = (fit, deviation)
    return best


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
    points: FloatArray,
    roles: FloatArray,
    corners: FloatArray,
    times: FloatArray,
    opts: WritingOptions,
    *,
    n_ctrl: int | None = None,
    max_spans: int | None = None,
) -> SmoothingProblem:
    duration = float(times[-1])
    spans = n_ctrl - opts.degree if n_ctrl else max(1, math.ceil(duration / opts.knot_interval))
    if max_spans is not None:
        spans = min(spans, max_spans)
    if spans > MAX_SPANS:
        raise InputError(
            f"knot_interval: got {opts.knot_interval:g} s for a {duration:.4g} s flight, i.e. "
            f"{spans:,} knot spans, expected at most {MAX_SPANS:,} (a longer knot_interval, "
            "a smaller size_m or fewer strokes)"
        )
    stroke = roles >= 0
    deviations = [
        PointDeviation(times[stroke], points[stroke], opts.data_weight),
        PointDeviation(times[corners], points[corners], opts.turning_weight),
    ]
    if np.any(~stroke) and opts.transit_weight > 0:
        deviations.append(PointDeviation(times[~stroke], points[~stroke], opts.transit_weight))
    return SmoothingProblem(
        dim=3,
        degree=opts.degree,
        n_ctrl=spans + opts.degree,
        duration=duration,
        smoothness={3: 1.0},
        deviations=tuple(deviations),
        boundary=Boundary.rest(points[0], points[-1], 3),
        limits=opts.derivative_limits(),
    )


def _pen_windows(roles: FloatArray, times: FloatArray, n: int) -> tuple[tuple[float, float], ...]:
    windows = []
    for i in range(n):
        where = np.flatnonzero(roles == i)
        windows.append((float(times[where[0]]), float(times[where[-1]])))
    return tuple(windows)


def measure_deviation(
    traj: Trajectory,
    windows: tuple[tuple[float, float], ...],
    strokes_world: tuple[FloatArray, ...],
    brush_length_m: float = 0.0,
    samples_per_stroke: int = 400,
) -> Deviation:
    """Two-sided distance between the pen-down path and the input strokes.

    For each stroke: the largest distance from pen-down samples to the
    stroke's polyline, and from the stroke's points to the pen-down path
    (its dense samples as a polyline). 3-D distances: lifting off the board
    counts. With ``brush_length_m > 0`` the path is the swung tip
    (:func:`swung_tip`), else the planned curve itself.
    """
    forward, backward, total, count = 0.0, 0.0, 0.0, 0
    for (t0, t1), stroke in zip(windows, strokes_world, strict=True):
        t = np.linspace(t0, t1, samples_per_stroke)
        path = swung_tip(traj, t, brush_length_m) if brush_length_m else traj.evaluate(t)
        to_input = polyline_distance(path, stroke)
        to_path = polyline_distance(stroke, path)
        forward = max(forward, float(to_input.max()))
        backward = max(backward, float(to_path.max()))
        total += float(to_input.sum())
        count += to_input.size
    return Deviation(forward, backward, total / count)


def check_separation(
    trajectories: list[Trajectory], minimum_m: float = 1.0, rate_hz: float = 50.0
) -> float:
    """Smallest pairwise distance over the whole flight, m; raise if below ``minimum_m``.

    Drones that finish early hold their last position (landed at home).
    """
    minimum = as_float("minimum_m", minimum_m, positive=True)
    horizon = max(t.duration for t in trajectories)
    t = np.linspace(0.0, horizon, max(2, math.ceil(horizon * rate_hz) + 1))
    tracks = [tr.evaluate(np.minimum(t, tr.duration)) for tr in trajectories]
    closest = math.inf
    for i in range(len(tracks)):
        for j in range(i + 1, len(tracks)):
            gap = np.linalg.norm(tracks[i] - tracks[j], axis=1)
            k = int(np.argmin(gap))
            if gap[k] < closest:
                closest = float(gap[k])
            if gap[k] < minimum:
                raise InfeasibleError(
                    f"separation: drones {i} and {j} come within {gap[k]:.3f} m at "
                    f"t = {t[k]:.2f} s, expected at least {minimum:g} m",
                    ("separation",),
                )
    return closest


#: How far the simulated board is raised into the brush's planned path, m.
PRESS_M = 0.002
#: How far the simulated board reaches beyond the writing on every side, m.
BOARD_MARGIN_M = 0.1


def contact_board(mission: Mission) -> ContactBoard | None:
    """The simulator's board under a horizontal writing board (``None`` for a wall).

    The plan touches the surface; the simulated board sits :data:`PRESS_M`
    higher so that the brush presses into it and tracking errors do not lift
    it off. The simulator's contact model is a horizontal slab only.
    """
    from skyquill.sim import ContactBoard

    if mission.board.kind != "horizontal":
        return None
    corner, size, margin = mission.board.origin, mission.options.size_m, BOARD_MARGIN_M
    return ContactBoard(
        height_m=float(corner[2]) + PRESS_M,
        extent=(corner[0] - margin, corner[0] + size + margin,
                corner[1] - margin, corner[1] + size + margin),
    )  # fmt: skip
