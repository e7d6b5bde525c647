"""Coverage work is estimated and bounded before any path is built."""

from __future__ import annotations

import pytest
from shapely.geometry import box

from skyquill.coverage.paths import contours, zigzag
from skyquill.coverage.plan import CoverageOptions, plan_coverage
from skyquill.coverage.plan.pieces import in_pieces
from skyquill.coverage.plan.tuning import _fitting_epsilons
from skyquill.coverage.regions import MAX_PATH_LENGTH_M, check_width, estimate_path_length
from skyquill.errors import InputError

KM_SQUARE = box(0.0, 0.0, 1000.0, 1000.0)
SQUARE = box(0.0, 0.0, 10.0, 10.0)


def test_a_kilometre_square_at_a_2_m_swath_is_refused_with_what_would_fit() -> None:
    message = (
        r"^width: got 2 m on a region of 1e\+06 m², i\.e\. a path of about 504 km, expected "
        r"at most 200 km \(a swath of at least 5\.1 m, or a smaller region: split it into "
        r"missions\)$"
    )
    with pytest.raises(InputError, match=message):
        plan_coverage(KM_SQUARE, CoverageOptions(width=2.0))


def test_a_millimetre_swath_is_refused_before_any_ring_is_made() -> None:
    with pytest.raises(InputError, match=r"^width: got 0\.001 m on a region of 100 m², i\.e\."):
        plan_coverage(SQUARE, CoverageOptions(width=0.001))
    with pytest.raises(InputError, match=r"^width: got 0\.001 m"):
        contours(SQUARE, 0.001)
    with pytest.raises(InputError, match=r"^width: got 0\.001 m"):
        zigzag(SQUARE, 0.001)


def test_epsilon_counts_in_the_estimate() -> None:
    # 100 m² / 0.005 m + 40 m ~ 20 km fits; at epsilon 0.5 the lines are twice as dense.
    assert check_width(SQUARE, 0.005) == 0.005
    with pytest.raises(InputError, match="expected at most 25 km"):
        check_width(SQUARE, 0.005, epsilon=0.5)


def test_a_perimeter_longer_than_the_budget_says_split() -> None:
    strip = box(0.0, 0.0, 13000.0, 1.0)
    with pytest.raises(InputError, match="the perimeter alone is too long: split the region"):
        check_width(strip, 0.5)


def test_tuning_skips_the_spacings_whose_path_is_too_long() -> None:
    # 4e4 m² / (0.7 * 2.2 m) + 800 m ~ 26.8 km: fits at epsilon 1 (19 km), not at 0.7.
    region = box(0.0, 0.0, 200.0, 200.0)
    assert estimate_path_length(region, 2.2) < MAX_PATH_LENGTH_M
    fitting = _fitting_epsilons(region, CoverageOptions(width=2.2))
    assert 1.0 in fitting and 0.7 not in fitting


def test_a_field_whose_widest_spacing_is_too_long_is_planned_in_cells() -> None:
    region = box(0.0, 0.0, 250.0, 250.0)  # 6.25e4 m² / 2.2 m ~ 28 km at epsilon 1
    options = CoverageOptions(width=2.2)
    assert not _fitting_epsilons(region, options)  # no spacing fits one path
    assert in_pieces(region, options)  # so it is a mission of cells (tests/coverage/test_cells)


@pytest.mark.parametrize("pattern", ["spiral", "zigzag"])
def test_the_estimate_bounds_the_planned_length(pattern: str) -> None:
    # An over-estimate: the perimeter term counts turns a small region barely has.
    plan = plan_coverage(SQUARE, CoverageOptions(width=2.0, pattern=pattern))  # type: ignore[arg-type]
    estimate = estimate_path_length(SQUARE, 2.0)
    assert 0.5 * estimate <= plan.path_length <= estimate


@pytest.mark.parametrize("altitude", [-1.0, 0.0])
def test_altitude_is_a_height_above_the_ground(altitude: float) -> None:
    message = rf"^altitude: got {altitude:g} m, expected a height above the ground, > 0$"
    with pytest.raises(InputError, match=message):
        CoverageOptions(altitude=altitude)
