"""Concave regions: convex parts, their order and the joined multi-spiral / zigzag."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import shapely
from coverage_strategies import star_shaped
from hypothesis import HealthCheck, given, settings
from shapely.geometry import LineString, Polygon

from skyquill.coverage.decompose import (
    convex_parts,
    multi_spiral_control_points,
    multi_zigzag,
    order_parts,
)
from skyquill.coverage.paths import spiral_curve
from skyquill.coverage.regions import coverage_fraction, region_from_vertices
from skyquill.errors import InputError

L_SHAPE = region_from_vertices([[0, 0], [12, 0], [12, 4], [4, 4], [4, 12], [0, 12]])
U_SHAPE = region_from_vertices(
    [[0, 0], [15, 0], [15, 12], [11, 12], [11, 4], [4, 4], [4, 12], [0, 12]]
)
FIELD = region_from_vertices(
    [[0, 0], [14, -2], [21, 3], [15, 8], [18, 16], [9, 19], [2, 14], [-1, 6]]
)
_ANGLES = np.arange(10) * np.pi / 5
STAR = region_from_vertices(
    np.c_[np.cos(_ANGLES), np.sin(_ANGLES)] * np.where(np.arange(10) % 2 == 0, 12.0, 6.0)[:, None]
)
CONCAVE = {"L": L_SHAPE, "U": U_SHAPE, "field": FIELD, "star": STAR}
WIDTH = 2.0


def _is_convex(part: Polygon) -> bool:
    return bool(part.convex_hull.area - part.area <= 1e-9 * part.area)


def _union_error(region: Polygon, parts: list[Polygon]) -> float:
    return float(region.symmetric_difference(shapely.union_all(parts)).area / region.area)


def _shares_edge(a: Polygon, b: Polygon) -> bool:
    return bool(shapely.intersection(a.boundary, b.boundary).length > 1e-9)


def _spiral(region: Polygon, delta: float) -> np.ndarray:
    curve = spiral_curve(multi_spiral_control_points(region, WIDTH, delta=delta))
    assert curve.k == 4  # one degree-4 B-spline: C³ throughout
    return np.asarray(curve(np.linspace(0.0, 1.0, 4000)))


def _outside(region: Polygon, path: np.ndarray) -> float:
    return float(shapely.distance(shapely.points(path), region).max())


def test_a_convex_region_is_one_part() -> None:
    square = region_from_vertices([[0, 0], [10, 0], [10, 10], [0, 10]])
    parts = convex_parts(square, WIDTH)
    assert len(parts) == 1
    assert parts[0].equals(square)


@pytest.mark.parametrize("name", list(CONCAVE))
def test_parts_are_convex_and_tile_the_region(name: str) -> None:
    region = CONCAVE[name]
    parts = convex_parts(region, WIDTH)
    assert len(parts) >= 2
    assert all(_is_convex(p) for p in parts)
    assert _union_error(region, parts) <= 1e-9
    assert sum(p.area for p in parts) == pytest.approx(region.area, rel=1e-9)


def test_rectilinear_shapes_are_cut_into_rectangles() -> None:
    # Reflex-vertex cuts beat Hertel-Mehlhorn's 45° trapezoids here.
    for region, count in ((L_SHAPE, 2), (U_SHAPE, 3)):
        parts = convex_parts(region, WIDTH)
        assert len(parts) == count
        assert all(p.minimum_rotated_rectangle.area == pytest.approx(p.area) for p in parts)


@pytest.mark.parametrize("name", ["L", "U", "field"])
def test_order_visits_adjacent_parts(name: str) -> None:
    parts = convex_parts(CONCAVE[name], WIDTH)
    ordered = order_parts(parts[::-1])
    assert sorted(p.wkt for p in ordered) == sorted(p.wkt for p in parts)
    assert all(_shares_edge(a, b) for a, b in itertools.pairwise(ordered))


def test_order_honours_the_start() -> None:
    parts = convex_parts(U_SHAPE, WIDTH)
    for k in range(len(parts)):
        assert order_parts(parts, start=k)[0].equals(parts[k])


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
    with pytest.raises(InputError, match="width"):
        convex_parts(L_SHAPE, 5.0)
    with pytest.raises(InputError, match="region"):
        convex_parts(LineString([(0, 0), (1, 1)]), WIDTH)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="parts"):
        order_parts([])
    with pytest.raises(InputError, match="start"):
        order_parts(convex_parts(L_SHAPE, WIDTH), start=2)
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
    assert all(_is_convex(p) for p in parts)
    assert _union_error(region, parts) <= 1e-9
    assert _outside(region, spiral) <= 0.05
    assert region.buffer(1e-6).covers(LineString(sweep))
