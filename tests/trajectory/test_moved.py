"""A trajectory moved by a rigid motion: every point moved, every derivative turned, same timing."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from trajectory_kinds import rest_to_rest_leg, retimed_arc

from skyquill.errors import InputError
from skyquill.trajectory import (
    RestToRestSequence,
    SampledTrajectory,
    SplineTrajectory,
    Trajectory,
)
from skyquill.trajectory.moved import moved
from skyquill.validation import FloatArray


def _kinds() -> dict[str, Trajectory]:
    arc = retimed_arc()
    end = arc.evaluate(np.array([arc.duration]))[0]
    leg = rest_to_rest_leg(end, end + np.array([1.0, -2.0]), 3.0)
    spline = SplineTrajectory(np.array([[0.0, 0.0, 2.0], [1.0, 3.0, 2.0], [4.0, 1.0, 2.5],
                                        [5.0, 5.0, 3.0], [2.0, 6.0, 2.0]]), 3, 5.0)  # fmt: skip
    return {"retimed": arc, "polynomial": leg, "sequence": RestToRestSequence((arc, leg)),
            "spline": spline}  # fmt: skip


def _orthogonal(angle: float, mirror: bool) -> FloatArray:
    c, s = math.cos(angle), math.sin(angle)
    turn = np.array([[c, -s], [s, c]])
    return turn @ np.diag([1.0, -1.0]) if mirror else turn


@settings(max_examples=20, deadline=None)
@given(
    kind=st.sampled_from(sorted(_kinds())),
    angle=st.floats(-math.pi, math.pi),
    mirror=st.booleans(),
    shift=st.tuples(st.floats(-100, 100), st.floats(-100, 100)),
)
def test_points_move_and_derivatives_turn(
    kind: str, angle: float, mirror: bool, shift: tuple[float, float]
) -> None:
    traj = _kinds()[kind]
    rotation, offset = _orthogonal(angle, mirror), np.array(shift)
    out = moved(traj, rotation, offset)
    assert type(out) is type(traj) and out.duration == traj.duration
    np.testing.assert_array_equal(out.breakpoints, traj.breakpoints)
    t = np.linspace(0.0, traj.duration, 301)
    for order in range(4):
        before, after = traj.evaluate(t, order), out.evaluate(t, order)
        expected = before[:, :2] @ rotation.T + (offset if order == 0 else 0.0)
        scale = 1.0 + np.abs(before).max() + (np.abs(offset).max() if order == 0 else 0.0)
        np.testing.assert_allclose(after[:, :2], expected, rtol=0, atol=1e-12 * scale)
        np.testing.assert_array_equal(after[:, 2:], before[:, 2:])  # the height is kept


def test_a_matrix_that_is_not_orthogonal_is_refused() -> None:
    with pytest.raises(InputError, match=r"^rotation: got"):
        moved(retimed_arc(), np.diag([1.0, 2.0]), np.zeros(2))


def test_a_kind_it_cannot_move_is_named() -> None:
    t = np.linspace(0.0, 1.0, 5)
    samples = SampledTrajectory(t, np.zeros((5, 3)), np.zeros((5, 3)), np.zeros((5, 3)))
    with pytest.raises(InputError, match=r"^traj: got a SampledTrajectory"):
        moved(samples, np.eye(2), np.zeros(2))
