"""Concave regions, step 1: convex parts that tile the region."""

from __future__ import annotations

import pytest
from concave_regions import CONCAVE, L_SHAPE, U_SHAPE, WIDTH, is_convex, union_error
from shapely.geometry import LineString

from skyquill.coverage.partition import convex_parts
from skyquill.coverage.regions import region_from_vertices
from skyquill.errors import InputError


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
    assert all(is_convex(p) for p in parts)
    assert union_error(region, parts) <= 1e-9
    assert sum(p.area for p in parts) == pytest.approx(region.area, rel=1e-9)


def test_rectilinear_shapes_are_cut_into_rectangles() -> None:
    # Reflex-vertex cuts beat Hertel-Mehlhorn's 45° trapezoids here.
    for region, count in ((L_SHAPE, 2), (U_SHAPE, 3)):
        parts = convex_parts(region, WIDTH)
        assert len(parts) == count
        assert all(p.minimum_rotated_rectangle.area == pytest.approx(p.area) for p in parts)


def test_bad_inputs_are_named() -> None:
    with pytest.raises(InputError, match="width"):
        convex_parts(L_SHAPE, 5.0)
    with pytest.raises(InputError, match="region"):
        convex_parts(LineString([(0, 0), (1, 1)]), WIDTH)  # type: ignore[arg-type]
