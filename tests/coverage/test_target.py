"""Coverage for a target: the planned path re-fitted into uploads, its coverage measured again."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from skyquill.coverage.plan import CoverageOptions, coverage_limits, plan_coverage, plan_tuned
from skyquill.coverage.regions import coverage_fraction, load_region, region_from_vertices
from skyquill.coverage.target import PATH_TOLERANCE_FRACTION
from skyquill.errors import InputError
from skyquill.limits import VehicleLimits
from skyquill.targets import CRAZYFLIE, plan_uploads
from skyquill.trajectory import RestToRestSequence
from skyquill.verify import verify

EXAMPLES = Path(__file__).parents[2] / "examples" / "coverage"


def test_the_l_field_is_flown_in_uploads_with_hovers() -> None:
    region = load_region(EXAMPLES / "l_field.geojson")
    # A 1.5 m swath: 50 m of stop-and-go zigzag, two uploads (the spiral too, but its LP is slow).
    options = CoverageOptions(pattern="zigzag-stop", width=1.5, target=CRAZYFLIE)
    plan = plan_coverage(region, options)
    delivered = plan.delivered
    assert delivered is not None and delivered.budget.strategy == "split"
    traj = plan.trajectory
    assert isinstance(traj, RestToRestSequence) and traj is delivered.trajectory
    uploads = plan_uploads(traj, CRAZYFLIE)
    assert len(uploads) >= 2 and all(u.pieces <= CRAZYFLIE.max_pieces for u in uploads)
    for u in uploads:
        for order in (1, 2):
            assert np.abs(traj.evaluate(np.array([u.start_s, u.end_s]), order)).max() <= 1e-6
    # Dense check of the delivered flight, independent of the planner's own.
    assert verify(traj, coverage_limits(options)).max_excess <= 1e-9
    assert plan.limits["max_excess"] <= 1e-9
    assert np.allclose(traj.evaluate(np.linspace(0, traj.duration, 50))[:, 2], options.altitude)
    # The stated path tolerance holds, and the coverage is the delivered flight's.
    assert delivered.max_deviation_m <= PATH_TOLERANCE_FRACTION * options.width
    assert plan.coverage == pytest.approx(coverage_fraction(region, plan.path, options.width))
    assert plan.planned_coverage is not None
    assert plan.coverage == pytest.approx(plan.planned_coverage, abs=0.01)
    target = plan.summary()["target"]
    assert target["name"] == "crazyflie" and target["strategy"] == "split"
    assert [u["pieces"] for u in target["uploads"]] == [u.pieces for u in uploads]
    assert target["uploads"][1]["hover_before_s"] == CRAZYFLIE.hover_s


def test_per_axis_limits_and_tuning_keep_the_target() -> None:
    square = region_from_vertices([[0, 0], [10, 0], [10, 10], [0, 10]])
    limits = VehicleLimits(vmax=3.0, amax_axis=5.0, jmax_axis=3.0)
    options = CoverageOptions(pattern="zigzag-stop", limits=limits, target=CRAZYFLIE)
    plan = plan_tuned(square, options, 0.95)
    assert plan.options.target is CRAZYFLIE and plan.delivered is not None
    assert plan.coverage >= 0.94
    assert verify(plan.trajectory, coverage_limits(plan.options)).max_excess <= 1e-9
    plan_uploads(plan.trajectory, CRAZYFLIE)


def test_a_path_too_long_for_the_target_is_refused_before_planning() -> None:
    big = region_from_vertices([[0, 0], [100, 0], [100, 100], [0, 100]])
    with pytest.raises(
        InputError,
        match=r"target: got a path of about .* m \(width 2 m\), expected at most 1000 m for a "
        r"crazyflie \(at most 50 uploads; a swath of at least .* m",
    ):
        plan_coverage(big, CoverageOptions(target=CRAZYFLIE))


def test_without_a_target_nothing_is_refitted() -> None:
    square = region_from_vertices([[0, 0], [10, 0], [10, 10], [0, 10]])
    plan = plan_coverage(square, CoverageOptions(pattern="zigzag-stop"))
    assert plan.delivered is None and plan.planned_coverage is None
    assert "target" not in plan.summary()
