"""Writing missions: continuity, pen windows, fidelity, limits, boards, several drones."""

from __future__ import annotations

import dataclasses
import itertools
import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from ink_check import ink_distance, tip_on_board

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.fidelity import contact_runs
from skyquill.calligraphy.mission import (
    WritingOptions,
    check_separation,
    densify,
    plan_writing,
)
from skyquill.calligraphy.show import layout, plan_show
from skyquill.errors import InfeasibleError, InputError, SkyquillError
from skyquill.geometry import polyline_distance
from skyquill.limits import VehicleLimits
from skyquill.strokes import Strokes, hanzi_strokes, text_strokes
from skyquill.trajectory import SplineTrajectory

H = Strokes(
    paths=(
        np.array([[0.0, 0.0], [0.0, 1.0]]),
        np.array([[0.6, 0.0], [0.6, 1.0]]),
        np.array([[0.0, 0.5], [0.6, 0.5]]),
    )
)
HOME = np.array([0.25, -1.0, 0.0])


@pytest.fixture(scope="module")
def h_mission():  # type: ignore[no-untyped-def]
    return plan_writing(H, Board(), WritingOptions(), home=HOME)


def test_one_continuous_flight_from_home_to_home(h_mission) -> None:  # type: ignore[no-untyped-def]
    traj = h_mission.trajectory
    ends = traj.evaluate(np.array([0.0, traj.duration]))
    tip_home = HOME - [0.0, 0.0, 0.3]  # the brush hangs 0.3 m below the vehicle
    assert np.allclose(ends, [tip_home, tip_home], atol=1e-9)
    assert np.allclose(traj.evaluate(np.array([0.0, traj.duration]), 1), 0.0, atol=1e-9)
    assert h_mission.verification.max_excess <= 1e-9


def test_pen_windows_are_on_the_board_and_within_tolerance(h_mission) -> None:  # type: ignore[no-untyped-def]
    assert len(h_mission.pen_windows) == 3
    assert h_mission.faithful
    assert h_mission.deviation.max_m <= 0.005
    travel = h_mission.options.brush.travel_m
    for t0, t1 in h_mission.pen_windows:
        # The untilted tip presses into the board (the swung tip rises a little above it).
        z = h_mission.trajectory.evaluate(np.linspace(t0, t1, 200))[:, 2]
        assert 1.0 - travel <= z.min() and z.max() <= 1.0
    # Between strokes the brush is lifted.
    gaps = [
        (a[1], b[0])
        for a, b in zip(h_mission.pen_windows[:-1], h_mission.pen_windows[1:], strict=True)
    ]
    for t0, t1 in gaps:
        z = h_mission.trajectory.evaluate(np.array([0.5 * (t0 + t1)]))[0, 2]
        assert z > 1.0 + 0.02


def test_pen_column_matches_windows(h_mission) -> None:  # type: ignore[no-untyped-def]
    t = np.linspace(0.0, h_mission.trajectory.duration, 1000)
    pen = h_mission.pen(t)
    assert set(np.unique(pen)) == {0.0, 1.0}
    assert pen[0] == 0.0 and pen[-1] == 0.0


def test_vehicle_trajectory_is_offset_by_the_brush(h_mission) -> None:  # type: ignore[no-untyped-def]
    vehicle = h_mission.vehicle_trajectory()
    t = np.linspace(0, vehicle.duration, 50)
    assert np.allclose(vehicle.evaluate(t) - h_mission.trajectory.evaluate(t), [0, 0, 0.3])
    assert np.allclose(vehicle.evaluate(t, 2), h_mission.trajectory.evaluate(t, 2))


def test_densify_keeps_vertices_and_spacing() -> None:
    poly = np.array([[0.0, 0, 0], [0.1, 0, 0], [0.1, 0.005, 0]])
    dense = densify(poly, 0.01)
    assert np.all(np.linalg.norm(np.diff(dense, axis=0), axis=1) <= 0.01 + 1e-12)
    for v in poly:
        assert np.min(np.linalg.norm(dense - v, axis=1)) < 1e-12


@settings(max_examples=60, deadline=None)
@given(
    steps=st.lists(
        st.tuples(*[st.floats(-0.05, 0.05, allow_subnormal=False)] * 3), min_size=0, max_size=25
    ),
    spacing=st.sampled_from([0.001, 0.01, 0.03]),
)
def test_densify_is_each_segment_sampled_alone(
    steps: list[tuple[float, float, float]], spacing: float
) -> None:
    """All segments at once give what sampling each segment alone gives, bit for bit:
    ``a + (j / n) (b - a)`` on a long segment, its end itself on a short or empty one."""
    poly = np.cumsum(np.array([(0.0, 0.0, 1.0), *steps]), axis=0)
    expected = [poly[:1]]
    for a, b in itertools.pairwise(poly):
        if np.linalg.norm(b - a) > spacing:
            n = math.ceil(float(np.linalg.norm(b - a)) / spacing)
            expected.append(a + np.outer(np.arange(1, n + 1) / n, b - a))
        else:
            expected.append(b[None, :])
    np.testing.assert_array_equal(densify(poly, spacing), np.vstack(expected))


def test_wall_board() -> None:
    wall = Board("wall", np.array([0.0, 2.0, 1.0]))
    mission = plan_writing(H, wall, WritingOptions(size_m=0.4))
    assert mission.faithful
    for (t0, t1), stroke in zip(mission.pen_windows, mission.strokes_world, strict=True):
        y = mission.trajectory.evaluate(np.linspace(t0, t1, 50))[:, 1]
        assert np.abs(y - 2.0).max() <= 0.004
        assert np.allclose(stroke[:, 1], 2.0)


def test_text_and_hanzi_are_written_faithfully() -> None:
    for strokes in (text_strokes("Hi"), hanzi_strokes("永")):
        mission = plan_writing(strokes)
        assert mission.faithful, strokes.source
        assert mission.verification.max_excess <= 1e-9


def test_polytope_norm_limits() -> None:
    limits = VehicleLimits(0.8, 1.0, 5.0)
    mission = plan_writing(H, options=WritingOptions(limits=limits, norm_sides=8))
    check = mission.verification
    assert check.max_excess <= 1e-9 and mission.faithful


def test_separation_violation_is_an_error() -> None:
    a = SplineTrajectory(np.zeros((6, 3)), 5, 1.0)
    b = SplineTrajectory(np.tile([0.5, 0.0, 0.0], (6, 1)), 5, 2.0)
    with pytest.raises(
        InfeasibleError, match=r"separation: drone 0 and drone 1 come within 0\.500 m"
    ):
        check_separation([a, b], 1.0)
    assert check_separation([a, b], 0.4) == pytest.approx(0.5)


def test_four_drones_write_yi_ma_dang_xian() -> None:
    parts = [hanzi_strokes(c) for c in "一马当先"]
    show = plan_show(parts, WritingOptions(size_m=0.5), separation_m=1.0, workers=2)
    assert len(show.missions) == 4
    assert show.min_separation_m >= 1.0
    assert all(m.faithful for m in show.missions)
    homes = [m.vehicle_trajectory().evaluate(np.array([0.0]))[0] for m in show.missions]
    assert np.allclose(homes, show.homes)


def test_layout_spacing() -> None:
    boards = layout(3, 0.5, 1.0)
    xs = [b.origin[0] for b, _ in boards]
    assert np.diff(xs).min() >= 0.5 + 1.0


def test_bad_options() -> None:
    with pytest.raises(InputError, match="size_m: got 0, expected a number > 0"):
        WritingOptions(size_m=0.0)
    with pytest.raises(InputError, match="board kind: got 'floor'"):
        Board("floor")  # type: ignore[arg-type]


@pytest.mark.parametrize("mode", ["fixed", "free"])
def test_resegmentation_lowers_the_cost_and_keeps_fidelity(mode: str) -> None:
    strokes = hanzi_strokes("永")
    before = plan_writing(strokes, options=WritingOptions(resegment="off"))
    after = plan_writing(strokes, options=WritingOptions(resegment=mode))  # type: ignore[arg-type]
    assert after.faithful and after.verification.max_excess <= 1e-9
    if mode == "fixed":
        assert after.trajectory.duration == pytest.approx(before.trajectory.duration, rel=1e-12)
        assert after.fits[0].cost < before.fits[0].cost
    else:
        assert after.trajectory.duration < before.trajectory.duration


def test_a_million_points_is_refused_quickly() -> None:
    import time

    t = np.linspace(0.0, 60.0, 1_000_000)
    huge = Strokes(paths=(np.column_stack([np.cos(t), np.sin(t) + 0.001 * t]),))
    start = time.perf_counter()
    with pytest.raises(InputError, match=r"strokes: got 1,000,000 points, expected at most"):
        plan_writing(huge)
    assert time.perf_counter() - start < 2.0


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.lists(
        st.lists(
            st.tuples(st.floats(-1e3, 1e3, allow_nan=False), st.floats(-1e3, 1e3, allow_nan=False)),
            min_size=0,
            max_size=12,
        ),
        min_size=0,
        max_size=3,
    )
)
def test_random_strokes_through_the_whole_pipeline(paths: list[list[tuple[float, float]]]) -> None:
    """Only skyquill's own errors, or a plan that respects the limits."""
    try:
        mission = plan_writing(
            Strokes(paths=tuple(np.array(p, dtype=float).reshape(-1, 2) for p in paths)),
            options=WritingOptions(resegment="off", max_stretches=2),
        )
    except SkyquillError as exc:
        assert str(exc)
        return
    assert mission.verification.max_excess <= 1e-9
    assert np.isfinite(mission.deviation.max_m)


def test_the_swung_tip_writes_the_strokes_by_default() -> None:
    """Fitting the tip (the default): the hanging brush's ink, read densely apart from the
    planner, is one stroke per input stroke within 1 %, pressed within the bearing's travel;
    the untilted path, which the vehicle-path mode fits, is not where the ink goes."""
    mission = plan_writing(hanzi_strokes("中"), Board(), WritingOptions(), home=HOME)
    assert mission.options.follows_tip(mission.board)
    distance, ink_strokes = ink_distance(mission)
    assert distance <= 0.005
    assert ink_strokes == len(mission.strokes_world) == 4
    assert mission.contact is not None and mission.contact.holds
    t, local, touching = tip_on_board(mission)
    assert -local[touching, 2].min() <= mission.options.brush.travel_m
    pen = mission.pen(t) > 0
    # Pressed at the planned depth while writing (the ends are touch-down and lift-off).
    press = mission.options.brush.press_depth_m
    assert np.median(-local[pen, 2]) == pytest.approx(press, abs=1e-3)
    summary = mission.summary()
    assert summary["follow"] == "tip" and summary["contact"]["holds"]
    path = plan_writing(hanzi_strokes("中"), Board(), WritingOptions(follow="path"), home=HOME)
    assert path.contact is None and path.summary()["follow"] == "path"
    assert ink_distance(path)[0] > 3 * distance


def test_fitting_the_tip_flies_ink_within_one_percent() -> None:
    """Closed loop over the brush's contact: the simulated ink (in the board's plane) stays
    within 1 % and whole; with the path fitted it lies centimetres off."""
    from skyquill.calligraphy.mission import contact_board
    from skyquill.sim import Quadrotor, simulate

    gaps = {}
    for follow in ("tip", "path"):
        mission = plan_writing(hanzi_strokes("中"), options=WritingOptions(follow=follow))
        flight = simulate(mission.vehicle_trajectory(), Quadrotor(), board=contact_board(mission))
        ink = np.vstack(flight.ink)[:, :2]
        flat = [s[:, :2] for s in mission.strokes_world]
        gaps[follow] = np.min([polyline_distance(ink, s) for s in flat], axis=0).max()
        if follow == "tip":
            assert len(flight.ink) == len(mission.strokes_world)
    assert gaps["tip"] <= 0.005
    assert gaps["path"] > 0.015


def test_a_wall_is_written_by_the_path() -> None:
    wall = Board("wall", np.array([0.0, 2.0, 1.0]))
    mission = plan_writing(hanzi_strokes("一"), wall, WritingOptions())
    assert not mission.options.follows_tip(wall)
    assert mission.contact is None


def test_route_times_lifts_for_the_jerk_limit_and_settle_after_the_approach() -> None:
    """Fitting the tip, every lift lasts at least a jerk-limited rest-to-rest move of its
    length; coming from home, the legs to and from it are slower and the vehicle pauses
    above the first stroke. Fitting the path, only the home legs change."""
    from skyquill.calligraphy.route import LIFT, route_points
    from skyquill.calligraphy.timing import (
        HOME_LEG_SPEED,
        LIFT_JERK_FACTOR,
        SETTLE_S,
        route_times,
    )
    from skyquill.optimize.timing import allocate_path_times

    board, opts = Board(), WritingOptions()
    strokes = tuple(board.to_world(p) for p in hanzi_strokes("人").scaled(0.5).paths)
    home = HOME - 0.3 * board.normal
    points, roles = route_points(strokes, board, home)
    tip = np.diff(route_times(points, roles, board, opts))
    path = np.diff(route_times(points, roles, board, WritingOptions(follow="path")))
    base = np.diff(allocate_path_times(points, 1.0, 1.0))
    lengths = np.linalg.norm(np.diff(points, axis=0), axis=1)
    lifts = contact_runs(roles == LIFT)
    assert len(lifts) == 4  # down onto and up from each of its two strokes
    for start, stop in lifts:
        legs = slice(start - 1, stop)
        least = (LIFT_JERK_FACTOR * lengths[legs].sum() / 10.0) ** (1 / 3)
        extra = SETTLE_S if start == lifts[0][0] else 0.0
        assert tip[legs].sum() >= least + extra - 1e-9
    approach = slice(0, lifts[0][0] - 1)
    assert np.allclose(path[approach], base[approach] / HOME_LEG_SPEED)
    inside = slice(lifts[0][0], lifts[-1][1])
    assert np.allclose(path[inside], base[inside])  # the path's writing keeps its timing


def test_a_character_beyond_the_tolerance_is_refused_with_the_measured_distance() -> None:
    """Too tight a tolerance: the error says how far the swung tip stays, after how many
    stretches, and what would help; best effort returns the plan, marked unfaithful."""
    tight = WritingOptions(tolerance_m=0.0002, max_stretches=1)
    with pytest.raises(InfeasibleError) as info:
        plan_writing(hanzi_strokes("人"), Board(), tight)
    message = str(info.value)
    assert re.search(r"the swung brush tip stays \d+(\.\d+)? mm from the input", message)
    assert "expected within the tolerance of 0.2 mm" in message
    assert "after 1 stretches (1.25x slower)" in message
    assert "best_effort" in message
    best = plan_writing(hanzi_strokes("人"), Board(), dataclasses.replace(tight, best_effort=True))
    assert not best.faithful and best.deviation.max_m > 0.0002
