"""Fit a smooth, limit-respecting trajectory to sampled points (``skyquill fit``).

The pipeline: time the points (given; or along the path,
:func:`allocate_path_times`; or rest to rest at every point, the paper's
:func:`allocate_segment_times` for waypoint plans),
minimum-jerk smoothing with point deviation (paper 000 §5.2-5.3, paper 003
§3.3.1), rest at both ends, the vehicle's limits through the convex hull. If
the limits cannot be met in the time given (jerk is not part of the
allocation) the whole timing is stretched by ``stretch_factor`` and the
problem solved again; the factor used is reported, never hidden.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from skyquill.errors import InfeasibleError, InputError
from skyquill.limits import DerivativeLimit, VehicleLimits
from skyquill.optimize.problem import Boundary, PointDeviation, SmoothingProblem
from skyquill.optimize.solve import FitResult, solve
from skyquill.optimize.timing import (
    MAX_COORDINATE_M,
    allocate_path_times,
    allocate_segment_times,
)
from skyquill.solvers import DEFAULT_BACKEND
from skyquill.spline import HullKind
from skyquill.validation import FloatArray, as_array, as_float, as_int, strictly_increasing

MAX_SPANS = 100_000


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
        as_int("max_stretches", self.max_stretches, low=0)
        if self.timing not in ("path", "segments"):
            raise InputError(f"timing: got {self.timing!r}, expected 'path' or 'segments'")
        fraction = as_float(
            "allocation_accel_fraction", self.allocation_accel_fraction, positive=True
        )
        if fraction > 1.0:
            raise InputError(f"allocation_accel_fraction: got {fraction:g}, expected <= 1")


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
    """

    result: FitResult
    points: FloatArray
    times: FloatArray
    time_scale: float
    limits: tuple[DerivativeLimit, ...]
    rms_deviation_m: float
    max_deviation_m: float


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
    """
    opts = options or FitOptions()
    pts = as_array("points", points, ndim=2, max_abs=MAX_COORDINATE_M)
    if pts.shape[1] not in (2, 3) or pts.shape[0] < 2:
        raise InputError(f"points: got shape {pts.shape}, expected (N >= 2, 2 or 3)")
    if times is None:
        vmax, amax = opts.limits.timing_bounds()
        allocate = allocate_path_times if opts.timing == "path" else allocate_segment_times
        t = allocate(pts, vmax, opts.allocation_accel_fraction * amax)
    else:
        t = as_array("times", times, shape=(pts.shape[0],), max_abs=1e7)
        strictly_increasing("times", t)
        t = t - t[0]
    limits = opts.limits.derivative_limits(pts.shape[1], sides=opts.norm_sides)
    scale = 1.0
    for attempt in range(opts.max_stretches + 1):
        try:
            result = solve(_problem(pts, t * scale, limits, opts), opts.solver)
            break
        except InfeasibleError:
            if attempt == opts.max_stretches:
                raise
            scale *= opts.stretch_factor
    err = np.linalg.norm(result.trajectory.evaluate(t * scale) - pts, axis=1)
    return PointFit(
        result, pts, t * scale, scale, limits, float(np.sqrt(np.mean(err**2))), float(err.max())
    )


def _problem(
    pts: FloatArray, t: FloatArray, limits: tuple[DerivativeLimit, ...], opts: FitOptions
) -> SmoothingProblem:
    duration = float(t[-1])
    n_spans = max(1, math.ceil(duration / opts.knot_interval))
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
