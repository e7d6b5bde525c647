"""A plan re-fitted into a vehicle's upload budget (``CoverageOptions.target``)."""

from __future__ import annotations

import time
from dataclasses import replace

from skyquill.coverage.deadline import Deadline
from skyquill.coverage.plan.covering import measured
from skyquill.coverage.plan.options import CoverageOptions
from skyquill.coverage.plan.result import CoveragePlan, coverage_limits, limits_report
from skyquill.coverage.target import deliver
from skyquill.verify import verify


def for_target(plan: CoveragePlan, options: CoverageOptions, deadline: Deadline) -> CoveragePlan:
    """``plan`` re-fitted into ``options.target``'s uploads, its coverage measured again."""
    assert options.target is not None  # only called with a target
    deadline.check("the re-fit for the target")
    start = time.perf_counter()
    delivered = deliver(plan.path, options.limits, options.width, options.altitude, options.target)
    # The refit holds the limits through the hull: a guaranteed check, unlike the LP's.
    check = verify(delivered.trajectory, coverage_limits(options), guaranteed=True)
    coverage, missed = measured(plan.region, delivered.path, options.width)
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
