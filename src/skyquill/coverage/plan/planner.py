"""``plan_coverage``: one region end to end -- path, timing, dense check, coverage."""

from __future__ import annotations

import functools
import time
from dataclasses import replace

from shapely.geometry import Polygon

from skyquill.coverage.deadline import (
    Deadline,
    Progress,
    is_time_limit,
)
from skyquill.coverage.plan.checks import check_region
from skyquill.coverage.plan.covering import covering_path, is_convex, measured
from skyquill.coverage.plan.jerk import plan_jerk
from skyquill.coverage.plan.options import CoverageOptions
from skyquill.coverage.plan.pieces import in_pieces, plan_mission
from skyquill.coverage.plan.refit import for_target
from skyquill.coverage.plan.result import CoveragePlan, coverage_limits, limits_report
from skyquill.coverage.plan.timing import stop_between_parts, timed_path
from skyquill.coverage.regions import Region
from skyquill.errors import InfeasibleError
from skyquill.parallel import HERE, Where
from skyquill.verify import verify


def plan_coverage(
    region: Region,
    options: CoverageOptions | None = None,
    *,
    progress: Progress | None = None,
    where: Where = HERE,
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
    where
        Where a mission's pieces are planned: one after the other here (the default), or
        at once in a process pool or on a dask cluster.

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
    start = time.perf_counter()
    opts = options or CoverageOptions()
    plan = plan_within(region, opts, Deadline(opts.time_limit, progress), where)
    return replace(plan, planning_time=time.perf_counter() - start)  # the whole planning


def plan_within(
    region: Region, opts: CoverageOptions, deadline: Deadline, where: Where = HERE
) -> CoveragePlan:
    """:func:`plan_coverage` within ``deadline``."""
    if in_pieces(region, opts):
        check_region(region, opts)  # refuses what is no (Multi)Polygon
        return plan_mission(
            region,
            opts,
            deadline,
            functools.partial(_piece, options=opts),
            zigzag=functools.partial(zigzag_piece, options=opts),
            where=where,
        )
    if opts.target is not None:
        check_region(region, opts)
        return for_target(plan_within(region, replace(opts, target=None), deadline), opts, deadline)
    if opts.pattern == "zigzag-jerk":
        return plan_jerk(region, opts, deadline, None)
    start = time.perf_counter()
    check_region(region, opts)
    deadline.check("the covering path")
    waypoints, path = covering_path(region, opts)
    try:
        timed = timed_path(waypoints, path, opts, deadline)
        joins = "continuous"
    except InfeasibleError as exc:
        if is_time_limit(exc) or opts.pattern != "spiral" or is_convex(region):
            raise
        # A join squeezed past a reflex corner can be too tight to time: fly
        # each part's spiral rest to rest instead, joined by straight legs.
        waypoints, path, timed = stop_between_parts(region, opts, deadline)
        joins = "stop"
    trajectory, speed_plan, check = timed
    if check is None:  # stop-and-go legs and parts at rest were not checked on the way
        deadline.check("the dense check")
        check = verify(trajectory, coverage_limits(opts), guaranteed=False)
    limits = limits_report(check)
    deadline.check("the coverage measure")
    coverage, missed = measured(region, path, opts.width)
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


def _piece(piece: Polygon, deadline: Deadline, *, options: CoverageOptions) -> CoveragePlan:
    """One hole-free piece of a mission, planned with the mission's ``options``."""
    return plan_within(piece, options, deadline)


def zigzag_piece(piece: Polygon, deadline: Deadline, *, options: CoverageOptions) -> CoveragePlan:
    """``piece`` planned as a smoothed zigzag (a mission's fallback for a spiral piece)."""
    return plan_within(piece, replace(options, pattern="zigzag"), deadline)
