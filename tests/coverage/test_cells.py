"""Cells: a piece whose path is too long to plan as one, cut into a lattice of cells."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import MultiPoint, Polygon, box

from skyquill.coverage import cells
from skyquill.coverage.cells import CELL_PATH_M, split_into_cells, too_long_for_one_plan
from skyquill.coverage.plan import CoverageOptions, plan_coverage, plan_tuned
from skyquill.coverage.regions import MAX_PATH_LENGTH_M, estimate_path_length, region_from_vertices
from skyquill.errors import InputError
from skyquill.targets import CRAZYFLIE


def test_a_piece_within_the_cap_stays_whole() -> None:
    piece = box(0.0, 0.0, 300.0, 300.0)  # 9e4 m² / 5 m + 1.2 km = 19.2 km
    assert not too_long_for_one_plan(piece, 5.0)
    assert split_into_cells(piece, 5.0) == [piece]


def test_a_long_piece_is_cut_into_equal_cells_each_within_the_cell_path() -> None:
    piece = box(0.0, 0.0, 1000.0, 600.0)  # 6e5 m² / 10 m + 3.2 km = 63 km
    assert too_long_for_one_plan(piece, 10.0)
    parts = split_into_cells(piece, 10.0)
    assert len(parts) > 1
    assert math.isclose(sum(p.area for p in parts), piece.area, rel_tol=1e-9)
    assert all(estimate_path_length(p, 10.0) <= CELL_PATH_M * (1 + 1e-9) for p in parts)
    # A rectangle cut into equal rectangles: every cell the same size.
    assert np.ptp([p.area for p in parts]) < 1e-6 * piece.area


@st.composite
def convex_pieces(draw: st.DrawFn) -> Polygon:
    """Random convex polygons 300 m to 1 km across, turned any way."""
    count = draw(st.integers(3, 12))
    xy = draw(
        st.lists(
            st.tuples(st.floats(0.0, 1.0), st.floats(0.0, 1.0)), min_size=count, max_size=count
        )
    )
    size = draw(st.floats(300.0, 1000.0))
    hull = MultiPoint([(size * x, size * y) for x, y in xy]).convex_hull
    if isinstance(hull, Polygon) and hull.area > 0.01 * size * size:
        return hull
    return box(0.0, 0.0, size, size)


@settings(max_examples=40, deadline=None)
@given(piece=convex_pieces(), spacing=st.floats(2.0, 20.0))
def test_cells_tile_their_piece_and_are_convex(piece: Polygon, spacing: float) -> None:
    parts = split_into_cells(piece, spacing)
    union = shapely.union_all(parts)
    assert math.isclose(union.area, piece.area, rel_tol=1e-7)
    assert math.isclose(sum(p.area for p in parts), piece.area, rel_tol=1e-7)  # no overlaps
    assert piece.buffer(1e-6 * math.sqrt(piece.area)).contains(union)
    for p in parts:
        assert p.convex_hull.area - p.area <= 1e-9 * piece.area
        assert estimate_path_length(p, spacing) <= CELL_PATH_M * (1 + 1e-9) or len(parts) == 1
    if not too_long_for_one_plan(piece, spacing):
        assert parts == [piece]


@pytest.fixture
def small_caps(monkeypatch: pytest.MonkeyPatch) -> None:
    """A single plan's cap of 500 m and cells of 250 m: a 40 m square at a 2 m swath
    (about 960 m of path) is planned in cells, in seconds."""
    monkeypatch.setattr(cells, "MAX_PATH_LENGTH_M", 500.0)
    monkeypatch.setattr(cells, "CELL_PATH_M", 250.0)


SQUARE_40 = [(0, 0), (40, 0), (40, 40), (0, 40)]


def test_a_field_too_long_for_one_path_is_planned_in_cells(small_caps: None) -> None:
    region = region_from_vertices(SQUARE_40)
    plan = plan_tuned(region, CoverageOptions(width=2.0), 0.99)
    summary = plan.summary()
    assert summary["pieces"] >= 4
    assert summary["cells"] == summary["pieces"]  # no holes: every piece is a cell
    assert summary["copies"] >= 1  # equal square cells: planned once, moved onto the others
    assert plan.coverage >= 0.99
    assert plan.limits["max_excess"] <= 0.02
    assert summary["keepout"]["passed"]


def test_cells_are_refused_an_upload_target(small_caps: None) -> None:
    region = region_from_vertices(SQUARE_40)
    with pytest.raises(InputError, match=r"^target: .*a path too long for one plan"):
        plan_coverage(region, CoverageOptions(width=2.0, target=CRAZYFLIE))


def test_a_mission_past_its_cap_is_refused_with_the_swath_that_fits() -> None:
    region = region_from_vertices([(0, 0), (1000, 0), (1000, 1000), (0, 1000)])
    with pytest.raises(InputError, match=r"^width: got 4 m .*expected at most 200 km \("):
        plan_coverage(region, CoverageOptions(width=4.0))


def test_the_single_path_cap_is_below_the_cells() -> None:
    assert CELL_PATH_M < MAX_PATH_LENGTH_M


def test_lines_under_a_metre_apart_keep_one_plans_cap() -> None:
    # 1e4 m² / 0.3 m ~ 33 km: over one plan's cap, and too fine a spacing for pieces.
    region = region_from_vertices([(0, 0), (100, 0), (100, 100), (0, 100)])
    assert not too_long_for_one_plan(region, 0.3)
    with pytest.raises(InputError, match=r"^width: got 0\.3 m .*expected at most 25 km \("):
        plan_coverage(region, CoverageOptions(width=0.3))
