"""Writing for a Crazyflie: every upload fits its memory, uploads change at rest, limits hold."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from ink_check import ink_distance

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.mission import Mission, WritingOptions, plan_writing
from skyquill.calligraphy.show import plan_show
from skyquill.errors import InfeasibleError, InputError
from skyquill.strokes import Strokes, hanzi_strokes, typed_strokes
from skyquill.targets import CRAZYFLIE, is_hover, plan_uploads
from skyquill.trajectory import RestToRestSequence, SplineTrajectory, Trajectory
from skyquill.verify import verify

SIZE_M = 0.5
HOME = np.array([0.25, -1.0, 0.0])
TARGETED = WritingOptions(size_m=SIZE_M, target=CRAZYFLIE)


def _plan(strokes: Strokes, home: bool) -> Mission:
    return plan_writing(strokes, Board(), TARGETED, home=HOME if home else None)


@pytest.fixture(
    scope="module",
    # 永: one upload; 中 and the Latin "Hi" (Hershey font, not hanzi data): split;
    # with a home the take-off and landing legs share the first and last uploads.
    params=[("永", False), ("中", False), ("Hi", False), ("永", True)],
    ids=["yong", "zhong", "Hi", "yong-from-home"],
)
def mission(request: pytest.FixtureRequest) -> Mission:
    text, home = request.param
    strokes = hanzi_strokes(text) if len(text) == 1 else typed_strokes(text)
    return _plan(strokes, home)


def _splines(traj: Trajectory) -> list[SplineTrajectory]:
    parts = traj.pieces if isinstance(traj, RestToRestSequence) else (traj,)
    assert all(isinstance(p, SplineTrajectory) for p in parts)
    return [p for p in parts if isinstance(p, SplineTrajectory)]


def test_every_upload_fits_the_memory(mission: Mission) -> None:
    uploads = plan_uploads(mission.trajectory, CRAZYFLIE)
    for upload in uploads:
        assert upload.pieces <= 31
        assert upload.pieces * CRAZYFLIE.bytes_per_piece <= 4096
    assert all(p.degree <= 7 for p in _splines(mission.trajectory))
    assert mission.target is not None
    assert [u.pieces for u in mission.target.uploads] == [u.pieces for u in uploads]
    strategy = "one-upload" if len(uploads) == 1 else "split"
    assert mission.target.strategy == strategy


def test_uploads_change_at_rest_after_a_hover(mission: Mission) -> None:
    traj = mission.trajectory
    uploads = plan_uploads(traj, CRAZYFLIE)
    for i, upload in enumerate(uploads):
        ends = np.array([upload.start_s, upload.end_s])
        for order in (1, 2):
            assert np.abs(traj.evaluate(ends, order)).max() <= 1e-6
        assert upload.hover_before_s == (CRAZYFLIE.hover_s if i else 0.0)
    if isinstance(traj, RestToRestSequence):
        hovers = [p for p in traj.pieces if is_hover(p)]
        assert len(hovers) == len(uploads) - 1


def test_ink_within_one_percent(mission: Mission) -> None:
    """The swung tip's ink, read densely apart from the planner: one ink stroke per stroke,
    within 1 % of the size in the board's plane."""
    distance, ink_strokes = ink_distance(mission)
    assert distance <= 0.01 * SIZE_M
    assert ink_strokes == len(mission.strokes_world)
    assert mission.deviation.max_m <= 0.01 * SIZE_M
    assert mission.faithful


def test_limits_hold_densely_with_zero_excess(mission: Mission) -> None:
    check = verify(mission.trajectory, mission.limits)
    assert check.n_samples >= 10_000
    assert check.max_excess <= 1e-9
    assert mission.verification.max_excess <= 1e-9


def test_summary_names_strategy_and_uploads(mission: Mission) -> None:
    entry = mission.summary()["target"]
    assert entry["name"] == "crazyflie"
    assert entry["strategy"] in ("one-upload", "split")
    first = entry["uploads"][0]
    assert first.keys() >= {"pieces", "bytes", "start_s", "end_s", "hover_before_s"}
    assert first["start_s"] == 0.0
    assert entry["uploads"][-1]["end_s"] == pytest.approx(mission.trajectory.duration)


def test_vehicle_trajectory_is_the_tip_offset(mission: Mission) -> None:
    vehicle = mission.vehicle_trajectory()
    t = np.linspace(0.0, mission.trajectory.duration, 500)
    offset = vehicle.evaluate(t) - mission.trajectory.evaluate(t)
    assert np.allclose(offset, mission.brush_offset, atol=1e-12)
    assert len(plan_uploads(vehicle, CRAZYFLIE)) == len(plan_uploads(mission.trajectory, CRAZYFLIE))


def test_without_a_target_one_spline_as_before() -> None:
    mission = plan_writing(hanzi_strokes("一"), Board(), WritingOptions())
    assert mission.target is None
    assert isinstance(mission.trajectory, SplineTrajectory)
    assert mission.trajectory is mission.fits[0].trajectory
    assert "target" not in mission.summary()


def test_a_tolerance_no_plan_meets_says_what_would_fit() -> None:
    options = WritingOptions(size_m=SIZE_M, target=CRAZYFLIE, tolerance_m=0.0005)
    with pytest.raises(InfeasibleError) as info:
        plan_writing(hanzi_strokes("人"), Board(), options)
    message = str(info.value)
    assert "no plan for a crazyflie (31 pieces of degree 7 per upload)" in message
    assert "one upload of 31 pieces strays" in message
    assert "split at the pen-up points into" in message
    assert "expected within 0.5 mm" in message
    assert "a tolerance of" in message


def test_best_effort_returns_the_split_plan_beyond_the_tolerance() -> None:
    options = WritingOptions(size_m=SIZE_M, target=CRAZYFLIE, tolerance_m=0.0005, best_effort=True)
    mission = plan_writing(hanzi_strokes("人"), Board(), options)
    assert not mission.faithful
    assert all(u.pieces <= 31 for u in plan_uploads(mission.trajectory, CRAZYFLIE))


def test_target_must_be_an_upload_target() -> None:
    with pytest.raises(InputError, match="target: got str, expected UploadTarget or None"):
        WritingOptions(target="crazyflie")  # type: ignore[arg-type]


def test_a_show_of_targeted_missions_checks_separation() -> None:
    # The vehicle's path fitted: 0.3 m characters fit a Crazyflie's uploads (fitting the
    # tip, a stroke alone strays 6 mm at 0.4 m: few knot spans for the swing).
    options = WritingOptions(size_m=0.3, target=CRAZYFLIE, follow="path")
    show = plan_show([hanzi_strokes("人"), hanzi_strokes("中")], options, workers=1)
    assert show.min_separation_m >= 1.0
    for m in show.missions:
        assert all(u.pieces <= 31 for u in plan_uploads(m.vehicle_trajectory(), CRAZYFLIE))


def test_one_strategy_alone_is_measured() -> None:
    """Fitting the path, 中 does not fit one upload at 1 %: alone, that strategy says so;
    best effort returns it. (Fitting the tip, it fits.)"""
    alone = WritingOptions(
        size_m=SIZE_M, target=CRAZYFLIE, target_strategies=("one-upload",), follow="path"
    )
    with pytest.raises(InfeasibleError, match="one upload of 31 pieces strays") as info:
        plan_writing(hanzi_strokes("中"), Board(), alone)
    assert "split at" not in str(info.value)
    mission = plan_writing(hanzi_strokes("中"), Board(), replace(alone, best_effort=True))
    assert mission.target is not None and mission.target.strategy == "one-upload"
    assert [u.pieces for u in mission.target.uploads] == [31]
    assert not mission.faithful


@pytest.mark.parametrize("strategies", [(), ("split", "split"), ("knots",)])
def test_target_strategies_are_checked(strategies: tuple[str, ...]) -> None:
    with pytest.raises(InputError, match="target_strategies: got"):
        WritingOptions(target_strategies=strategies)  # type: ignore[arg-type]
