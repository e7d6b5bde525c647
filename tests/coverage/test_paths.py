"""Covering paths: contours, the spiral spline (paper 001 §1), the boustrophedon."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from shapely.geometry import MultiPoint, Polygon

from skyquill.coverage.paths import (
    contours,
    hartley_judd_knots,
    spiral_control_points,
    spiral_curve,
    with_corner_points,
    zigzag,
)
from skyquill.coverage.regions import coverage_fraction, region_from_vertices
from skyquill.errors import InputError

SQUARE = region_from_vertices([[0, 0], [10, 0], [10, 10], [0, 10]])
RECT = region_from_vertices([[0, 0], [30, 0], [30, 12], [0, 12]])
TRIANGLE = region_from_vertices([[0, 0], [20, 0], [10, 17.32]])
IRREGULAR = region_from_vertices([[0, 0], [13, -2], [20, 5], [17, 15], [6, 17], [-2, 10]])
L_SHAPE = region_from_vertices([[0, 0], [12, 0], [12, 4], [4, 4], [4, 12], [0, 12]])


def _spiral(region: Polygon, mode: str = "offset", delta: float = 0.1) -> np.ndarray:
    rings = contours(region, 2.0, mode)  # type: ignore[arg-type]
    curve = spiral_curve(spiral_control_points(rings, delta))
    return np.asarray(curve(np.linspace(0.0, 1.0, 3000)))


def _outside(region: Polygon, path: np.ndarray) -> float:
    return float(shapely.distance(shapely.points(path), region).max())


def test_offset_rings_of_the_square_are_one_swath_apart() -> None:
    rings = contours(SQUARE, 2.0)
    # buffer(-1), buffer(-3); buffer(-5) is the bare centre point (empty).
    assert len(rings) == 2
    polys = [Polygon(r) for r in rings]
    assert polys[0].exterior.distance(SQUARE.exterior) == pytest.approx(1.0)
    assert polys[1].exterior.distance(polys[0].exterior) == pytest.approx(2.0)
    assert polys[0].buffer(-2.0).symmetric_difference(polys[1]).area < 1e-9
    assert all(shapely.is_ccw(shapely.LinearRing(r)) for r in rings)


def test_spiral_on_the_paper_square_stays_inside_and_covers() -> None:
    for mode in ("offset", "homothetic"):
        path = _spiral(SQUARE, mode)
        assert _outside(SQUARE, path) <= 1e-9
        assert coverage_fraction(SQUARE, path, 2.0) >= 0.97


def test_spiral_curve_is_clamped_to_its_end_control_points() -> None:
    points = spiral_control_points(contours(SQUARE, 2.0), 0.5)
    curve = spiral_curve(points)
    assert np.allclose(curve(0.0), points[0])
    assert np.allclose(curve(1.0), points[-1])
    assert curve.k == 4


def test_zigzag_on_the_square_has_five_sweep_lines_and_covers() -> None:
    path = zigzag(SQUARE, 2.0)
    assert path.shape == (10, 2)
    across = max((np.unique(np.round(path[:, k], 6)) for k in (0, 1)), key=len)
    assert np.allclose(across, [1, 3, 5, 7, 9])  # five sweep lines, one swath apart
    assert _outside(SQUARE, path) <= 1e-9
    assert coverage_fraction(SQUARE, path, 2.0) >= 0.97


def test_homothetic_over_layers_an_elongated_rectangle() -> None:
    homothetic = contours(RECT, 2.0, "homothetic")
    offset = contours(RECT, 2.0, "offset")
    assert (len(homothetic), len(offset)) == (9, 3)


@pytest.mark.parametrize("region", [RECT, IRREGULAR], ids=["rectangle", "irregular"])
def test_offset_spiral_covers_elongated_and_irregular_regions(region: Polygon) -> None:
    path = _spiral(region, "offset")
    assert _outside(region, path) <= 1e-9
    assert coverage_fraction(region, path, 2.0) >= 0.98


@pytest.mark.parametrize("region", [TRIANGLE, IRREGULAR], ids=["triangle", "irregular"])
def test_triangle_and_irregular_polygon_are_covered(region: Polygon) -> None:
    spiral = _spiral(region, "homothetic")
    sweep = zigzag(region, 2.0, perimeter=True)
    for path in (spiral, sweep):
        assert _outside(region, path) <= 1e-9
        assert coverage_fraction(region, path, 2.0) >= 0.97


@pytest.mark.parametrize("angle", [None, 0.0, -np.pi / 4])
def test_zigzag_refuses_a_concave_region(angle: float | None) -> None:
    with pytest.raises(InputError, match="concave regions need decomposition"):
        zigzag(L_SHAPE, 2.0, angle=angle)


def test_hartley_judd_knots_are_clamped_and_sorted() -> None:
    points = spiral_control_points(contours(IRREGULAR, 2.0), 0.5)
    knots = hartley_judd_knots(points, 4)
    assert len(knots) == len(points) + 5
    assert np.all(np.diff(knots) >= 0.0)
    assert np.all(knots[:5] == 0.0)
    assert np.all(knots[-5:] == 1.0)
    assert knots.min() >= 0.0
    assert knots.max() <= 1.0


def test_hartley_judd_spans_follow_leg_lengths() -> None:
    points = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [5.0, 0.0]])
    # degree 1: spans are the legs themselves, 1 : 1 : 3.
    assert np.allclose(hartley_judd_knots(points, 1), [0, 0, 0.2, 0.4, 1, 1])


def test_bad_inputs_are_named() -> None:
    with pytest.raises(InputError, match="mode"):
        contours(SQUARE, 2.0, "radial")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="delta"):
        spiral_control_points(contours(SQUARE, 2.0), 0.0)
    with pytest.raises(InputError, match="control_points"):
        spiral_curve(np.zeros((3, 2)))


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.lists(
        st.tuples(st.floats(-20, 20), st.floats(-20, 20)),
        min_size=3,
        max_size=12,
    )
)
def test_random_convex_regions_give_paths_inside(points: list[tuple[float, float]]) -> None:
    hull = MultiPoint(points).convex_hull
    if not isinstance(hull, Polygon):
        return
    try:
        region = region_from_vertices(np.asarray(hull.exterior.coords))
        spiral = _spiral(region, "offset", 0.5)
        sweep = zigzag(region, 2.0, perimeter=True)
    except InputError:
        return
    assert _outside(region, spiral) <= 1e-9
    assert _outside(region, sweep) <= 1e-9


def test_step_drift_is_shorter_than_the_papers_lap_drift_and_stays_inside() -> None:
    rings = contours(SQUARE, 2.0)
    paths = {}
    for drift in ("lap", "step"):
        curve = spiral_curve(spiral_control_points(rings, 0.3, drift=drift))  # type: ignore[arg-type]
        paths[drift] = np.asarray(curve(np.linspace(0.0, 1.0, 5000)))
        assert _outside(SQUARE, paths[drift]) < 1e-9
    length = {k: float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum()) for k, p in paths.items()}
    # 46.8 m against 62.6 m: the lap drift needs an extra undrifted outer lap.
    assert length["step"] < 0.8 * length["lap"]
    assert coverage_fraction(SQUARE, paths["step"], 2.0) > 0.95
    with pytest.raises(InputError, match="drift"):
        spiral_control_points(rings, 0.3, drift="zigzag")  # type: ignore[arg-type]


def test_a_reversal_becomes_a_u_turn_not_a_cusp() -> None:
    there_and_back = np.array([[0.0, 0.0], [5.0, 0.0], [0.0, 0.0]])
    curve = spiral_curve(with_corner_points(there_and_back, 0.4))
    speed = np.linalg.norm(curve(np.linspace(0.0, 1.0, 20001), 1), axis=1)
    assert speed.min() > 0.01 * speed.max()  # a cusp would have |C'| = 0 (here 0.023)


#: Random convex regions (hypothesis, tests/coverage/test_plan.py) with a vertex a
#: micrometre or less off a straight edge: their spirals could not be timed on any grid.
BENT_BY_ROUND_OFF = (
    [(0.0, 1.4881591259435156), (0.0, 8.814815439974618),
     (2.714295001734623e-169, 12.569412626410816), (6.131868215140549, 22.39524653616589),
     (16.729332049106187, 13.892435772459239)],
    [(2.8175667347736576e-190, 17.08421457290478), (13.201536343068545, 27.996168988311503),
     (24.68258407006851, 25.297967769199264), (27.874030793804348, 9.400424882218244),
     (19.733189139216947, 1.6182670598244044), (1.4087833673868288e-6, 0.6044902039165497),
     (2.8175667347736575e-169, 14.444495305198167)],
)  # fmt: skip


@pytest.mark.parametrize("vertices", BENT_BY_ROUND_OFF)
def test_a_vertex_where_the_edge_goes_on_straight_is_no_corner(
    vertices: list[tuple[float, float]],
) -> None:
    from skyquill.coverage.plan import CoverageOptions, plan_coverage

    region = region_from_vertices(vertices)
    rings = contours(region, 2.0)
    assert len(rings[0]) == len(vertices) - 1  # the straight vertex is not a corner
    plan = plan_coverage(region, CoverageOptions(pattern="spiral", delta=0.5, grid=600))
    assert plan.limits["max_excess"] <= 0.02


def test_only_vertices_where_a_ring_goes_on_straight_are_dropped() -> None:
    from skyquill.coverage.paths import STRAIGHT_TURN_RAD, _without_straight

    square = np.array([[0.0, 0.0], [2.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]])
    np.testing.assert_array_equal(_without_straight(square), square[[0, 2, 3, 4]])
    bent = square.copy()
    bent[1, 1] = -2.0 * np.tan(10 * STRAIGHT_TURN_RAD)  # a turn ten times the tolerance
    np.testing.assert_array_equal(_without_straight(bent), bent)
    spike = np.array([[0.0, 0.0], [2.0, 0.0], [1.0, 0.0], [1.0, 1.0]])  # turns back: kept
    np.testing.assert_array_equal(_without_straight(spike), spike)
