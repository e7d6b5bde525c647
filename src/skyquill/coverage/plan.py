"""Coverage missions end to end: region -> covering path -> timed, verified trajectory.

Three patterns, compared on equal terms (paper ``001_61beb0e01a19013a`` §4):

* ``spiral`` -- the paper's spiral spline (§1): contours, spiral control
  points with corner points at ``delta``, a degree-4 B-spline with
  Hartley-Judd knots, timed by the jerk-limited speed LP (§2);
* ``zigzag`` -- the fair baseline: the boustrophedon's waypoints through the
  *same* corner points, spline and speed LP;
* ``zigzag-stop`` -- the paper's baseline: straight legs, rest at every
  corner, each leg time-optimal under the same limits (Ruckig).

Concave regions are split into convex parts whose spirals (or zigzags) are
joined into one path (:mod:`skyquill.coverage.joined`, the paper's Fig. 5).
Regions with holes (keep-out zones) or of several fields are cut into
hole-free pieces, each planned as above, flown in one mission with the spray
off on the transits between them (:mod:`skyquill.coverage.mission`).
"""

from __future__ import annotations

import functools
import logging
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from shapely.geometry import LineString, MultiPolygon, Polygon

from skyquill.coverage import DEFAULT_MIN_COVERAGE
from skyquill.coverage.deadline import (
    DEFAULT_TIME_LIMIT_S,
    Deadline,
    Progress,
    check_time_limit,
    is_time_limit,
)
from skyquill.coverage.jerk_zigzag import AxisLimits, default_shape, fastest, tuning_shapes
from skyquill.coverage.missed import Missed, missed_area
from skyquill.coverage.mission import Mission, PiecePlanner, fly_mission
from skyquill.coverage.paths import (
    ContourMode,
    DriftMode,
    contours,
    merge_close,
    spiral_control_points,
    spiral_curve,
    with_corner_points,
    zigzag,
)
from skyquill.coverage.regions import (
    Region,
    check_width,
    coverage_fraction,
    estimate_path_length,
    has_keepouts,
    swept,
)
from skyquill.coverage.speed import SpeedPlan, plan_speed
from skyquill.coverage.target import DeliveredPath, check_target_path, deliver
from skyquill.errors import InfeasibleError, InputError
from skyquill.limits import BoxLimit, CylinderLimit, DerivativeLimit, VehicleLimits
from skyquill.optimize.legs import LegLimits, stop_and_go
from skyquill.targets import UploadTarget
from skyquill.trajectory import Samples, Trajectory, concatenate
from skyquill.validation import as_float, as_int
from skyquill.verify import Verification, verify

FloatArray = NDArray[np.float64]
_log = logging.getLogger(__name__)
Pattern = Literal["spiral", "zigzag", "zigzag-stop", "zigzag-jerk"]
PATTERNS: tuple[Pattern, ...] = ("spiral", "zigzag", "zigzag-stop", "zigzag-jerk")
CONTOUR_MODES: tuple[ContourMode, ...] = ("offset", "homothetic")
DRIFT_MODES: tuple[DriftMode, ...] = ("step", "lap")
#: Candidates of :func:`tune_coverage`.
TUNING_EPSILONS = (1.0, 0.9, 0.8, 0.7)
TUNING_DELTAS = (2.0, 1.5, 1.0, 0.6, 0.3, 0.15)

#: Share of the allowed miss a mission's pieces are tuned to (the rest is the holes').
MISSION_MISS_SHARE = 0.5
#: Tuning candidates planned in full (best estimated first; see :func:`_estimated_duration`),
#: and how far above the best estimate a second one may be (the estimate's ranking erred
#: by 2 % on the held-out regions).
TUNED_FULL_PLANS = 2
ESTIMATE_MARGIN = 1.05
#: The estimate's speed-LP grid points and pseudo-jerk iterations.
ESTIMATE_GRID = 300
ESTIMATE_JERK_ITERATIONS = 3

#: Spacing of the speed LP's grid along the path, m (the grid needs several
#: points per corner feature; see :func:`grid_points`).
GRID_SPACING_M = 0.05
#: Waypoints closer than this fraction of ``delta`` are one (see :func:`covering_waypoints`).
MERGE_FRACTION = 0.01
#: Bounds on the LP's grid size (LP time grows faster than linearly).
GRID_POINTS = (300, 2000)
#: Spacing of the dense samples that coverage is measured on, m.
COVERAGE_SPACING_M = 0.02
#: Largest region side accepted, m (beyond it the LP grid would be too coarse).
MAX_REGION_SIZE_M = 1000.0
#: Planning time per metre of estimated path assumed before any work, s/m: measured
#: 0.7 ms/m (a 316 m square at a 5 m swath, 19.8 km, in 14.5 s on 2 shared cores),
#: rounded up. A budget below the estimate is refused at once rather than spent.
PLANNING_S_PER_M = 1e-3


@dataclass(frozen=True)
class CoverageOptions:
    """What to cover with and how.

    Attributes
    ----------
    width : float
        Coverage diameter (swath), m.
    limits : VehicleLimits
        ``vmax`` is the speed; acceleration and jerk are held either as norms
        (``amax``, ``jmax``: the default) or per axis (``amax_axis``,
        ``jmax_axis``: paper 001's limits), both the same kind.
    pattern : {"spiral", "zigzag", "zigzag-stop", "zigzag-jerk"}
        ``"zigzag-jerk"``: straight lanes joined by turns that are Ruckig's
        time-optimal motions under the limits (:mod:`~skyquill.coverage.jerk_zigzag`;
        ``epsilon`` is its lane spacing, ``delta`` and ``perimeter`` do not
        apply; tuned, it picks the lanes' direction, insets and turn depth).
    contours : {"offset", "homothetic"}
        Spiral rings: true inward offsets, or the paper's shrink (eq. 1-3).
    drift : {"step", "lap"}
        Spiral laps: whole rings joined by a step, or the paper's eq. 4 drift
        (which needs an extra undrifted outer lap; see
        :func:`~skyquill.coverage.paths.spiral_control_points`).
    epsilon : float
        Density factor in (0, 1]: rings and sweep lines ``epsilon * width``
        apart (more overlap, fewer gaps at corners, longer path).
    perimeter : bool
        Zigzag patterns: start with a lap around the region (sweeps the
        slivers that sweep-line ends leave along slanted sides).
    delta : float
        Distance of the corner control points from each corner, m (smaller:
        sharper corners, more coverage, slower).
    rate : float
        Setpoint rate, Hz (the control period of §2.2 is ``1 / rate``).
    altitude : float
        Flight height above the ground written to the setpoints, m, > 0.
    grid : int or None
        Speed-LP grid points; ``None`` picks them from the path length.
    norm_sides : int
        The acceleration and jerk norms are held in the speed LP by the
        inscribed regular polygon of this many sides (even, >= 4;
        ``norm_sides`` of :func:`~skyquill.coverage.speed.plan_speed`; 16 is
        within 2 % of the circle) and measured as norms.
    target : UploadTarget or None
        A vehicle's upload budget (:data:`skyquill.targets.TARGETS`): the
        planned path is then re-fitted into its uploads, degree-7 pieces flown
        rest to rest between uploads (:mod:`skyquill.coverage.target`).
    time_limit : float
        Wall-time budget of one plan (all of :func:`plan_tuned`'s trials
        together), s, > 0: the plan is returned within it (plus one step), or
        an ``InfeasibleError`` with family ``"time_limit"`` names the step it
        stopped at; a budget below the estimate (:data:`PLANNING_S_PER_M`
        times the estimated path length) is refused before any work.
    """

    width: float = 2.0
    limits: VehicleLimits = field(default_factory=lambda: VehicleLimits(3.0, 5.0, 3.0))
    pattern: Pattern = "spiral"
    contours: ContourMode = "offset"
    drift: DriftMode = "step"
    epsilon: float = 1.0
    perimeter: bool = False
    delta: float = 0.5
    rate: float = 50.0
    altitude: float = 2.0
    grid: int | None = None
    norm_sides: int = 16
    target: UploadTarget | None = None
    time_limit: float = DEFAULT_TIME_LIMIT_S

    def __post_init__(self) -> None:
        for name in ("width", "delta", "rate"):
            as_float(name, getattr(self, name), positive=True)
        _check_limits(self.limits)
        if as_float("altitude", self.altitude) <= 0.0:
            raise InputError(
                f"altitude: got {self.altitude:g} m, expected a height above the ground, > 0"
            )
        if self.pattern not in PATTERNS:
            raise InputError(f"pattern: got {self.pattern!r}, expected one of {PATTERNS}")
        if self.contours not in CONTOUR_MODES:
            raise InputError(f"contours: got {self.contours!r}, expected one of {CONTOUR_MODES}")
        if self.drift not in DRIFT_MODES:
            raise InputError(f"drift: got {self.drift!r}, expected one of {DRIFT_MODES}")
        if not 0.0 < as_float("epsilon", self.epsilon) <= 1.0:
            raise InputError(f"epsilon: got {self.epsilon!r}, expected a value in (0, 1]")
        if self.grid is not None:
            as_int("grid", self.grid, low=3, high=20_000)
        sides = as_int("norm_sides", self.norm_sides, low=4, high=1024)
        if sides % 2:
            raise InputError(f"norm_sides: got {sides}, expected an even integer from 4 to 1024")
        check_time_limit(self.time_limit)
        if self.target is not None and not isinstance(self.target, UploadTarget):
            name = type(self.target).__name__
            raise InputError(f"target: got {name}, expected an UploadTarget or None")

    @property
    def per_axis(self) -> bool:
        """Whether acceleration and jerk are per-axis bounds (else norms)."""
        return self.limits.amax is None

    @property
    def vmax(self) -> float:
        """Speed limit, m/s."""
        assert self.limits.vmax is not None  # checked at construction
        return self.limits.vmax

    @property
    def amax(self) -> float:
        """Acceleration limit (the norm, or per axis), m/s^2."""
        value = self.limits.amax_axis if self.per_axis else self.limits.amax
        assert value is not None  # checked at construction
        return value

    @property
    def jmax(self) -> float:
        """Jerk limit (the norm, or per axis), m/s^3."""
        value = self.limits.jmax_axis if self.per_axis else self.limits.jmax
        assert value is not None  # checked at construction
        return value

    @property
    def limit_norm_sides(self) -> int | None:
        """The LP's polygon for the norms, or None when the limits are per axis."""
        return None if self.per_axis else self.norm_sides


def _check_limits(limits: VehicleLimits) -> None:
    """The limits the speed LP can hold: a speed, and acceleration and jerk of one kind."""
    if not isinstance(limits, VehicleLimits):
        raise InputError(f"limits: got {type(limits).__name__}, expected VehicleLimits")
    if limits.vmax is None:
        raise InputError("limits.vmax: got None, expected the speed limit (m/s)")
    norms = (limits.amax is not None, limits.jmax is not None)
    axes = (limits.amax_axis is not None, limits.jmax_axis is not None)
    if not (norms == (True, True) and axes == (False, False)) and not (
        norms == (False, False) and axes == (True, True)
    ):
        raise InputError(
            f"limits: got amax={limits.amax}, jmax={limits.jmax}, amax_axis="
            f"{limits.amax_axis}, jmax_axis={limits.jmax_axis}; expected the acceleration and "
            "the jerk both as norms (amax, jmax) or both per axis (amax_axis, jmax_axis)"
        )


@dataclass(frozen=True, eq=False)
class CoveragePlan:
    """A planned coverage flight.

    Attributes
    ----------
    region : shapely.Polygon
    options : CoverageOptions
    waypoints : ndarray, shape (K, 2)
        The control polygon (spline patterns) or the stop points (zigzag-stop), m.
    path : ndarray, shape (M, 2)
        The flown path, densely sampled (every ~2 cm), m (with a target: the
        delivered flight's).
    trajectory : Trajectory
        The flight at ``options.altitude``, 3-D: a retimed path (spline
        patterns), straight legs (stop-and-go) or parts at rest between them;
        with a target, ``delivered.trajectory``.
    coverage : float
        Covered fraction of the region's area (by ``path``).
    limits : dict
        The dense check of ``trajectory`` against :func:`coverage_limits`
        (see :func:`limits_report`) and ``joins``.
    planning_time : float
        Wall time of :func:`plan_coverage`, s.
    speed_plan : SpeedPlan or None
        The LP's plan (spline patterns only; with a target, of the planned
        path before it was re-fitted).
    delivered : DeliveredPath or None
        With ``options.target``: the re-fit into the target's uploads.
    planned_coverage : float or None
        With a target: the coverage of the planned path before the re-fit.
    missed : Missed or None
        What ``path``'s swath misses of the region (area, share, the largest
        gaps; holes are not the region's); None only for plans built by hand.
    mission : Mission or None
        For a region with holes or several fields: the pieces' mission, with
        where the spray is on and the keep-out check (``path`` is then the
        whole flight, transits included, and ``coverage`` counts only what
        is sprayed); None for a simple polygon (the spray is on throughout).
    """

    region: Region
    options: CoverageOptions
    waypoints: FloatArray
    path: FloatArray
    trajectory: Trajectory
    coverage: float
    limits: dict[str, Any]
    planning_time: float
    speed_plan: SpeedPlan | None
    delivered: DeliveredPath | None = None
    planned_coverage: float | None = None
    missed: Missed | None = None
    mission: Mission | None = None

    @property
    def pen_windows_s(self) -> tuple[tuple[float, float], ...]:
        """When the spray is on, ``(start, end)`` in s: throughout, or the mission's windows."""
        if self.mission is None:
            return ((0.0, self.duration),)
        return self.mission.pen_windows_s

    @property
    def duration(self) -> float:
        """Flight time from rest to rest, s."""
        return self.trajectory.duration

    def samples(self) -> Samples:
        """The trajectory sampled at ``options.rate`` (the setpoints a controller gets)."""
        return self.trajectory.sample(self.options.rate)

    @property
    def path_length(self) -> float:
        """Length of the flown path, m."""
        return _length(self.path)

    def summary(self) -> dict[str, Any]:
        """What ``summary.json`` holds (JSON-ready)."""
        lp = self.speed_plan
        target = self.delivered
        return {
            "pattern": self.options.pattern,
            "duration_s": self.duration,
            "path_length_m": self.path_length,
            "coverage_fraction": self.coverage,
            **self.limits,
            "planning_time_s": self.planning_time,
            "region_area_m2": float(self.region.area),
            **({} if self.missed is None else self.missed.summary()),
            **({} if self.mission is None else self.mission.summary()),
            "options": asdict(self.options),
            "vehicle_limits": self.options.limits.as_dict(),
            "limits_held": "per axis"
            if self.options.per_axis
            else (f"norms (acceleration and jerk by an inscribed {self.options.norm_sides}-gon)"),
            "lp": None
            if lp is None
            else {
                "grid_points": int(lp.u.size),
                "iterations": lp.iterations,
                "solve_time_s": lp.solve_time,
            },
        } | (
            {}
            if target is None
            else {"target": target.summary(), "planned_coverage_fraction": self.planned_coverage}
        )


def grid_points(length: float) -> int:
    """Speed-LP grid size for a path of ``length`` metres (spacing ~5 cm, bounded)."""
    lo, hi = GRID_POINTS
    return int(min(max(math.ceil(length / GRID_SPACING_M), lo), hi))


def is_convex(region: Polygon) -> bool:
    """Whether ``region`` equals its convex hull (to round-off)."""
    return bool(region.convex_hull.area - region.area <= 1e-9 * region.area)


def covering_waypoints(region: Polygon, options: CoverageOptions) -> FloatArray:
    """The pattern's waypoints: a spline's control polygon, or the stop points.

    Concave regions are decomposed into convex parts, covered one after the
    other along one continuous path. Waypoints closer than
    :data:`MERGE_FRACTION` of ``delta`` to the previous one are merged
    (:func:`~skyquill.coverage.paths.merge_close`).
    """
    return merge_close(_waypoints(region, options), MERGE_FRACTION * options.delta)


def _waypoints(region: Polygon, options: CoverageOptions) -> FloatArray:
    w, d, eps = options.width, options.delta, options.epsilon
    if options.pattern == "spiral":
        if is_convex(region):
            rings = contours(region, w, options.contours, epsilon=eps)
            return spiral_control_points(rings, d, drift=options.drift)
        from skyquill.coverage.joined import multi_spiral_control_points

        return multi_spiral_control_points(region, eps * w, mode=options.contours, delta=d)
    # The sweep lines' spacing is the swath; epsilon < 1 packs them closer.
    if is_convex(region):
        stops = zigzag(region, eps * w, perimeter=options.perimeter)
    else:
        from skyquill.coverage.joined import multi_zigzag

        stops = multi_zigzag(region, eps * w, perimeter=options.perimeter)
    if options.pattern == "zigzag-stop":
        return stops
    return with_corner_points(merge_close(stops, MERGE_FRACTION * d), d)


def covering_path(region: Polygon, options: CoverageOptions) -> tuple[FloatArray, FloatArray]:
    """The pattern's waypoints ``(K, 2)`` and its flown path densely sampled ``(M, 2)``, m."""
    waypoints = covering_waypoints(region, options)
    if options.pattern == "zigzag-stop":
        return waypoints, _densified(waypoints)
    return waypoints, _dense(spiral_curve(waypoints))


def tune_coverage(
    region: Polygon, options: CoverageOptions, target: float
) -> tuple[CoverageOptions, float]:
    """The fastest options whose path covers ``target`` of the region, and their coverage.

    See :func:`plan_tuned`, which also returns the plan.
    """
    plan = plan_tuned(region, options, target)
    return plan.options, plan.coverage


def plan_tuned(
    region: Region,
    options: CoverageOptions,
    target: float = DEFAULT_MIN_COVERAGE,
    *,
    progress: Progress | None = None,
) -> CoveragePlan:
    """The fastest plan whose path covers ``target`` of the region.

    For every ``epsilon`` in :data:`TUNING_EPSILONS` and, for zigzags, without
    and with a perimeter lap, the roundest corners that still reach
    ``target`` are found by geometry alone: ``delta`` in :data:`TUNING_DELTAS`
    from the largest down (at one spacing a larger ``delta`` is shorter and
    faster; the stop-and-go zigzag has no ``delta``). The candidates are
    ranked by a coarse speed LP (:func:`_estimated_duration`; path length
    alone misjudges them: a denser spacing with rounder corners can fly
    faster than a wider one with sharp corners), the best
    :data:`TUNED_FULL_PLANS` are planned in full and the shortest flight wins.

    All trials share one ``options.time_limit``; ``progress`` is told every
    step (see :class:`~skyquill.coverage.deadline.Deadline`).

    Raises
    ------
    InfeasibleError
        No candidate reaches ``target``, or none that does can be timed; the
        time limit is spent (family ``"time_limit"``).
    """
    goal = as_float("min_coverage", target, positive=True)
    if goal > 1.0:
        raise InputError(f"min_coverage: got {goal:g}, expected a fraction in (0, 1]")
    # The sparsest spacing must fit the path-length cap and the budget; denser
    # ones that do not are skipped by the tuning (a 10 ha field at a 5 m swath).
    _check_region(region, replace(options, epsilon=max(TUNING_EPSILONS)))
    deadline = Deadline(options.time_limit, progress)
    if options.target is not None:
        # Trials are compared as planned; only the winner is re-fitted for the target.
        untargeted = _tuned(region, replace(options, target=None), goal, deadline)
        return _for_target(untargeted, replace(untargeted.options, target=options.target), deadline)
    return _tuned(region, options, goal, deadline)


def _tuned(
    region: Region, options: CoverageOptions, goal: float, deadline: Deadline
) -> CoveragePlan:
    """:func:`plan_tuned` after its checks, within ``deadline``."""
    if _in_pieces(region, options):
        return _tuned_mission(region, options, goal, deadline)
    if options.pattern == "zigzag-jerk":
        return _plan_jerk(region, options, deadline, goal)
    deltas = (options.delta,) if options.pattern == "zigzag-stop" else TUNING_DELTAS
    laps = (False,) if options.pattern == "spiral" else (False, True)
    candidates: list[tuple[CoverageOptions, FloatArray]] = []
    best = 0.0
    roundest = max(deltas)
    for lap in laps:
        # Spacings from the widest: once one reaches the goal with the roundest
        # corners, a denser one (more and longer lanes, corners no rounder)
        # cannot fly faster, and is not tried.
        for eps in _fitting_epsilons(region, options):
            found = _roundest_reaching(region, replace(options, epsilon=eps, perimeter=lap),
                                       deltas, goal, deadline)  # fmt: skip
            best = max(best, found[2])
            if found[0] is not None:
                candidates.append((found[0], found[1]))
                if found[0].delta == roundest:
                    break
    if not candidates:
        raise InfeasibleError(
            f"min_coverage: got {goal:g}, but the best {options.pattern} path covers only "
            f"{best:.4f} of the region (tried epsilon {TUNING_EPSILONS}, delta {deltas})",
            ("coverage",),
        )
    plans = _best_planned(region, candidates, deadline)
    if not plans:
        raise InfeasibleError(
            f"min_coverage: {len(candidates)} {options.pattern} path(s) cover {goal:g} of the "
            "region, but none of them could be timed within the limits",
            ("coverage", "speed_lp"),
        )
    return min(plans, key=lambda plan: plan.duration)


def _roundest_reaching(
    region: Polygon,
    options: CoverageOptions,
    deltas: tuple[float, ...],
    goal: float,
    deadline: Deadline,
) -> tuple[CoverageOptions | None, FloatArray, float]:
    """The roundest corners (largest ``delta``) whose path covers ``goal``: the options (None
    if none does), their waypoints and the best coverage seen."""
    best = 0.0
    for delta in sorted(deltas, reverse=True):
        trial = replace(options, delta=delta)
        deadline.check(f"the tuning trial epsilon={trial.epsilon:g}, delta={delta:g}")
        waypoints, path = covering_path(region, trial)
        covered = coverage_fraction(region, path, trial.width)
        best = max(best, covered)
        if covered >= goal:
            return trial, waypoints, best
    return None, np.zeros((0, 2)), best


def _fitting_epsilons(region: Polygon, options: CoverageOptions) -> list[float]:
    """The tuning's spacings whose estimated path fits the length cap and the budget."""
    fitting = []
    for eps in TUNING_EPSILONS:
        try:
            _check_region(region, replace(options, epsilon=eps))
        except InputError:
            continue
        fitting.append(eps)
    return fitting


def _tuned_mission(
    region: Region, options: CoverageOptions, goal: float, deadline: Deadline
) -> CoveragePlan:
    """The mission with each hole-free piece tuned to leave :data:`MISSION_MISS_SHARE` of
    the miss ``goal`` allows.

    A mission covers less than its pieces do: the spray closes where a
    piece's path comes within half a swath of a hole (the headland laps
    round the holes sweep most of that band back), and what the planning
    obstacles add to the holes is missed.

    Raises
    ------
    InfeasibleError
        The mission does not reach ``goal`` (family ``"coverage"``; the
        message says how close it came), or the time limit is spent.
    """
    piece_goal = 1.0 - MISSION_MISS_SHARE * (1.0 - goal)
    tune = functools.partial(_tuned_piece, options=options, goal=piece_goal)
    plan = _plan_mission(region, options, deadline, tune)
    if plan.coverage < goal:
        raise InfeasibleError(
            f"min_coverage: got {goal:g}, but the {options.pattern} mission covers "
            f"{plan.coverage:.4f} of the region with its pieces at {piece_goal:g} (the spray "
            "closes within half a swath of the holes); ask for less coverage or try the "
            "zigzag pattern",
            ("coverage",),
        )
    return plan


def _tuned_piece(
    piece: Polygon, deadline: Deadline, *, options: CoverageOptions, goal: float
) -> CoveragePlan:
    return _tuned(piece, options, goal, deadline)


def _best_planned(
    region: Polygon, candidates: list[tuple[CoverageOptions, FloatArray]], deadline: Deadline
) -> list[CoveragePlan]:
    """The candidates planned in full: the best estimated that plans, and the next ones
    estimated within :data:`ESTIMATE_MARGIN` of it, at most :data:`TUNED_FULL_PLANS`."""
    if candidates[0][0].pattern == "zigzag-stop":  # no LP: planning it is the estimate
        return [p for trial, _ in candidates if (p := _plan_or_none(region, trial, deadline))]
    estimates = []
    for trial, waypoints in candidates:
        deadline.check(f"the estimate of epsilon={trial.epsilon:g}, delta={trial.delta:g}")
        estimates.append(_estimated_duration(waypoints, trial, deadline))
    plans: list[CoveragePlan] = []
    for k in np.argsort(estimates, kind="stable"):
        if plans and estimates[k] > ESTIMATE_MARGIN * min(estimates):
            break
        if (plan := _plan_or_none(region, candidates[k][0], deadline)) is not None:
            plans.append(plan)
        if len(plans) == TUNED_FULL_PLANS:
            break
    return plans


def _estimated_duration(
    waypoints: FloatArray, options: CoverageOptions, deadline: Deadline
) -> float:
    """The flight time of ``waypoints``' spline by a coarse speed LP, s (inf: not timed).

    :data:`ESTIMATE_GRID` points, :data:`ESTIMATE_JERK_ITERATIONS` pseudo-jerk
    solves, no refinement: ~0.1 s where the full plan takes 1-7 s. On the held-out
    regions (a 47 x 30 m concave hexagon, a triangle, a star, the paper's square;
    spiral and zigzag at 99 %) it came out 2-25 % above the full plan's time but
    ranked the candidates so that the best of the first two planned in full was the
    fastest of all, or within 1 % of it.
    """
    try:
        speed = plan_speed(
            spiral_curve(waypoints), options.vmax, options.amax, options.jmax,
            n=ESTIMATE_GRID, jerk_iterations=ESTIMATE_JERK_ITERATIONS, refine_rounds=0,
            max_excess=None, norm_sides=options.limit_norm_sides, deadline=deadline,
        )  # fmt: skip
    except InfeasibleError as exc:
        if is_time_limit(exc):
            raise
        return math.inf
    return float(speed.duration)


def _check_region(region: Region, options: CoverageOptions) -> None:
    """Refuse a region too large, a path too long or a budget too short, before any path is
    built."""
    if not isinstance(region, Polygon | MultiPolygon):
        raise InputError(
            f"region: got {type(region).__name__}, expected a shapely Polygon or MultiPolygon"
        )
    minx, miny, maxx, maxy = region.bounds
    if max(maxx - minx, maxy - miny) > MAX_REGION_SIZE_M:
        raise InputError(
            f"region: got a region {maxx - minx:.4g} x {maxy - miny:.4g} m, expected at most "
            f"{MAX_REGION_SIZE_M:g} m across (split it into several missions)"
        )
    check_width(region, options.width, options.epsilon)
    _check_budget(region, options)
    if options.target is not None:
        if has_keepouts(region):
            raise InputError(
                "target: got an upload target for a region with holes or several fields, "
                "expected none (the re-fit would not keep the spray off over the transits)"
            )
        assert isinstance(region, Polygon)  # no keep-outs: one field
        check_target_path(region, options.width, options.epsilon, options.target)


def _check_budget(region: Region, options: CoverageOptions) -> None:
    """Refuse a time limit shorter than the estimated planning time (nothing is built)."""
    length = estimate_path_length(region, options.epsilon * options.width)
    need = PLANNING_S_PER_M * length
    if need > options.time_limit:
        raise InputError(
            f"time_limit: got {options.time_limit:g} s, expected at least {need:.3g} s for a "
            f"path of about {length / 1e3:.3g} km ({1e3 * PLANNING_S_PER_M:g} ms per metre "
            "estimated): allow more time, widen the swath or split the region"
        )


def _plan_or_none(
    region: Polygon, options: CoverageOptions, deadline: Deadline
) -> CoveragePlan | None:
    """The plan, or ``None`` where the path cannot be timed within the limits.

    A spent budget is not such a path: it is raised.
    """
    try:
        return _plan(region, options, deadline)
    except InfeasibleError as exc:
        if is_time_limit(exc):
            raise
        return None


def _length(path: FloatArray) -> float:
    return float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())


def plan_coverage(
    region: Region,
    options: CoverageOptions | None = None,
    *,
    progress: Progress | None = None,
) -> CoveragePlan:
    """Plan a coverage flight of ``region``: path, speed, setpoints, coverage, limits.

    Parameters
    ----------
    region
        The region (shapely Polygon, m), e.g. from
        :func:`~skyquill.coverage.regions.load_region`; with holes, or a
        MultiPolygon of several fields: flown as one mission of hole-free
        pieces (see :mod:`skyquill.coverage.mission`).
    options
        :class:`CoverageOptions` (defaults: the paper's §4 limits, spiral).
    progress
        Told ``(step, elapsed_s, time_limit_s)`` at every step (a CLI's bar).

    Raises
    ------
    InputError
        Width not positive or too large for the region, bad options; a path
        estimated longer than :data:`~skyquill.coverage.regions.MAX_PATH_LENGTH_M`,
        or a ``time_limit`` below its estimated planning time (refused before
        it is built; the speed LP's size is capped by :data:`GRID_POINTS` and ``grid``).
    InfeasibleError
        The path cannot be timed within the limits. A concave region's
        spiral whose joins are too tight to time is flown part by part,
        resting at each join (``limits["joins"] == "stop"``) before that.
        With ``options.target``: the re-fit needs more uploads than
        :data:`~skyquill.optimize.budget.MAX_UPLOADS` (a path estimated longer
        than :data:`~skyquill.coverage.target.MAX_TARGET_PATH_M` is an
        :class:`InputError` before any work). The time limit is spent
        (family ``"time_limit"``, the message names the step). A region
        with holes whose flight comes closer to a hole than allowed (family
        ``"keepout"``; never returned).
    """
    opts = options or CoverageOptions()
    return _plan(region, opts, Deadline(opts.time_limit, progress))


def _plan(region: Region, opts: CoverageOptions, deadline: Deadline) -> CoveragePlan:
    """:func:`plan_coverage` within ``deadline``."""
    if _in_pieces(region, opts):
        _check_region(region, opts)  # refuses what is no (Multi)Polygon
        return _plan_mission(region, opts, deadline, lambda piece, dl: _plan(piece, opts, dl))
    if opts.target is not None:
        _check_region(region, opts)
        return _for_target(_plan(region, replace(opts, target=None), deadline), opts, deadline)
    if opts.pattern == "zigzag-jerk":
        return _plan_jerk(region, opts, deadline, None)
    start = time.perf_counter()
    _check_region(region, opts)
    deadline.check("the covering path")
    waypoints, path = covering_path(region, opts)
    try:
        timed = _timed_path(waypoints, path, opts, deadline)
        joins = "continuous"
    except InfeasibleError as exc:
        if is_time_limit(exc) or opts.pattern != "spiral" or is_convex(region):
            raise
        # A join squeezed past a reflex corner can be too tight to time: fly
        # each part's spiral rest to rest instead, joined by straight legs.
        waypoints, path, timed = _stop_between_parts(region, opts, deadline)
        joins = "stop"
    trajectory, speed_plan, check = timed
    if check is None:  # stop-and-go legs and parts at rest were not checked on the way
        deadline.check("the dense check")
        check = verify(trajectory, coverage_limits(opts), guaranteed=False)
    limits = limits_report(check)
    deadline.check("the coverage measure")
    coverage, missed = _measured(region, path, opts.width)
    return CoveragePlan(
        region=region,
        options=opts,
        waypoints=waypoints,
        path=path,
        trajectory=trajectory,
        coverage=coverage,
        limits=limits | {"joins": joins},
        planning_time=time.perf_counter() - start,
        speed_plan=speed_plan,
        missed=missed,
    )


def _in_pieces(region: Region, options: CoverageOptions) -> bool:
    """Whether ``region`` is flown as a mission of pieces: holes, several fields, or a
    concave field for the jerk-zigzag (whose lanes need a convex region)."""
    if has_keepouts(region) or not isinstance(region, Polygon):
        return True
    return options.pattern == "zigzag-jerk" and not is_convex(region)


def _plan_jerk(
    region: Polygon, opts: CoverageOptions, deadline: Deadline, goal: float | None
) -> CoveragePlan:
    """The jerk-zigzag over the convex ``region``: the default shape, or with a ``goal``
    the fastest of the tuning grid that covers it."""
    start = time.perf_counter()
    _check_region(region, opts)
    limits = AxisLimits.from_limits(opts.vmax, opts.amax, opts.jmax, per_axis=opts.per_axis)
    if goal is None:
        shapes = [default_shape(region, opts.width, opts.epsilon)]
    else:
        shapes = tuning_shapes(region, opts.width)
    found = fastest(
        region, shapes, limits, opts.altitude,
        accept=lambda path: goal is None or coverage_fraction(region, path, opts.width) >= goal,
        step=deadline.check,
    )  # fmt: skip
    if found is None:
        raise InfeasibleError(
            f"pattern 'zigzag-jerk': got a region none of {len(shapes)} lane layout(s) fits "
            + ("" if goal is None else f"with {goal:g} coverage ")
            + "(lanes too short to turn at speed?), expected room for two lanes and their turns",
            ("coverage",),
        )
    flight, path = found
    check = _within_limits(flight.trajectory, opts, "flight", deadline)
    coverage, missed = _measured(region, path, opts.width)
    return CoveragePlan(
        region=region,
        options=opts,
        waypoints=flight.waypoints,
        path=path,
        trajectory=flight.trajectory,
        coverage=coverage,
        limits=limits_report(check) | {"joins": "continuous"},
        planning_time=time.perf_counter() - start,
        speed_plan=None,
        missed=missed,
    )


def _within_limits(
    trajectory: Trajectory, opts: CoverageOptions, what: str, deadline: Deadline
) -> Verification:
    """The dense check of ``trajectory``; a ``what`` over :data:`MAX_EXCESS` is refused."""
    deadline.check("the dense check")
    check = verify(trajectory, coverage_limits(opts), guaranteed=False)
    if check.max_excess > MAX_EXCESS:
        raise InfeasibleError(
            f"pattern {opts.pattern!r}: got a {what} {100 * check.max_excess:.1f} % over the "
            f"limits, expected at most {100 * MAX_EXCESS:g} %",
            ("speed_lp",),
        )
    return check


def _plan_mission(
    region: Region,
    opts: CoverageOptions,
    deadline: Deadline,
    plan_piece: Callable[[Polygon, Deadline], CoveragePlan],
) -> CoveragePlan:
    """The mission over ``region``'s hole-free pieces, each planned by ``plan_piece``."""
    start = time.perf_counter()
    legs = LegLimits(opts.vmax, opts.amax, opts.jmax, per_axis=opts.per_axis)
    flight = _flight_of(
        plan_piece if opts.pattern != "spiral" else _spiral_or_zigzag(plan_piece, opts)
    )
    mission = fly_mission(
        region,
        opts.width,
        legs=legs,
        altitude=opts.altitude,
        deadline=deadline,
        plan_piece=flight,
        convex=opts.pattern in {"spiral", "zigzag-jerk"},
    )
    check = _within_limits(mission.trajectory, opts, "mission", deadline)
    return CoveragePlan(
        region=region,
        options=opts,
        waypoints=mission.waypoints,
        path=mission.path,
        trajectory=mission.trajectory,
        coverage=mission.coverage,
        limits=limits_report(check) | {"joins": "stop"},
        planning_time=time.perf_counter() - start,
        speed_plan=None,
        missed=missed_area(region, mission.swept),
        mission=mission,
    )


#: Share of the remaining budget a spiral piece of a mission may spend before it is zigzagged.
SPIRAL_SHARE = 0.25


def _spiral_or_zigzag(
    plan_piece: Callable[[Polygon, Deadline], CoveragePlan], opts: CoverageOptions
) -> Callable[[Polygon, Deadline], CoveragePlan]:
    """``plan_piece``, but a piece whose spiral takes over :data:`SPIRAL_SHARE` of the
    remaining budget (or cannot be timed) is zigzagged instead.

    The speed LP of some convex parts stalls (a pentagon of 114 m² next to a
    round hole: no plan in 60 s, its mirror image in 3 s); one such part must
    not spend the whole mission's budget.
    """

    def plan(piece: Polygon, deadline: Deadline) -> CoveragePlan:
        share = Deadline(SPIRAL_SHARE * deadline.remaining())
        try:
            return plan_piece(piece, share)
        except InfeasibleError as exc:
            deadline.check("a zigzag for a piece whose spiral failed")
            _log.warning("piece of %.3g m²: spiral failed (%s), zigzag instead", piece.area, exc)
            return _plan(piece, replace(opts, pattern="zigzag"), deadline)

    return plan


def _flight_of(plan_piece: Callable[[Polygon, Deadline], CoveragePlan]) -> PiecePlanner:
    """A piece planner for :func:`fly_mission`: the plan's trajectory and waypoints."""

    def flight(piece: Polygon, deadline: Deadline) -> tuple[Trajectory, FloatArray]:
        plan = plan_piece(piece, deadline)
        return plan.trajectory, plan.waypoints

    return flight


def _measured(region: Polygon, path: FloatArray, width: float) -> tuple[float, Missed]:
    """Covered fraction of ``region`` by ``path``'s swath and what it misses (one buffer)."""
    area = swept(path, width)
    return float(region.intersection(area).area / region.area), missed_area(region, area)


def _for_target(plan: CoveragePlan, options: CoverageOptions, deadline: Deadline) -> CoveragePlan:
    """``plan`` re-fitted into ``options.target``'s uploads, its coverage measured again."""
    assert options.target is not None  # only called with a target
    deadline.check("the re-fit for the target")
    start = time.perf_counter()
    delivered = deliver(plan.path, options.limits, options.width, options.altitude, options.target)
    # The refit holds the limits through the hull: a guaranteed check, unlike the LP's.
    check = verify(delivered.trajectory, coverage_limits(options), guaranteed=True)
    coverage, missed = _measured(plan.region, delivered.path, options.width)
    return replace(
        plan,
        options=options,
        path=delivered.path,
        trajectory=delivered.trajectory,
        coverage=coverage,
        missed=missed,
        limits=limits_report(check) | {"joins": plan.limits["joins"]},
        planning_time=plan.planning_time + time.perf_counter() - start,
        delivered=delivered,
        planned_coverage=plan.coverage,
    )


#: A timed path: its trajectory, its speed plan (None for stop-and-go) and the dense check
#: already made of it (None when none was needed to accept it).
_Timed = tuple[Trajectory, SpeedPlan | None, Verification | None]


def coverage_limits(options: CoverageOptions) -> tuple[DerivativeLimit, ...]:
    """The limits of a coverage flight (3-D, at constant height), as the verifier states them.

    The speed is the norm; acceleration and jerk the horizontal norms, or per
    axis when the options say so (the flight is level: the horizontal norm is
    the norm). Checked by their true shapes, whatever polygon the LP used.
    """

    def norm(order: int, bound: float) -> CylinderLimit:
        return CylinderLimit(order, bound, z_lower=-bound, z_upper=bound)

    if not options.per_axis:
        return (norm(1, options.vmax), norm(2, options.amax), norm(3, options.jmax))
    return (
        norm(1, options.vmax),
        BoxLimit.symmetric(2, options.amax, 3),
        BoxLimit.symmetric(3, options.jmax, 3),
    )


def _lifted(points: FloatArray, altitude: float) -> FloatArray:
    return np.column_stack([points, np.full(points.shape[0], altitude)])


def _timed_path(
    waypoints: FloatArray, path: FloatArray, opts: CoverageOptions, deadline: Deadline
) -> _Timed:
    """The path's trajectory at the flight height and its speed plan (``None`` for stop-and-go)."""
    if opts.pattern == "zigzag-stop":
        legs = LegLimits(opts.vmax, opts.amax, opts.jmax, per_axis=opts.per_axis)
        flown = stop_and_go(_lifted(waypoints, opts.altitude), legs)
        return flown.trajectory, None, None
    length = _length(path)
    n = opts.grid or grid_points(length)
    speed_plan, trajectory, check = _timed(
        spiral_curve(waypoints), opts, n, deadline, length=length
    )
    return trajectory, speed_plan, check


def _stop_between_parts(
    region: Polygon, opts: CoverageOptions, deadline: Deadline
) -> tuple[FloatArray, FloatArray, _Timed]:
    """Each part's spiral timed on its own, the joins flown as stop-and-go legs."""
    from skyquill.coverage.joined import multi_spiral_pieces

    spirals, routes = multi_spiral_pieces(
        region, opts.epsilon * opts.width, mode=opts.contours, delta=opts.delta
    )
    stop = replace(opts, pattern="zigzag-stop")
    pieces: list[tuple[FloatArray, FloatArray, _Timed]] = []
    for k, spiral in enumerate(spirals):
        if k > 0 and len(routes[k - 1]) > 1 and _length(routes[k - 1]) > 1e-9:
            pieces.append(_piece(routes[k - 1], stop, _densified(routes[k - 1]), deadline))
        if len(spiral) > SPLINE_DEGREE:
            pieces.append(_piece(spiral, opts, _dense(spiral_curve(spiral)), deadline))
        elif _length(spiral) > 1e-9:  # a part narrower than the swath: along its spine
            pieces.append(_piece(spiral, stop, _densified(spiral), deadline))
    waypoints = np.vstack([p[0] for p in pieces])
    path = np.vstack([p[1] for p in pieces])
    return waypoints, path, (concatenate([p[2][0] for p in pieces]), None, None)


def _piece(
    waypoints: FloatArray, opts: CoverageOptions, path: FloatArray, deadline: Deadline
) -> tuple[FloatArray, FloatArray, _Timed]:
    return waypoints, path, _timed_path(waypoints, path, opts, deadline)


#: Degree of the covering splines (paper 001: 4, so that jerk is differentiable).
SPLINE_DEGREE = 4
#: Largest relative excess over a limit a returned plan may have (issue 5: <= 2 %).
MAX_EXCESS = 0.02
#: A speed plan whose mean speed is below this fraction of vmax has collapsed (the
#: slowest real plans, tiny regions of tight corners, average over 5 %).
MIN_MEAN_SPEED_FRACTION = 0.01
#: Speed-LP grids tried in turn: (grid points as a multiple of ``n``, grid kind).
GRID_LADDER: tuple[tuple[int, Literal["uniform", "adaptive"]], ...] = (
    (1, "uniform"),
    (1, "adaptive"),
    (2, "adaptive"),
)


def _timed(
    curve: Any, options: CoverageOptions, n: int, deadline: Deadline, *, length: float
) -> tuple[SpeedPlan, Trajectory, Verification]:
    """The speed plan on the first grid of :data:`GRID_LADDER` that verifies, its trajectory
    and that check.

    The check is the one dense check of the trajectory the plan becomes (the
    one that is written and flown), not of the planner's own setpoints.

    ``length`` is the path's (m), for the mean speed a collapsed plan is told by.

    A turn shorter than a grid cell (a join of a multi-spiral, the hook at a
    spiral's end) can make the grid LP stop the vehicle between two nodes --
    infeasible on that grid, not on the path -- or leave excess between the
    nodes that local tightening cannot remove; a grid denser there
    (adaptive: half by arc length, half by estimated time) or finer resolves
    most. What none resolves is refused, never returned over the limits.

    Raises
    ------
    InfeasibleError
        No grid gives a plan within :data:`MAX_EXCESS` of the limits; the
        deadline is spent.
    """
    period = 1.0 / options.rate
    seen: list[str] = []
    for factor, kind in GRID_LADDER:
        try:
            plan = plan_speed(
                curve, options.vmax, options.amax, options.jmax,
                n=factor * n, control_period=period, grid=kind,
                norm_sides=options.limit_norm_sides, deadline=deadline,
            )  # fmt: skip
        except InfeasibleError as exc:
            if is_time_limit(exc):
                raise
            seen.append(f"{kind} grid of {factor * n}: {exc}")
            continue
        mean_speed = length / plan.duration
        if mean_speed < MIN_MEAN_SPEED_FRACTION * options.vmax:
            # A grid LP that all but stops the vehicle (a 6 m star: 68 h of flight)
            # is a numerical collapse, not a plan; its dense check alone took 69 s.
            seen.append(f"{kind} grid of {factor * n}: mean speed {mean_speed:.2g} m/s")
            continue
        deadline.check("the timing law")
        trajectory = plan.trajectory(options.altitude)
        deadline.check("the dense check")
        check = verify(trajectory, coverage_limits(options), guaranteed=False)
        excess = check.max_excess
        if excess <= MAX_EXCESS:
            return plan, trajectory, check
        seen.append(f"{kind} grid of {factor * n}: excess {100 * excess:.1f} %")
    raise InfeasibleError(
        f"pattern {options.pattern!r}: could not time the path within the limits ("
        + "; ".join(seen)
        + ")",
        ("speed_lp",),
    )


def _dense(curve: Any) -> FloatArray:
    """``curve`` sampled every ~``COVERAGE_SPACING_M`` (by its control polygon's length)."""
    rough = np.asarray(curve(np.linspace(0.0, 1.0, 2001)), dtype=np.float64)
    length = float(np.linalg.norm(np.diff(rough, axis=0), axis=1).sum())
    m = max(2001, math.ceil(length / COVERAGE_SPACING_M))
    return np.asarray(curve(np.linspace(0.0, 1.0, m)), dtype=np.float64)


def _densified(waypoints: FloatArray) -> FloatArray:
    """A polyline resampled every ~``COVERAGE_SPACING_M`` (its corners kept)."""
    line = LineString(waypoints)
    m = max(2, math.ceil(line.length / COVERAGE_SPACING_M))
    along = np.unique(np.concatenate([np.linspace(0.0, line.length, m), _vertex_distances(line)]))
    return np.array([line.interpolate(s).coords[0] for s in along], dtype=np.float64)


def _vertex_distances(line: LineString) -> FloatArray:
    xy = np.asarray(line.coords, dtype=np.float64)
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xy, axis=0), axis=1))])


def limits_report(check: Verification) -> dict[str, Any]:
    """Largest speed, per-axis |acceleration| and |jerk|, and the largest relative excess."""
    return {
        "max_speed": check.max_speed,
        "max_acc": list(check.max_acc),
        "max_jerk": list(check.max_jerk),
        "max_excess": check.max_excess,
        "limits": check.limits_report(),
    }
