"""Light painting on a sky board: the light is the vehicle, the flight stays on the plane,
and paper 003 §5.3's plane cost keeps it there when seen from the side."""

from __future__ import annotations

import numpy as np
import pytest

from skyquill.calligraphy.board import Board, sky_board
from skyquill.calligraphy.distortion import (
    VIEW_ANGLES_DEG,
    mission_distortion,
    project,
    view_distortion,
)
from skyquill.calligraphy.mission import Mission, WritingOptions, plan_writing
from skyquill.errors import InputError
from skyquill.limits import VehicleLimits
from skyquill.optimize import Boundary, PlaneDeviation, PointDeviation, SmoothingProblem, solve
from skyquill.strokes import typed_strokes

BOARD = sky_board(np.array([0.0, 0.0, 2.0]), yaw_deg=30.0, tilt_deg=20.0)
HOME = np.array([0.3, -2.0, 0.0])


def _plan(weight: float) -> Mission:
    options = WritingOptions(size_m=0.8, plane_weight=weight)
    return plan_writing(typed_strokes("Hi", "futural"), BOARD, options, HOME)


@pytest.fixture(scope="module")
def with_cost() -> Mission:
    return _plan(1e5)


@pytest.fixture(scope="module")
def without_cost() -> Mission:
    return _plan(0.0)


def _off_plane(mission: Mission, t0: float, t1: float) -> float:
    t = np.linspace(t0, t1, 5000)
    return float(np.abs(mission.board.to_board(mission.trajectory.evaluate(t))[:, 2]).max())


def test_the_light_is_the_vehicle(with_cost: Mission) -> None:
    np.testing.assert_array_equal(with_cost.brush_offset, np.zeros(3))
    t = np.linspace(0.0, with_cost.trajectory.duration, 50)
    vehicle = with_cost.vehicle_trajectory().evaluate(t)
    np.testing.assert_allclose(vehicle, with_cost.trajectory.evaluate(t), atol=1e-12)
    np.testing.assert_allclose(with_cost.trajectory.evaluate(np.array([0.0]))[0], HOME)
    summary = with_cost.summary()
    assert summary["follow"] == "path" and "contact" not in summary
    assert with_cost.faithful and with_cost.verification.max_excess <= 1e-9


def test_the_drawing_and_its_transits_stay_on_the_plane(with_cost: Mission) -> None:
    # From the first stroke's start to the last one's end, pen up or down: no lift.
    first, last = with_cost.pen_windows[0][0], with_cost.pen_windows[-1][1]
    assert _off_plane(with_cost, first, last) < 1e-3


def test_the_plane_cost_pulls_the_path_onto_the_plane(
    with_cost: Mission, without_cost: Mission
) -> None:
    first, last = with_cost.pen_windows[0][0], with_cost.pen_windows[-1][1]
    on, off = _off_plane(with_cost, first, last), _off_plane(without_cost, first, last)
    assert off > 2.0 * on  # the approach from home, smoothed, leaves the plane without it
    side_on = mission_distortion(with_cost)[-1]
    side_off = mission_distortion(without_cost)[-1]
    assert side_on.angle_deg == 90.0 and side_on.rms_m < side_off.rms_m


def _m(board: Board, weight: float) -> tuple[np.ndarray, np.ndarray]:
    """Paper 003 Fig. 8's M, per-axis speed and acceleration limits (bench/sky_distortion.py)."""
    vertices = board.to_world(
        np.array([[0.0, 0.0], [0.5, 2.0], [1.0, 0.8], [1.5, 2.0], [2.0, 0.0]])
    )
    duration = 8.0
    t = np.linspace(0.0, duration, 5)
    terms: tuple[PointDeviation | PlaneDeviation, ...] = (
        PointDeviation(t[1:-1], vertices[1:-1], 1e5),
    )
    if weight:
        terms += (PlaneDeviation(board.normal, board.origin, 0.0, duration, weight),)
    limits = VehicleLimits(None, None, None, 1.2, 1.5, None).derivative_limits(3)
    fit = solve(
        SmoothingProblem(
            3,
            5,
            165,
            duration,
            {3: 1.0},
            terms,
            boundary=Boundary.rest(vertices[0], vertices[-1], 3),
            limits=limits,
        )
    )
    assert fit.verification.max_excess <= 1e-9
    return fit.trajectory.evaluate(np.linspace(0.0, duration, 3000)), vertices


def test_the_m_leaves_a_turned_plane_without_the_cost_and_not_with_it() -> None:
    board = sky_board(np.array([0.0, 0.0, 2.0]), yaw_deg=35.0, tilt_deg=25.0)
    heights = {}
    for weight in (0.0, 1e5):
        path, _ = _m(board, weight)
        heights[weight] = float(np.abs(board.to_board(path)[:, 2]).max())
    # Measured: 48.8 mm without, 5.8 mm with (bench/results/sky_distortion.json).
    assert heights[0.0] > 0.04
    assert heights[1e5] < 0.008


def test_the_m_on_an_unturned_plane_stays_on_it_anyway() -> None:
    # Per-axis boxes are symmetric about the plane y = 0: so is the optimum.
    board = sky_board(np.array([0.0, 0.0, 2.0]))
    path, _ = _m(board, 0.0)
    assert float(np.abs(board.to_board(path)[:, 2]).max()) < 1e-6


def test_the_side_view_is_the_distance_off_the_plane() -> None:
    board = sky_board(np.array([1.0, 2.0, 3.0]), yaw_deg=-40.0, tilt_deg=10.0)
    stroke = board.to_world(np.array([[0.0, 0.0], [0.0, 1.0]]))
    path = board.to_world(np.array([[0.0, 0.2], [0.0, 0.5]])) + np.array([[0.01], [0.03]]) * (
        board.normal
    )
    front, oblique, side = (view_distortion([path], [stroke], board, a) for a in VIEW_ANGLES_DEG)
    assert front.max_m == pytest.approx(0.0, abs=1e-12)
    assert side.max_m == pytest.approx(0.03) and oblique.max_m == pytest.approx(
        0.03 * np.sin(np.radians(55))
    )
    np.testing.assert_allclose(project(np.array([[1.0, 2.0, 3.0]]), 90.0), [[3.0, 2.0]])
    with pytest.raises(InputError, match="paths_W: got 0 paths for 1 strokes"):
        view_distortion([], [stroke], board, 0.0)


def test_a_sky_board_needs_no_brush_but_must_fit_under_the_ceiling() -> None:
    options = WritingOptions(size_m=0.5, plane_weight=0.0)
    strokes = typed_strokes("l", "futural")
    plan_writing(strokes, sky_board(np.array([0.0, 0.0, 1.0])), options)  # no brush reach check
    with pytest.raises(InputError, match="below 120 m"):
        plan_writing(strokes, sky_board(np.array([0.0, 0.0, 119.8]), tilt_deg=10.0), options)
    with pytest.raises(InputError, match="plane_weight"):
        WritingOptions(plane_weight=-1.0)
