"""The jerk-zigzag pattern's plan: straight lanes joined by Ruckig's time-optimal turns."""

from __future__ import annotations

import time

from shapely.geometry import Polygon

from skyquill.coverage.deadline import Deadline
from skyquill.coverage.jerk_zigzag import AxisLimits, default_shape, fastest, tuning_shapes
from skyquill.coverage.plan.checks import check_region
from skyquill.coverage.plan.covering import measured
from skyquill.coverage.plan.options import CoverageOptions
from skyquill.coverage.plan.result import CoveragePlan, limits_report
from skyquill.coverage.plan.timing import within_limits
from skyquill.coverage.regions import coverage_fraction
from skyquill.errors import InfeasibleError


def plan_jerk(
    region: Polygon, opts: CoverageOptions, deadline: Deadline, goal: float | None
) -> CoveragePlan:
    """The jerk-zigzag over the convex ``region``: the default shape, or with a ``goal``
    the fastest of the tuning grid that covers it."""
    start = time.perf_counter()
    check_region(region, opts)
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
            f"pattern: got 'zigzag-jerk' for a region none of {len(shapes)} lane layout(s) fits "
            + ("" if goal is None else f"with {goal:g} coverage ")
            + "(lanes too short to turn at speed?), expected room for two lanes and their turns "
            "(or another pattern)",
            ("coverage",),
        )
    flight, path = found
    check = within_limits(flight.trajectory, opts, "flight", deadline)
    coverage, missed = measured(region, path, opts.width)
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
