"""A plan's distance from the strokes, and the ink it leaves."""

from __future__ import annotations

import numpy as np
import pytest

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.brush import Brush
from skyquill.calligraphy.fidelity import contact_runs, measure_deviation, planned_ink, swung_tip
from skyquill.trajectory import SplineTrajectory


def test_measure_deviation_is_two_sided() -> None:
    line = SplineTrajectory(
        np.column_stack([np.linspace(0, 1, 6), np.zeros(6), np.ones(6)]), 5, 1.0
    )
    stroke = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 1.0]])
    assert measure_deviation(line, ((0.0, 1.0),), (stroke,)).max_m < 1e-9
    longer = np.array([[0.0, 0.0, 1.0], [1.5, 0.0, 1.0]])  # the path misses the last 0.5 m
    dev = measure_deviation(line, ((0.0, 1.0),), (longer,))
    assert dev.path_to_input_max_m < 1e-9
    assert dev.input_to_path_max_m == pytest.approx(0.5, abs=1e-6)


def test_contact_runs_are_the_runs_of_true() -> None:
    mask = np.array([0, 1, 1, 0, 0, 1, 0, 1, 1, 1], dtype=bool)
    assert contact_runs(mask) == [(1, 3), (5, 6), (7, 10)]
    assert contact_runs(np.zeros(4, dtype=bool)) == []


def test_a_level_flight_at_rest_swings_nothing() -> None:
    still = SplineTrajectory(np.tile([0.1, 0.2, 1.0], (8, 1)), 5, 2.0)
    t = np.linspace(0.0, 2.0, 5)
    assert np.allclose(swung_tip(still, t, 0.3), still.evaluate(t))


def test_planned_ink_is_where_the_tip_is_under_the_surface() -> None:
    """A straight pass at constant speed pressed 5 mm into the board between 0.2 m and 0.4 m
    (the dip is made of control points, so the ink starts and ends within the dip): one ink
    stroke, on the input line in the board's plane, the depth read back."""
    n = 40
    x = np.linspace(0.0, 0.6, n)
    z = np.where((x > 0.2) & (x < 0.4), 0.995, 1.02)
    traj = SplineTrajectory(np.column_stack([x, np.full(n, 0.1), z]), 3, 6.0)
    stroke = np.array([[0.2, 0.1, 1.0], [0.4, 0.1, 1.0]])
    board = Board(origin=np.array([0.0, 0.0, 1.0]))
    deviation, contact = planned_ink(
        traj, ((2.0, 4.0),), (stroke,), board, brush=Brush(), size_m=0.5
    )
    assert contact.ink_strokes == contact.strokes == 1
    assert 0.0 < contact.max_depth_m <= 0.006
    assert contact.holds
    assert deviation.path_to_input_max_m < 0.03  # the ink lies on the line, within its ends
