"""What a covering path misses: area, share and where, checked on paths built by hand."""

from __future__ import annotations

import json

import numpy as np
import pytest
from shapely.geometry import box

from skyquill.coverage.missed import MAX_GAPS, missed_area
from skyquill.coverage.plan import CoverageOptions, plan_coverage
from skyquill.coverage.regions import coverage_fraction, swept

SQUARE = box(0.0, 0.0, 10.0, 10.0)


def test_a_path_along_the_left_half_misses_the_right_half() -> None:
    # A disc of 2 m along x = 1 and x = 3 (y from 0 to 10) covers x <= 4.
    path = np.array([[1.0, 0.0], [1.0, 10.0], [3.0, 10.0], [3.0, 0.0]])
    missed = missed_area(SQUARE, swept(path, 2.0))
    assert missed.area_m2 == pytest.approx(60.0, rel=1e-3)
    assert missed.fraction == pytest.approx(1.0 - coverage_fraction(SQUARE, path, 2.0), abs=1e-12)
    assert missed.gap_count == 1
    (gap,) = missed.gaps
    assert gap.centroid == pytest.approx((7.0, 5.0), abs=0.05)
    assert gap.bounds == pytest.approx((4.0, 0.0, 10.0, 10.0), abs=0.05)


def test_gaps_are_listed_largest_first_and_at_most_max_gaps() -> None:
    # Short dashes leave many separate gaps between them along a strip.
    xs = np.arange(0.5, 10.0, 0.75)
    rows = [np.array([[x, 0.0], [x, 10.0]]) for x in xs]
    path = np.vstack([r if k % 2 == 0 else r[::-1] for k, r in enumerate(rows)])
    missed = missed_area(SQUARE, swept(path, 0.5))
    areas = [g.area_m2 for g in missed.gaps]
    assert areas == sorted(areas, reverse=True)
    assert len(missed.gaps) == min(MAX_GAPS, missed.gap_count)
    assert sum(areas) <= missed.area_m2 + 1e-9


def test_a_plan_reports_its_missed_area_in_the_summary() -> None:
    plan = plan_coverage(SQUARE, CoverageOptions(pattern="zigzag-stop"))
    assert plan.missed is not None
    summary = json.loads(json.dumps(plan.summary()))
    assert summary["missed_fraction"] == pytest.approx(1.0 - plan.coverage, abs=1e-9)
    assert summary["missed_area_m2"] == pytest.approx(100.0 * (1.0 - plan.coverage), rel=1e-6)
    assert summary["gap_count"] >= len(summary["gaps"]) > 0
    assert set(summary["gaps"][0]) == {"area_m2", "centroid_m", "bounds_m"}
