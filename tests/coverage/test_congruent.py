"""Congruent pieces: the motion between copies, and a mission that plans each class once."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely import affinity
from shapely.geometry import MultiPoint, Polygon

from skyquill.coverage import mission
from skyquill.coverage.congruent import congruence_classes, motion_onto
from skyquill.coverage.deadline import Deadline
from skyquill.coverage.holes import hole_free_pieces
from skyquill.coverage.mission import _convex
from skyquill.coverage.plan import CoverageOptions, CoveragePlan, plan_coverage
from skyquill.coverage.plan.planner import plan_within
from skyquill.coverage.regions import coverage_fraction, load_region, region_from_vertices
from skyquill.limits import VehicleLimits
from skyquill.trajectory.moved import moved

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "coverage"
#: Symmetric about x = 8 with a hole in the middle: its pieces are mirror images, no shifts.
KITE = [(0, 6), (8, 0), (16, 6), (8, 18)]
HOLE = [(6, 5), (10, 5), (10, 9), (6, 9)]
PER_AXIS = VehicleLimits(vmax=3.0, amax_axis=5.0, jmax_axis=3.0)


def _rounded(points: np.ndarray) -> set[tuple[float, float]]:
    return {(round(x, 6), round(y, 6)) for x, y in points}


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    angle=st.floats(-math.pi, math.pi),
    mirror=st.booleans(),
    start=st.integers(0, 20),
)
def test_a_turned_mirrored_shifted_copy_is_found(
    seed: int, angle: float, mirror: bool, start: int
) -> None:
    rng = np.random.default_rng(seed)
    piece = shapely.normalize(MultiPoint(rng.uniform(0, 30, (8, 2))).convex_hull)
    assert isinstance(piece, Polygon)
    copy = affinity.rotate(affinity.scale(piece, -1.0 if mirror else 1.0, 1.0, origin=(0, 0)),
                           angle, origin=(0, 0), use_radians=True)  # fmt: skip
    copy = affinity.translate(copy, 57.0, -13.0)
    # Its corners from another start, and a straight vertex in the middle of one side.
    corners = np.asarray(copy.exterior.coords)[:-1]
    corners = np.roll(corners, start % len(corners), axis=0)
    corners = np.vstack([corners[:1], 0.5 * (corners[0] + corners[1]), corners[1:]])
    copy = Polygon(corners)
    motion = motion_onto(piece, copy, "rigid")
    assert motion is not None
    moved_corners = motion.apply(np.asarray(piece.exterior.coords)[:-1])
    assert _rounded(moved_corners) <= _rounded(corners)  # corners onto corners
    assert Polygon(moved_corners).symmetric_difference(copy).area < 1e-9 * piece.area
    assert np.linalg.det(motion.rotation) == pytest.approx(-1.0 if mirror else 1.0)
    # Shifts only: a turned or mirrored copy is not one (random corners: no symmetry).
    if min(abs(angle), 2 * math.pi - abs(angle)) > 1e-3 or mirror:
        assert motion_onto(piece, copy, "translations") is None


def test_a_piece_a_little_larger_is_no_copy() -> None:
    piece = Polygon([(0, 0), (10, 0), (12, 7), (1, 5)])
    assert motion_onto(piece, affinity.scale(piece, 1.0 + 1e-6, 1.0 + 1e-6), "rigid") is None


def test_holes_1_3ha_has_three_pairs_all_shifted() -> None:
    region = load_region(EXAMPLES / "holes_1_3ha.geojson")
    parts = [q for p in hole_free_pieces(region, 5.0) for q in _convex(p, 5.0)]
    copies = [(i, k, m) for i, (k, m) in enumerate(congruence_classes(parts, "rigid")) if k != i]
    assert sorted(round(parts[i].area) for i, _, _ in copies) == [290, 302, 2990]
    assert all(np.array_equal(m.rotation, np.eye(2)) for _, _, m in copies)


def test_a_moved_plan_covers_its_copy_as_the_plan_covers_its_piece() -> None:
    pieces = hole_free_pieces(region_from_vertices(KITE, holes=[HOLE]), 2.0)
    _, (k, motion) = congruence_classes(pieces, "rigid")
    assert k == 0 and np.linalg.det(motion.rotation) == pytest.approx(-1.0)  # mirrored
    plan = plan_within(pieces[0], CoverageOptions(pattern="zigzag"), Deadline(60.0))
    flight = moved(plan.trajectory, motion.rotation, motion.shift)
    assert flight.duration == plan.duration
    t = np.linspace(0.0, plan.duration, 4001)
    path, own = flight.evaluate(t)[:, :2], plan.trajectory.evaluate(t)[:, :2]
    # The same samples moved (the swath's disc is a polygon: equal up to its facets).
    covered = coverage_fraction(pieces[1], path, 2.0)
    assert covered == pytest.approx(coverage_fraction(pieces[0], own, 2.0), abs=1e-6)
    assert pieces[1].buffer(1e-9).contains(shapely.LineString(path))


def _fresh(monkeypatch: pytest.MonkeyPatch, region: Polygon, opts: CoverageOptions) -> CoveragePlan:
    with monkeypatch.context() as patch:
        patch.setattr(mission, "congruence_classes", lambda pieces, _: mission._alone(len(pieces)))
        return plan_coverage(region, opts)


def test_mirror_images_under_norm_limits_are_planned_once(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    region = region_from_vertices(KITE, holes=[HOLE])
    options = CoverageOptions(pattern="spiral")
    once, fresh = plan_coverage(region, options), _fresh(monkeypatch, region, options)
    assert once.mission is not None and once.mission.copies == 3  # 6 convex parts
    assert once.summary()["keepout"]["passed"] and once.limits["max_excess"] <= 0.02
    # The spiral depends on its piece's orientation (it turns clockwise in every piece, a
    # mirrored one anticlockwise), so a fresh plan of a mirror image is another flight:
    # 97.07 s against 94.95 s, coverage 0.8976 against 0.8996.
    assert once.duration == pytest.approx(fresh.duration, rel=0.03)
    assert once.coverage == pytest.approx(fresh.coverage, abs=0.005)


def test_per_axis_limits_do_not_move_plans_by_mirrors(monkeypatch: pytest.MonkeyPatch) -> None:
    region = region_from_vertices(KITE, holes=[HOLE])
    options = CoverageOptions(pattern="spiral", limits=PER_AXIS)
    plan = plan_coverage(region, options)
    assert plan.mission is not None and plan.mission.copies == 0
    assert plan.duration == _fresh(monkeypatch, region, options).duration


def test_shifted_copies_keep_the_fresh_flight_under_per_axis_limits(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # Two equal fields side by side: one is the other shifted.
    field = [(0, 0), (9, 0), (10, 7), (1, 6)]
    region = shapely.MultiPolygon([Polygon(field), affinity.translate(Polygon(field), 20, 3)])
    options = CoverageOptions(pattern="zigzag", limits=PER_AXIS)
    plan, fresh = plan_coverage(region, options), _fresh(monkeypatch, region, options)
    assert plan.mission is not None and plan.mission.copies == 1
    assert plan.duration == pytest.approx(fresh.duration, rel=1e-9)
    assert plan.coverage == pytest.approx(fresh.coverage, abs=1e-9)
