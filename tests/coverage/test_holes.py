"""Hole-free pieces: the cuts open every hole, the pieces tile the region minus the obstacles."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from shapely.geometry import Point, Polygon, box

from skyquill.coverage.holes import GUARD_FRACTION, hole_free_pieces, planning_obstacle
from skyquill.coverage.regions import holes, load_region, region_from_vertices

ROUND = np.asarray(Point(10, 10).buffer(2.5).exterior.coords)[:-1]


def test_an_obstacle_contains_its_hole_with_the_guard_and_has_few_vertices() -> None:
    hole = Point(10, 10).buffer(2.5)
    obstacle = planning_obstacle(hole, 2.0)
    assert obstacle.contains(hole.buffer(0.9 * GUARD_FRACTION * 2.0))
    assert len(obstacle.exterior.coords) - 1 <= 12
    square = box(4, 4, 6, 6)
    assert planning_obstacle(square, 2.0).equals(square.buffer(0.04, join_style="mitre"))


@pytest.mark.parametrize(
    "wkt",
    [
        "POLYGON ((0 0, 20 0, 20 20, 0 20, 0 0), (5 5, 8 5, 8 8, 5 8, 5 5), "
        "(12 11, 16 11, 16 15, 12 15, 12 11))",
        # An L with a hole in its foot, and a hole right above another.
        "POLYGON ((0 0, 30 0, 30 10, 10 10, 10 30, 0 30, 0 0), (20 3, 24 3, 24 7, 20 7, 20 3), "
        "(3 15, 6 15, 6 18, 3 18, 3 15), (3 22, 6 22, 6 25, 3 25, 3 22))",
        "MULTIPOLYGON (((0 0, 10 0, 10 10, 0 10, 0 0), (4 4, 6 4, 6 6, 4 6, 4 4)), "
        "((20 0, 30 0, 30 10, 20 10, 20 0)))",
    ],
)
def test_pieces_have_no_holes_and_tile_the_region_minus_the_obstacles(wkt: str) -> None:
    region = load_region(wkt)
    pieces = hole_free_pieces(region, 2.0)
    assert all(isinstance(p, Polygon) and not p.interiors and p.is_valid for p in pieces)
    obstacles = shapely.union_all([planning_obstacle(h, 2.0) for h in holes(region)])
    free = region.difference(obstacles)
    union = shapely.union_all(pieces)
    assert union.symmetric_difference(free).area <= 1e-6 * region.area
    assert sum(p.area for p in pieces) == pytest.approx(free.area, rel=1e-9)
    assert not any(p.intersects(h.buffer(-1e-6)) for p in pieces for h in holes(region))


def test_a_round_hole_splits_a_square_into_two_halves() -> None:
    region = region_from_vertices([(0, 0), (20, 0), (20, 20), (0, 20)], holes=[ROUND])
    pieces = hole_free_pieces(region, 2.0)
    assert len(pieces) == 2
    assert pieces[0].area == pytest.approx(pieces[1].area, rel=1e-6)
