"""The upload budget: how a plan is cut into a vehicle's uploads."""

from __future__ import annotations

import numpy as np
import pytest

from skyquill.errors import InputError
from skyquill.targets import CRAZYFLIE, hover, is_hover, plan_uploads
from skyquill.trajectory import RestToRestSequence, SplineTrajectory


def _move(a: list[float], b: list[float], spans: int, duration: float) -> SplineTrajectory:
    """Rest-to-rest degree-7 spline from ``a`` to ``b`` with ``spans`` knot spans."""
    n = spans + 7
    s = np.linspace(0.0, 1.0, n)
    ease = s**3 * (10 - 15 * s + 6 * s**2)
    ease[:4], ease[-4:] = 0.0, 1.0  # equal first/last 4 points: rest to order 3
    points = np.asarray(a) + ease[:, None] * (np.asarray(b) - np.asarray(a))
    return SplineTrajectory(points, 7, duration)


def test_crazyflie_holds_31_pieces() -> None:
    assert CRAZYFLIE.max_pieces == 31  # 4096 B / 132 B (cflib Poly4D)


def test_hover_is_not_uploaded_and_separates_uploads() -> None:
    first = _move([0, 0, 1], [1, 0, 1], 20, 4.0)
    second = _move([1, 0, 1], [1, 1, 1], 25, 5.0)
    plan = RestToRestSequence((first, hover(np.array([1.0, 0, 1]), 1.0), second))
    uploads = plan_uploads(plan, CRAZYFLIE)
    assert [u.pieces for u in uploads] == [20, 25]
    assert [u.start_s for u in uploads] == [0.0, 5.0]
    assert [u.hover_before_s for u in uploads] == [0.0, 1.0]
    assert is_hover(plan.pieces[1]) and not is_hover(first)


def test_rest_joins_pack_greedily() -> None:
    a = _move([0, 0, 1], [1, 0, 1], 20, 4.0)
    b = _move([1, 0, 1], [0, 0, 1], 10, 2.0)
    c = _move([0, 0, 1], [1, 0, 1], 5, 1.0)
    uploads = plan_uploads(RestToRestSequence((a, b, c)), CRAZYFLIE)
    assert [u.pieces for u in uploads] == [30, 5]
    assert uploads[1].hover_before_s == 0.0 and uploads[1].start_s == 6.0


def test_a_long_motion_is_refused_with_the_way_out() -> None:
    with pytest.raises(InputError, match=r"got 40 pieces .* at most 31 .* target 'crazyflie'"):
        plan_uploads(_move([0, 0, 1], [1, 0, 1], 40, 4.0), CRAZYFLIE)
