"""Transit routes: straight when clear, around the holes (never through them) otherwise."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import LineString, Point, box

from skyquill.coverage.transit import _graph_geometry, _searched_route, transit_route


def test_a_clear_transit_is_straight() -> None:
    route = transit_route(np.array([0.0, 0.0]), np.array([10.0, 0.0]), [box(4, 2, 6, 4)], 0.5)
    assert np.array_equal(route, [[0.0, 0.0], [10.0, 0.0]])


@pytest.mark.parametrize(
    "holes", [[Point(15, 15).buffer(3)], [Point(15, 15).buffer(3), box(22, 5, 24, 25)]]
)
def test_a_transit_goes_around_the_holes_keeping_half_its_clearance(holes: list) -> None:
    begin, end = np.array([5.0, 15.0]), np.array([30.0, 15.0])
    route = transit_route(begin, end, holes, 1.0)
    line = LineString(route)
    assert np.array_equal(route[0], begin) and np.array_equal(route[-1], end)
    assert all(line.distance(h) >= 0.5 - 1e-9 for h in holes)
    # Shortest: no longer than over the grown holes' corners (the wall's ends at y = 4, 26).
    assert line.length <= 36.0


def test_a_transit_from_next_to_a_hole_leaves_it() -> None:
    hole = box(4, 4, 6, 6)
    route = transit_route(np.array([6.2, 5.0]), np.array([0.0, 5.0]), [hole], 1.0)
    assert LineString(route).distance(hole) > 0.0
    assert len(route) > 2


@settings(max_examples=60, deadline=None)
@given(
    ends=st.lists(st.floats(0.0, 40.0), min_size=4, max_size=4),
    centre=st.tuples(st.floats(10.0, 30.0), st.floats(10.0, 30.0)),
    radius=st.floats(1.0, 6.0),
)
def test_the_straight_route_is_what_the_search_finds(
    ends: list[float], centre: tuple[float, float], radius: float
) -> None:
    # The shortcut for a clear line answers as the visibility-graph search does.
    holes = [Point(*centre).buffer(radius), box(centre[0] + 8, 2, centre[0] + 9, 12)]
    begin, end = np.array(ends[:2]), np.array(ends[2:])
    corners, blocks = _graph_geometry(tuple(holes), 1.0)
    searched = _searched_route(np.vstack([begin, end, *corners]), blocks)
    assert np.array_equal(transit_route(begin, end, holes, 1.0), searched)
