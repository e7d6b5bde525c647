"""Timing a covering path: the speed plan on a ladder of grids, stop-and-go legs, parts at rest,
the dense check.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from shapely.geometry import Polygon

from skyquill.coverage.deadline import (
    Deadline,
    is_time_limit,
)
from skyquill.coverage.paths import spiral_curve
from skyquill.coverage.plan.covering import (
    SPLINE_DEGREE,
    dense_path,
    densified,
    grid_points,
    path_length,
)
from skyquill.coverage.plan.options import CoverageOptions
from skyquill.coverage.plan.result import coverage_limits
from skyquill.coverage.speed import SpeedPlan, plan_speed
from skyquill.errors import InfeasibleError
from skyquill.optimize.legs import LegLimits, stop_and_go
from skyquill.trajectory import Trajectory, concatenate
from skyquill.verify import Verification, verify

FloatArray = NDArray[np.float64]


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


#: A timed path: its trajectory, its speed plan (None for stop-and-go) and the dense check
#: already made of it (None when none was needed to accept it).
Timed = tuple[Trajectory, SpeedPlan | None, Verification | None]


def lifted(points: FloatArray, altitude: float) -> FloatArray:
    return np.column_stack([points, np.full(points.shape[0], altitude)])


def timed_path(
    waypoints: FloatArray, path: FloatArray, opts: CoverageOptions, deadline: Deadline
) -> Timed:
    """The path's trajectory at the flight height and its speed plan (``None`` for stop-and-go)."""
    if opts.pattern == "zigzag-stop":
        legs = LegLimits(opts.vmax, opts.amax, opts.jmax, per_axis=opts.per_axis)
        flown = stop_and_go(lifted(waypoints, opts.altitude), legs)
        return flown.trajectory, None, None
    length = path_length(path)
    n = opts.grid or grid_points(length)
    speed_plan, trajectory, check = _timed(
        spiral_curve(waypoints), opts, n, deadline, length=length
    )
    return trajectory, speed_plan, check


def stop_between_parts(
    region: Polygon, opts: CoverageOptions, deadline: Deadline
) -> tuple[FloatArray, FloatArray, Timed]:
    """Each part's spiral timed on its own, the joins flown as stop-and-go legs."""
    from skyquill.coverage.joined import multi_spiral_pieces

    spirals, routes = multi_spiral_pieces(
        region, opts.epsilon * opts.width, mode=opts.contours, delta=opts.delta
    )
    stop = replace(opts, pattern="zigzag-stop")
    pieces: list[tuple[FloatArray, FloatArray, Timed]] = []
    for k, spiral in enumerate(spirals):
        if k > 0 and len(routes[k - 1]) > 1 and path_length(routes[k - 1]) > 1e-9:
            pieces.append(_piece(routes[k - 1], stop, densified(routes[k - 1]), deadline))
        if len(spiral) > SPLINE_DEGREE:
            pieces.append(_piece(spiral, opts, dense_path(spiral_curve(spiral)), deadline))
        elif path_length(spiral) > 1e-9:  # a part narrower than the swath: along its spine
            pieces.append(_piece(spiral, stop, densified(spiral), deadline))
    waypoints = np.vstack([p[0] for p in pieces])
    path = np.vstack([p[1] for p in pieces])
    return waypoints, path, (concatenate([p[2][0] for p in pieces]), None, None)


def _piece(
    waypoints: FloatArray, opts: CoverageOptions, path: FloatArray, deadline: Deadline
) -> tuple[FloatArray, FloatArray, Timed]:
    return waypoints, path, timed_path(waypoints, path, opts, deadline)


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


def within_limits(
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
