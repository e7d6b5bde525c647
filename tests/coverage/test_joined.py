"""Concave regions, step 3: the joined multi-spiral and multi-zigzag."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from concave_regions import CONCAVE, L_SHAPE, STAR, WIDTH, is_convex, union_error
from coverage_strategies import star_shaped
from hypothesis import HealthCheck, given, settings
from shapely.geometry import LineString, Polygon

from skyquill.coverage.joined import multi_spiral_control_points, multi_zigzag
from skyquill.coverage.partition import convex_parts
from skyquill.coverage.paths import spiral_curve
from skyquill.coverage.regions import coverage_fraction, region_from_vertices
from skyquill.errors import InputError


def _spiral(region: Polygon, delta: float) -> np.ndarray:
    curve = spiral_curve(multi_spiral_control_points(region, WIDTH, delta=delta))
    assert curve.k == 4  # one degree-4 B-spline: C³ throughout
    return np.asarray(curve(np.linspace(0.0, 1.0, 4000)))


def _outside(region: Polygon, path: np.ndarray) -> float:
    return float(shapely.distance(shapely.points(path), region).max())


@pytest.mark.parametrize("name", ["L", "U", "field"])
@pytest.mark.parametrize("delta", [0.3, 1.0])
def test_multi_spiral_is_one_curve_inside_that_covers(name: str, delta: float) -> None:
    region = CONCAVE[name]
    path = _spiral(region, delta)
    assert _outside(region, path) <= 0.05
    assert coverage_fraction(region, path, WIDTH) >= 0.97


def test_multi_spiral_covers_the_star_and_homothetic_mode_works() -> None:
    path = _spiral(STAR, 0.5)
    assert _outside(STAR, path) <= 0.05
    assert coverage_fraction(STAR, path, WIDTH) >= 0.97
    points = multi_spiral_control_points(L_SHAPE, WIDTH, mode="homothetic", delta=0.5)
    path = np.asarray(spiral_curve(points)(np.linspace(0.0, 1.0, 4000)))
    assert _outside(L_SHAPE, path) <= 0.05
    assert coverage_fraction(L_SHAPE, path, WIDTH) >= 0.97


def test_multi_spiral_of_a_convex_region_is_its_spiral() -> None:
    square = region_from_vertices([[0, 0], [10, 0], [10, 10], [0, 10]])
    path = _spiral(square, 0.5)
    assert _outside(square, path) <= 1e-9
    assert coverage_fraction(square, path, WIDTH) >= 0.97


@pytest.mark.parametrize("name", list(CONCAVE))
def test_multi_zigzag_stays_inside_and_covers(name: str) -> None:
    region = CONCAVE[name]
    path = multi_zigzag(region, WIDTH, perimeter=True)
    assert region.buffer(1e-6).covers(LineString(path))
    assert coverage_fraction(region, path, WIDTH) >= 0.97
    bare = multi_zigzag(region, WIDTH)
    assert region.buffer(1e-6).covers(LineString(bare))
    if name != "star":  # without the lap the star's tips are missed
        assert coverage_fraction(region, bare, WIDTH) >= 0.96


def test_bad_inputs_are_named() -> None:
    with pytest.raises(InputError, match="delta"):
        multi_spiral_control_points(L_SHAPE, WIDTH, delta=0.0)
    with pytest.raises(InputError, match="mode"):
        multi_spiral_control_points(L_SHAPE, WIDTH, mode="radial")  # type: ignore[arg-type]


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(star_shaped(vertices=(5, 12), size_m=(8.0, 40.0), radius=(0.2, 1.0)))
def test_random_star_shaped_regions_work_or_are_refused(vertices: np.ndarray) -> None:
    try:
        region = region_from_vertices(vertices)
        parts = convex_parts(region, WIDTH)
        spiral = _spiral(region, 0.5)
        sweep = multi_zigzag(region, WIDTH, perimeter=True)
    except InputError:
        return
    assert all(is_convex(p) for p in parts)
    assert union_error(region, parts) <= 1e-9
    assert _outside(region, spiral) <= 0.05
    assert region.buffer(1e-6).covers(LineString(sweep))
