"""Every plan finishes, or stops with a typed error naming why, within its time budget."""

from __future__ import annotations

import time

import numpy as np
import pytest
from coverage_strategies import star_shaped
from hypothesis import HealthCheck, given, settings
from shapely.geometry import box

from skyquill.coverage.deadline import Deadline, check_time_limit, is_time_limit
from skyquill.coverage.paths import merge_close, spiral_curve
from skyquill.coverage.plan import (
    CoverageOptions,
    covering_waypoints,
    plan_coverage,
    plan_tuned,
)
from skyquill.coverage.regions import region_from_vertices
from skyquill.errors import InfeasibleError, InputError, SkyquillError

#: The issue's 47 m x 30 m field with one reflex corner (its default spiral once ran > 10 min).
HEXAGON = region_from_vertices([[0, 0], [47, 0], [47, 15], [30, 30], [20, 18], [0, 30]])
#: Slack over a budget: one step (an LP solve, the dense check) may finish after it is spent.
STEP_SLACK_S = 5.0


def test_the_concave_hexagon_spiral_finishes_quickly() -> None:
    start = time.perf_counter()
    plan = plan_coverage(HEXAGON, CoverageOptions(time_limit=60.0))
    assert time.perf_counter() - start < 30.0
    assert plan.limits["max_excess"] <= 0.02
    assert plan.coverage > 0.9
    assert np.all(np.isfinite(plan.samples().a))


def test_a_spent_budget_names_the_step(monkeypatch: pytest.MonkeyPatch) -> None:
    # The hexagon plans in about 0.6 s, faster than the 1 ms a metre estimated before any
    # work (0.7 s for its path): with a tenth of that rate, 0.2 s passes the estimate and
    # is spent during the planning.
    from skyquill.coverage.plan import checks

    monkeypatch.setattr(checks, "PLANNING_S_PER_M", 1e-4)
    with pytest.raises(InfeasibleError, match=r"^time_limit: got 0.2 s, .* it stopped at ") as exc:
        plan_coverage(HEXAGON, CoverageOptions(time_limit=0.2))
    assert is_time_limit(exc.value)


def test_tuning_shares_one_budget() -> None:
    start = time.perf_counter()
    with pytest.raises(InfeasibleError, match=r"^time_limit: got 1 s"):
        plan_tuned(HEXAGON, CoverageOptions(pattern="zigzag", time_limit=1.0), 0.99)
    assert time.perf_counter() - start < 1.0 + STEP_SLACK_S


def test_a_budget_below_the_estimate_is_refused_before_any_work() -> None:
    field = box(0.0, 0.0, 316.0, 316.0)  # 10 ha at a 5 m swath: ~21 km of path
    start = time.perf_counter()
    message = (
        r"^time_limit: got 5 s, expected at least 21\.2 s for a path of about 21\.2 km "
        r"\(1 ms per metre estimated\): allow more time, widen the swath or split the region$"
    )
    with pytest.raises(InputError, match=message):
        plan_coverage(field, CoverageOptions(width=5.0, time_limit=5.0))
    assert time.perf_counter() - start < 1.0


@pytest.mark.parametrize("value", [0.0, -1.0, float("inf"), float("nan"), "60", True])
def test_time_limit_is_a_positive_number_of_seconds(value: object) -> None:
    with pytest.raises(InputError, match=r"^time_limit: got "):
        CoverageOptions(time_limit=value)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"^time_limit: got "):
        check_time_limit(value)


def test_the_deadline_reports_every_step() -> None:
    seen: list[tuple[str, float, float]] = []
    plan_coverage(box(0.0, 0.0, 10.0, 10.0), progress=lambda *step: seen.append(step))
    steps = [step for step, _, _ in seen]
    assert steps[0] == "the covering path" and steps[-1] == "the coverage measure"
    assert any(step.startswith("speed LP solve") for step in steps)
    assert all(limit == 60.0 for _, _, limit in seen)
    elapsed = [e for _, e, _ in seen]
    assert elapsed == sorted(elapsed)


def test_deadline_counts_from_its_start() -> None:
    deadline = Deadline(0.05)
    deadline.check("first")
    time.sleep(0.06)
    assert deadline.remaining() == 0.0
    with pytest.raises(InfeasibleError, match="it stopped at second after"):
        deadline.check("second")


def test_near_coincident_waypoints_are_merged() -> None:
    # The perimeter lap started 1e-9 m from the region's corner: |C'| varied by 1e5 and
    # more along the spline, and the speed LP's solves stalled.
    square = box(0.0, 0.0, 10.0, 10.0)
    options = CoverageOptions(pattern="zigzag", perimeter=True, delta=1.0, epsilon=0.9)
    waypoints = covering_waypoints(square, options)
    assert np.min(np.linalg.norm(np.diff(waypoints, axis=0), axis=1)) > 0.01 * options.delta
    speed = np.linalg.norm(spiral_curve(waypoints)(np.linspace(0.0, 1.0, 20001), 1), axis=1)
    assert speed.max() / speed.min() < 1e3
    points = np.array([[0.0, 0.0], [1e-9, 0.0], [1.0, 0.0], [1.0, 1e-3]])
    np.testing.assert_array_equal(merge_close(points, 0.01), points[[0, 2]])


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(star_shaped(vertices=(4, 9), size_m=(6.0, 40.0), radius=(0.3, 1.0)))
def test_random_regions_plan_within_the_budget_or_are_refused(vertices: np.ndarray) -> None:
    # Never a hang, never an untyped exception: a plan within the budget (plus one
    # step), or a skyquill error.
    budget = 3.0
    start = time.perf_counter()
    try:
        region = region_from_vertices(vertices)
        plan = plan_coverage(region, CoverageOptions(time_limit=budget))
    except SkyquillError:
        pass
    else:
        assert plan.limits["max_excess"] <= 0.02
        assert np.all(np.isfinite(plan.samples().p))
    assert time.perf_counter() - start < budget + STEP_SLACK_S
