"""Regions with holes and several fields: one flight that never enters a hole.

Every plan is checked here independently of the planner and of
:func:`~skyquill.coverage.keepout.check_keepout`: the trajectory is sampled
densely, the spray is read from the plan's pen windows, and shapely's
distances to the holes are taken directly.
"""

from __future__ import annotations

import time

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from shapely.geometry import Point, Polygon

from skyquill.coverage.plan import CoverageOptions, CoveragePlan, plan_coverage, plan_tuned
from skyquill.coverage.regions import holes, load_region, region_from_vertices
from skyquill.errors import InfeasibleError, InputError, SkyquillError
from skyquill.io.trajectory_json import pen_down

SQUARE = [(0, 0), (16, 0), (16, 16), (0, 16)]
ZIGZAG = CoverageOptions(pattern="zigzag")


def _round(x: float, y: float, r: float) -> np.ndarray:
    return np.asarray(Point(x, y).buffer(r).exterior.coords)[:-1]


def _independent_clearances(plan: CoveragePlan) -> tuple[list[float], list[float]]:
    """Per hole: the vehicle's closest approach, and the spray's (sampled at 500 Hz)."""
    t = np.linspace(0.0, plan.duration, int(plan.duration * 500) + 2)
    p = plan.trajectory.evaluate(t)[:, :2]
    on = pen_down(t, plan.pen_windows_s) > 0.5
    points = shapely.points(p)
    near, spraying = [], []
    for hole in holes(plan.region):
        d = shapely.distance(points, hole)
        near.append(float(d.min()))
        spraying.append(float(d[on].min()) if on.any() else np.inf)
    return near, spraying


def _assert_safe(plan: CoveragePlan) -> None:
    near, spraying = _independent_clearances(plan)
    half = 0.5 * plan.options.width
    assert min(near) > 0.0
    assert min(spraying) >= half * (1 - 1e-6)
    summary = plan.summary()
    assert summary["keepout"]["passed"]
    reported = [h["closest_m"] for h in summary["keepout"]["holes"]]
    # The planner's check samples every 1 cm: within that of the 500 Hz sampling.
    assert reported == pytest.approx(near, abs=0.01)


def test_a_square_with_a_round_hole() -> None:
    region = region_from_vertices(SQUARE, holes=[_round(8, 8, 2.0)])
    plan = plan_coverage(region, ZIGZAG)
    _assert_safe(plan)
    summary = plan.summary()
    hole_area = Polygon(region.interiors[0]).area
    assert summary["region_area_m2"] == pytest.approx(256.0 - hole_area)
    # The missed area is of the region outside the hole, so coverage + missed = 1.
    assert summary["missed_fraction"] == pytest.approx(1.0 - plan.coverage, abs=1e-9)
    assert plan.coverage >= 0.9
    assert summary["pieces"] == 2 and summary["fields"] == 1
    assert plan.limits["max_excess"] <= 0.02


def test_a_square_with_two_holes() -> None:
    square_hole = [(3, 3), (6, 3), (6, 6), (3, 6)]
    region = region_from_vertices(SQUARE, holes=[square_hole, _round(11, 10, 1.5)])
    plan = plan_coverage(region, ZIGZAG)
    _assert_safe(plan)
    assert len(plan.summary()["keepout"]["holes"]) == 2
    assert plan.coverage >= 0.88


def test_an_l_with_a_hole_spiral() -> None:
    region = load_region(
        "POLYGON ((0 0, 20 0, 20 8, 8 8, 8 20, 0 20, 0 0), "
        "(12 2.5, 15 2.5, 15 5.5, 12 5.5, 12 2.5))"
    )
    plan = plan_coverage(region, CoverageOptions(pattern="spiral"))
    _assert_safe(plan)
    assert plan.coverage >= 0.9


def test_two_fields_are_one_flight_with_the_spray_off_between_them() -> None:
    region = load_region(
        "MULTIPOLYGON (((0 0, 10 0, 10 10, 0 10, 0 0)), ((20 0, 30 0, 30 10, 20 10, 20 0)))"
    )
    plan = plan_coverage(region, ZIGZAG)
    summary = plan.summary()
    assert summary["fields"] == 2 and summary["keepout"]["holes"] == []
    assert summary["transit_length_m"] >= 10.0  # the gap between the fields
    windows = plan.pen_windows_s
    assert len(windows) == 2
    # Between the windows the vehicle crosses the gap with the spray off.
    t = np.linspace(windows[0][1], windows[1][0], 50)[1:-1]
    x = plan.trajectory.evaluate(t)[:, 0]
    assert np.any((x > 10.5) & (x < 19.5))
    assert np.all(pen_down(t, windows) == 0.0)
    assert plan.coverage >= 0.9
    # Sprayed area counts only inside the fields: the transit adds nothing.
    assert plan.missed is not None and plan.missed.area_m2 == pytest.approx(
        (1 - plan.coverage) * 200.0
    )


def test_a_tuned_plan_with_a_hole_reaches_its_target() -> None:
    region = region_from_vertices(SQUARE, holes=[[(6, 6), (9, 6), (9, 9), (6, 9)]])
    plan = plan_tuned(region, CoverageOptions(pattern="zigzag-stop"), 0.9)
    _assert_safe(plan)
    assert plan.coverage >= 0.9


def test_a_target_with_holes_is_refused() -> None:
    from skyquill.targets import TARGETS

    region = region_from_vertices(SQUARE, holes=[_round(8, 8, 2.0)])
    target = next(iter(TARGETS.values()))
    with pytest.raises(InputError, match="target: got an upload target for a region with holes"):
        plan_coverage(region, CoverageOptions(target=target))


def test_a_swath_wider_than_a_field_is_named() -> None:
    region = load_region(
        "MULTIPOLYGON (((0 0, 10 0, 10 10, 0 10, 0 0)), ((20 0, 21.5 0, 21.5 9, 20 9, 20 0)))"
    )
    with pytest.raises(InputError, match="width: got 2 m, expected less than the field 2's"):
        plan_coverage(region, ZIGZAG)


@st.composite
def _holed_regions(draw: st.DrawFn) -> Polygon:
    """A random star-shaped shell (6-9 m from its centre) with 0-2 random holes (squares or
    discs, some crossing the shell or each other: those must be refused by name)."""
    n = draw(st.integers(5, 8))
    jitter = draw(st.lists(st.floats(0.0, 0.8), min_size=n, max_size=n))
    angles = (np.arange(n) + np.asarray(jitter)) * (2 * np.pi / n)
    radii = np.asarray(draw(st.lists(st.floats(6.0, 9.0), min_size=n, max_size=n)))
    shell = np.column_stack([radii * np.cos(angles), radii * np.sin(angles)])
    rings = []
    for _ in range(draw(st.integers(0, 2))):
        x, y = draw(st.floats(-3.5, 3.5)), draw(st.floats(-3.5, 3.5))
        r = draw(st.floats(0.3, 1.5))
        if draw(st.booleans()):
            rings.append(_round(x, y, r))
        else:
            rings.append(np.array([(x - r, y - r), (x + r, y - r), (x + r, y + r), (x - r, y + r)]))
    return Polygon(shell, rings)


@settings(max_examples=5, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_holed_regions())
def test_random_holed_regions_plan_or_are_refused_by_name(polygon: Polygon) -> None:
    limit = 6.0
    try:
        region = region_from_vertices(
            polygon.exterior.coords[:-1], holes=[r.coords[:-1] for r in polygon.interiors]
        )
        plan = plan_coverage(region, CoverageOptions(pattern="zigzag", time_limit=limit))
    except (InputError, InfeasibleError) as exc:
        assert str(exc).split(":")[0]  # names the argument
        return
    except SkyquillError:
        return
    assert plan.planning_time <= limit + 4.0  # one step (an LP solve) may overrun the budget
    if holes(region):
        _assert_safe(plan)


def test_a_flight_that_sprays_into_a_hole_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    from skyquill.coverage import mission

    gated = mission._gated

    def spray_everywhere(*args: object, **kwargs: object) -> object:
        path, spraying, pen = gated(*args, **kwargs)  # type: ignore[arg-type]
        return path, np.ones_like(spraying), pen  # a planner that forgot to close the nozzle

    monkeypatch.setattr(mission, "_gated", spray_everywhere)
    region = region_from_vertices(SQUARE, holes=[_round(8, 8, 2.0)])
    with pytest.raises(InfeasibleError, match="keepout: got a flight") as info:
        plan_coverage(region, ZIGZAG)
    assert info.value.families == ("keepout",)


def test_every_hole_gets_a_headland_lap_unless_it_would_leave_the_field() -> None:
    inner = region_from_vertices(SQUARE, holes=[[(6, 6), (9, 6), (9, 10), (6, 10)]])
    edge = region_from_vertices(SQUARE, holes=[[(0.5, 6), (3, 6), (3, 9), (0.5, 9)]])
    with_lap, without = plan_coverage(inner, ZIGZAG), plan_coverage(edge, ZIGZAG)
    assert with_lap.summary()["headlands"] == 1 and without.summary()["headlands"] == 0
    _assert_safe(with_lap)
    # The lap sweeps the band round the hole that the gated pieces miss.
    band = Polygon(inner.interiors[0]).buffer(1.0).difference(Polygon(inner.interiors[0]))
    assert band.difference(with_lap.mission.swept).area < 0.05 * band.area  # type: ignore[union-attr]


L_WITH_HOLE = (
    "POLYGON ((0 0, 20 0, 20 8, 8 8, 8 20, 0 20, 0 0), (12 2.5, 15 2.5, 15 5.5, 12 5.5, 12 2.5))"
)


def _same_flight(a: CoveragePlan, b: CoveragePlan) -> None:
    assert b.duration == a.duration
    t = np.linspace(0.0, a.duration, 2001)
    np.testing.assert_array_equal(b.trajectory.evaluate(t), a.trajectory.evaluate(t))
    assert b.pen_windows_s == a.pen_windows_s and b.coverage == a.coverage


def test_pieces_planned_at_once_in_a_pool_give_the_same_flight() -> None:
    from skyquill.parallel import Where

    region = load_region(L_WITH_HOLE)
    options = CoverageOptions(pattern="spiral")
    here = plan_tuned(region, options, 0.95)
    pooled = plan_tuned(region, options, 0.95, where=Where(workers=2))
    _same_flight(here, pooled)
    _assert_safe(pooled)


@pytest.mark.slow
def test_pieces_planned_on_a_dask_cluster_give_the_same_flight() -> None:
    from skyquill.parallel import Where

    region = region_from_vertices(SQUARE, holes=[_round(8, 8, 2.0)])
    here = plan_coverage(region, ZIGZAG)
    _same_flight(here, plan_coverage(region, ZIGZAG, where=Where(scheduler="local")))


def test_a_piece_planned_at_once_gets_the_budget_left_when_it_starts() -> None:
    # A worker that starts a piece late (queued behind others) must not get the budget
    # left when the pieces were handed out: the mission would run past its time limit.
    from skyquill.coverage.deadline import Deadline
    from skyquill.coverage.mission import _planned_alone

    seen: list[float] = []

    def plan_piece(piece: Polygon, deadline: Deadline) -> tuple[object, object]:
        seen.append(deadline.limit_s)
        return None, None

    square = Polygon([(0, 0), (1, 0), (1, 1), (0, 1)])
    _planned_alone(square, plan_piece=plan_piece, ends_at=time.time() + 30.0)  # type: ignore[arg-type]
    _planned_alone(square, plan_piece=plan_piece, ends_at=time.time() - 5.0)  # type: ignore[arg-type]
    assert 29.0 < seen[0] <= 30.0
    assert seen[1] == 0.0  # spent: its first check refuses with the time limit
