"""Fit a smooth, limit-respecting trajectory to sampled points (``skyquill fit``).

The pipeline: time the points (given; or along the path,
:func:`allocate_path_times`; or rest to rest at every point, the paper's
:func:`allocate_segment_times` for waypoint plans),
minimum-jerk smoothing with point deviation (paper 000 §5.2-5.3, paper 003
§3.3.1), rest at both ends, the vehicle's limits through the convex hull. If
the limits cannot be met in the time given (jerk is not part of the
allocation) the whole timing is stretched by ``stretch_factor`` and the
problem solved again; the factor used is reported, never hidden. A fit
farther from the points than the tolerance is not a result: allocated timings
are redone slower, then it is an :class:`~skyquill.errors.InfeasibleError`
(unless ``best_effort``).

With a ``target`` (a vehicle's upload budget) the fit is made of degree-7
pieces, at most one upload's worth over the whole flight; if that misses the
tolerance, allocated timings are cut into uploads flown rest to rest with a
hover between them (:mod:`skyquill.optimize.budget`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np

from skyquill.errors import InfeasibleError, InputError
from skyquill.limits import DerivativeLimit, VehicleLimits
from skyquill.optimize.budget import BudgetPlan, ChunkFit, one_upload, split_into_uploads
from skyquill.optimize.problem import Boundary, PointDeviation, SmoothingProblem
from skyquill.optimize.solve import FitResult, solve
from skyquill.optimize.timing import (
    MAX_COORDINATE_M,
    allocate_path_times,
    allocate_segment_times,
)
from skyquill.solvers import DEFAULT_BACKEND
from skyquill.spline import HullKind
from skyquill.targets import UploadTarget
from skyquill.trajectory import Trajectory
from skyquill.validation import FloatArray, as_array, as_float, as_int, strictly_increasing
from skyquill.verify import Verification

#: Most knot spans one fit may have: the QP has ``(spans + degree) * d``
#: unknowns and a hull constraint block per span and limit, solved up to
#: ``MAX_SLOWDOWNS + 1`` times. 50,000 spans (``--timing segments``) took 260 s
#: and 1 GB; at 20,000 the worst fit stays within the memory and time every
#: ceiling promises (docs/ceilings.md, measured by bench/ceilings.py).
MAX_SPANS = 20_000
#: Most points one fit may take: each is a row of the deviation block
#: (``degree + 1`` nonzeros per axis); 200 k points is a tablet recording
#: of over half an hour at 100 Hz: beyond it, resample first.
MAX_POINTS = 200_000
#: Default fidelity tolerance as a fraction of the points' bounding-box
#: diagonal when the timing is allocated (path or segments): the allocation
#: slows in turns, so the fit follows the points closely (bundled spiral: 10 mm
#: of a 1.1 m diagonal); a fit farther off is not the drawing asked for.
TOLERANCE_FRACTION = 0.01
#: The same with the caller's times (a tablet's clock): the fit is measured at
#: each point's recorded time, and a hand faster than the limits allow makes
#: the fit lag behind its clock, so the deviation measures the clock more than
#: the shape (bundled spiral: 74 mm RMS, 241 mm max, 22 % of its 1.08 m
#: diagonal, at the default limits); only a fit that lost the drawing is refused.
GIVEN_TOLERANCE_FRACTION = 0.3
#: How many times an allocated timing is redone with half the acceleration
#: when the fit misses the tolerance (bundled waypoints at 1.5 m/s, 1 m/s^2,
#: 4 m/s^3: 250 mm off at 0.5, 0.1 mm at 0.25); each costs one more solve.
MAX_SLOWDOWNS = 3


@dataclass(frozen=True)
class FitOptions:
    """Knobs of :func:`fit_points` (SI units).

    Attributes
    ----------
    limits
        The vehicle's limits (``vmax`` is the speed, ``amax`` and ``jmax`` the
        norms; per-axis boxes only as ``*_axis``), held on the whole trajectory
        through the convex hull.
    norm_sides
        ``None``: the norms are held exactly (second-order cones on every hull
        point, Clarabel); an integer ``m``: by the inscribed polytope of
        :class:`~skyquill.limits.NormLimit` with ``m`` sides (a QP).
    degree
        Spline degree (5: continuous jerk).
    weight
        ``omega`` of the point deviation against the jerk cost.
    knot_interval
        Seconds per knot span.
    hull
        ``"bspline"`` or ``"bezier"``.
    solver
        QP backend.
    timing
        How points without times are timed: ``"path"`` (one rest-to-rest
        profile along the whole path, slowing in turns: drawings) or
        ``"segments"`` (rest to rest between consecutive points, paper 003
        §3.5: sparse waypoint plans, flown through every corner).
    allocation_accel_fraction
        The allocation plans with this fraction of the acceleration bound. It knows
        nothing of jerk, and at full ``amax`` the jerk-limited fit cannot
        brake in time at the ends and cuts the last turn (spiral example: max
        deviation 51 mm at 1.0, 10 mm at 0.5, 7 mm at 0.35 for 19% more time).
    stretch_factor, max_stretches
        Timing stretch on infeasibility.
    tolerance_m
        Largest accepted distance, m, between a point and the fit at the point's
        time. ``None``: :data:`TOLERANCE_FRACTION` of the points' bounding-box
        diagonal with allocated times, :data:`GIVEN_TOLERANCE_FRACTION` of it
        with the caller's times (see :func:`default_tolerance`).
    best_effort
        Return a fit that misses the tolerance instead of raising
        :class:`~skyquill.errors.InfeasibleError` (as ``WritingOptions.best_effort``).
    target
        A vehicle's upload budget (:data:`skyquill.targets.TARGETS`), or ``None``.
        With one, ``degree`` and ``knot_interval`` are the target's: pieces
        of its highest degree, at most :attr:`~skyquill.targets.UploadTarget.max_pieces`
        spread over the flight (or over each upload when the plan is split).
    """

    limits: VehicleLimits = field(default_factory=lambda: VehicleLimits(1.0, 2.0, 10.0))
    norm_sides: int | None = None
    degree: int = 5
    weight: float = 1e4
    knot_interval: float = 0.1
    hull: HullKind = "bspline"
    timing: Literal["path", "segments"] = "path"
    solver: str = DEFAULT_BACKEND
    allocation_accel_fraction: float = 0.5
    stretch_factor: float = 1.25
    max_stretches: int = 10
    tolerance_m: float | None = None
    best_effort: bool = False
    target: UploadTarget | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.limits, VehicleLimits):
            raise InputError(f"limits: got {type(self.limits).__name__}, expected VehicleLimits")
        self.limits.timing_bounds()  # the allocation needs a speed and an acceleration
        for name in ("weight", "knot_interval"):
            as_float(name, getattr(self, name), positive=True)
        if self.norm_sides is not None:
            as_int("norm_sides", self.norm_sides, low=3, high=1024)
        as_int("degree", self.degree, low=3, high=7)
        if as_float("stretch_factor", self.stretch_factor) <= 1.0:
            raise InputError(f"stretch_factor: got {self.stretch_factor:g}, expected > 1")
        # Every stretch is one more solve; 1.25^50 is already 70 000 times slower.
        as_int("max_stretches", self.max_stretches, low=0, high=50)
        if self.timing not in ("path", "segments"):
            raise InputError(f"timing: got {self.timing!r}, expected 'path' or 'segments'")
        fraction = as_float(
            "allocation_accel_fraction", self.allocation_accel_fraction, positive=True
        )
        if fraction > 1.0:
            raise InputError(f"allocation_accel_fraction: got {fraction:g}, expected <= 1")
        if self.tolerance_m is not None:
            as_float("tolerance_m", self.tolerance_m, positive=True)
        if not isinstance(self.best_effort, bool):
            raise InputError(f"best_effort: got {self.best_effort!r}, expected True or False")
        if self.target is not None and not isinstance(self.target, UploadTarget):
            name = type(self.target).__name__
            raise InputError(f"target: got {name}, expected an UploadTarget or None")


def default_tolerance(points: FloatArray, given_times: bool) -> float:
    """The default fidelity tolerance, m, of a fit to ``points`` (N, d), m.

    A fraction of the bounding-box diagonal (:data:`TOLERANCE_FRACTION`, or
    :data:`GIVEN_TOLERANCE_FRACTION` when the times are the caller's), never
    below 1 mm (a single point's noise).
    """
    diagonal = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
    fraction = GIVEN_TOLERANCE_FRACTION if given_times else TOLERANCE_FRACTION
    return max(fraction * diagonal, 1e-3)


@dataclass(frozen=True)
class PointFit:
    """Result of :func:`fit_points`.

    Attributes
    ----------
    result
        The engine's :class:`FitResult` (trajectory, cost, verification).
    points
        The input points, shape (N, d), m.
    times
        The times the points were fitted at (after stretching), shape (N,), s.
    time_scale
        Total stretch applied to the initial timing (1 if none).
    limits
        The limits imposed.
    rms_deviation_m, max_deviation_m
        ``||p(t_i) - points_i||`` statistics.
    accel_fraction
        The fraction of ``amax`` the allocation used (``None`` with given
        times): ``options.allocation_accel_fraction``, halved up to
        :data:`MAX_SLOWDOWNS` times while the fit missed the tolerance.
    budget
        With ``options.target``: the plan cut into the target's uploads
        (``None`` without). Split into several, ``result`` is the first
        upload's engine result, ``times`` are on the whole plan's clock
        (hovers included), ``time_scale`` is the largest and
        ``accel_fraction`` the smallest over the uploads.
    """

    result: FitResult
    points: FloatArray
    times: FloatArray
    time_scale: float
    limits: tuple[DerivativeLimit, ...]
    rms_deviation_m: float
    max_deviation_m: float
    accel_fraction: float | None = None
    budget: BudgetPlan | None = None

    @property
    def trajectory(self) -> Trajectory:
        """What is flown: the engine's spline, or with a target the plan cut into uploads."""
        return self.result.trajectory if self.budget is None else self.budget.trajectory

    @property
    def verification(self) -> Verification:
        """The dense check of :attr:`trajectory` against :attr:`limits`."""
        return self.result.verification if self.budget is None else self.budget.verification


def fit_points(
    points: FloatArray,
    times: FloatArray | None = None,
    options: FitOptions | None = None,
) -> PointFit:
    """Fit a trajectory that starts and ends at rest at the first and last point.

    Parameters
    ----------
    points
        Shape (N, d), d in {2, 3}, m, N >= 2.
    times
        Shape (N,), s, strictly increasing, or ``None`` to allocate them.
    options
        :class:`FitOptions`; defaults if ``None``.

    Raises
    ------
    InputError
        Bad points, times or options; more than :data:`MAX_POINTS` points or
        :data:`MAX_SPANS` knot spans (refused before the QP is assembled).
    InfeasibleError
        The limits cannot be met within ``max_stretches``, or the fit is farther
        than the tolerance from the points (unless ``best_effort``); allocated
        timings are first redone slower (see ``PointFit.accel_fraction``).
        With ``options.target``: timed points that one upload cannot hold
        within the tolerance (the message says what would fit), or untimed
        ones needing more than :data:`~skyquill.optimize.budget.MAX_UPLOADS`.
    """
    opts = options or FitOptions()
    pts = as_array("points", points, ndim=2, max_abs=MAX_COORDINATE_M)
    if pts.shape[1] not in (2, 3) or pts.shape[0] < 2:
        raise InputError(f"points: got shape {pts.shape}, expected (N >= 2, 2 or 3)")
    if pts.shape[0] > MAX_POINTS:
        raise InputError(
            f"points: got {pts.shape[0]:,} points, expected at most {MAX_POINTS:,} "
            "(resample the recording more coarsely)"
        )
    limits = opts.limits.derivative_limits(pts.shape[1], sides=opts.norm_sides)
    if opts.target is not None:
        # A piece of the highest degree the vehicle evaluates carries the most path.
        opts = replace(opts, degree=opts.target.max_degree)
    if times is not None:
        t = as_array("times", times, shape=(pts.shape[0],), max_abs=1e7)
        strictly_increasing("times", t)
        if opts.target is not None:
            return _timed_for_target(pts, t - t[0], limits, opts, opts.target)
        fit = _fit_timed(pts, t - t[0], limits, opts)
        _check_fidelity(fit.max_deviation_m, pts, True, opts)
        return fit
    if opts.target is not None:
        return _allocated_for_target(pts, limits, opts, opts.target)
    fit = _fit_allocated(pts, limits, opts, _tolerance(pts, False, opts))
    _check_fidelity(fit.max_deviation_m, pts, False, opts)
    return fit


def _fit_allocated(
    pts: FloatArray,
    limits: tuple[DerivativeLimit, ...],
    opts: FitOptions,
    tolerance: float,
    spans: int | None = None,
) -> PointFit:
    """Fit at allocated times, redone slower while farther than ``tolerance`` from ``pts``."""
    # The allocation knows nothing of jerk: when the fit cuts the turns, allocate
    # again with half the acceleration (slower turns), reported in the result.
    vmax, amax = opts.limits.timing_bounds()
    allocate = allocate_path_times if opts.timing == "path" else allocate_segment_times
    fraction = opts.allocation_accel_fraction
    for slowdown in range(MAX_SLOWDOWNS + 1):
        fit = _fit_timed(pts, allocate(pts, vmax, fraction * amax), limits, opts, spans)
        fit = replace(fit, accel_fraction=fraction)
        if fit.max_deviation_m <= tolerance or slowdown == MAX_SLOWDOWNS:
            break
        fraction *= 0.5
    return fit


def _allocated_for_target(
    pts: FloatArray, limits: tuple[DerivativeLimit, ...], opts: FitOptions, target: UploadTarget
) -> PointFit:
    """One upload if it is within the tolerance, else rest-to-rest uploads with hovers."""
    plan = _split_plan(pts, limits, opts, target)
    fractions = [c.accel_fraction for c in plan.chunks if c.accel_fraction is not None]
    return _budget_fit(
        plan, pts, limits, max(c.time_scale for c in plan.chunks), min(fractions, default=None)
    )


def _split_plan(
    pts: FloatArray, limits: tuple[DerivativeLimit, ...], opts: FitOptions, target: UploadTarget
) -> BudgetPlan:
    tolerance = _tolerance(pts, False, opts)

    def fit_chunk(chunk: FloatArray) -> ChunkFit:
        fit = _fit_allocated(chunk, limits, opts, tolerance, target.max_pieces)
        return ChunkFit(
            fit.result, fit.times, fit.max_deviation_m, fit.time_scale, fit.accel_fraction
        )

    return split_into_uploads(pts, fit_chunk, tolerance, target, limits)


def _timed_for_target(
    pts: FloatArray,
    t: FloatArray,
    limits: tuple[DerivativeLimit, ...],
    opts: FitOptions,
    target: UploadTarget,
) -> PointFit:
    """One upload at the caller's times; refused (with what would fit) beyond the tolerance."""
    fit = _fit_timed(pts, t, limits, opts, target.max_pieces)
    tolerance = _tolerance(pts, True, opts)
    if fit.max_deviation_m > tolerance and not opts.best_effort:
        # Splitting would insert rests and hovers into the caller's clock: say what would fit.
        try:
            uploads = len(_split_plan(pts, limits, opts, target).uploads)
            instead = f"the points without their times ({uploads} upload{'s' * (uploads > 1)})"
        except InfeasibleError:
            instead = "fewer points (the points without their times need too many uploads)"
        raise InfeasibleError(
            f"tolerance_m: one {target.name} upload ({target.max_pieces} pieces) at the given "
            f"times is {fit.max_deviation_m * 1e3:.4g} mm from the points at most, expected at "
            f"most {tolerance * 1e3:.4g} mm; more uploads would change the given timing. "
            f"A tolerance_m of {fit.max_deviation_m:.4g} m, or {instead} would fit",
            ("fidelity", "target"),
        )
    chunk = ChunkFit(fit.result, fit.times, fit.max_deviation_m, fit.time_scale)
    return replace(fit, budget=one_upload(chunk, target, limits))


def _budget_fit(
    plan: BudgetPlan,
    pts: FloatArray,
    limits: tuple[DerivativeLimit, ...],
    time_scale: float,
    accel_fraction: float | None,
) -> PointFit:
    err = np.linalg.norm(plan.trajectory.evaluate(plan.times) - pts, axis=1)
    return PointFit(
        plan.chunks[0].result,
        pts,
        plan.times,
        time_scale,
        limits,
        float(np.sqrt(np.mean(err**2))),
        float(err.max()),
        accel_fraction,
        plan,
    )


def _fit_timed(
    pts: FloatArray,
    t: FloatArray,
    limits: tuple[DerivativeLimit, ...],
    opts: FitOptions,
    spans: int | None = None,
) -> PointFit:
    """Fit at times ``t`` (N,), stretched by ``stretch_factor`` while infeasible.

    ``spans``: the number of knot spans (else one per ``knot_interval``).
    """
    scale = 1.0
    for attempt in range(opts.max_stretches + 1):
        try:
            result = solve(_problem(pts, t * scale, limits, opts, spans), opts.solver)
            break
        except InfeasibleError:
            if attempt == opts.max_stretches:
                raise
            scale *= opts.stretch_factor
    err = np.linalg.norm(result.trajectory.evaluate(t * scale) - pts, axis=1)
    return PointFit(
        result, pts, t * scale, scale, limits, float(np.sqrt(np.mean(err**2))), float(err.max())
    )


def _tolerance(pts: FloatArray, given: bool, opts: FitOptions) -> float:
    return opts.tolerance_m if opts.tolerance_m is not None else default_tolerance(pts, given)


def _check_fidelity(max_dev: float, pts: FloatArray, given: bool, opts: FitOptions) -> None:
    """Raise InfeasibleError when the fit is farther than the tolerance from the points."""
    tol = _tolerance(pts, given, opts)
    if max_dev <= tol or opts.best_effort:
        return
    helps = (
        "times further apart (slower), looser limits"
        if given
        else "slower timing (a lower vmax), looser amax/jmax"
    )
    raise InfeasibleError(
        f"tolerance_m: the fit is {max_dev * 1e3:.4g} mm from the points at most, expected "
        f"at most {tol * 1e3:.4g} mm; {helps}, a shorter knot_interval (more knots), "
        "a larger tolerance_m or best_effort would help",
        ("fidelity",),
    )


def _problem(
    pts: FloatArray,
    t: FloatArray,
    limits: tuple[DerivativeLimit, ...],
    opts: FitOptions,
    spans: int | None = None,
) -> SmoothingProblem:
    duration = float(t[-1])
    n_spans = spans or max(1, math.ceil(duration / opts.knot_interval))
    if n_spans > MAX_SPANS:
        raise InputError(
            f"knot_interval: got {opts.knot_interval:g} s for a {duration:.6g} s plan, i.e. "
            f"{n_spans} knot spans, expected at most {MAX_SPANS} (are the points in metres?)"
        )
    return SmoothingProblem(
        dim=pts.shape[1],
        degree=opts.degree,
        n_ctrl=n_spans + opts.degree,
        duration=duration,
        smoothness={3: 1.0},
        deviations=(PointDeviation(t, pts, opts.weight),),
        boundary=Boundary.rest(pts[0], pts[-1], 3),
        limits=limits,
        hull=opts.hull,
    )
