"""RetimedPath: the chain rule against finite differences, finite at the ends, exact timing."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import BSpline
from trajectory_kinds import arc_curve, retimed_arc, smoothstep_timing

from skyquill.errors import InputError
from skyquill.trajectory import PiecewisePolynomial, RetimedPath


def test_quintic_law_is_reproduced_exactly() -> None:
    traj = retimed_arc(4.0)
    t = np.linspace(0.0, 4.0, 501)
    x = t / 4.0
    u = 10 * x**3 - 15 * x**4 + 6 * x**5
    np.testing.assert_allclose(traj.timing.evaluate(t)[:, 0], u, atol=1e-12)
    np.testing.assert_allclose(traj.evaluate(t), arc_curve()(u), atol=1e-12)


@pytest.mark.parametrize("order", [1, 2, 3, 4])
def test_chain_rule_matches_central_differences(order: int) -> None:
    traj = retimed_arc(4.0)
    t = np.linspace(0.1, 3.9, 97)
    h = 1e-4
    numeric = (traj.evaluate(t + h, order - 1) - traj.evaluate(t - h, order - 1)) / (2 * h)
    scale = max(1.0, float(np.abs(numeric).max()))
    np.testing.assert_allclose(traj.evaluate(t, order), numeric, atol=1e-5 * scale)


def test_orders_at_once_are_the_orders_one_by_one() -> None:
    traj = retimed_arc(4.0)
    t = np.linspace(0.0, 4.0, 41)
    got = traj.evaluate_orders(t, (4, 1, 0, 3))
    assert list(got) == [4, 1, 0, 3]
    for n, values in got.items():
        np.testing.assert_array_equal(values, traj.evaluate(t, n))
    with pytest.raises(InputError, match="order"):
        traj.evaluate_orders(t, (5,))


def test_every_derivative_is_finite_and_at_rest_at_both_ends() -> None:
    traj = retimed_arc(3.0)
    ends = np.array([0.0, 3.0])
    for order in range(5):
        assert np.all(np.isfinite(traj.evaluate(ends, order)))
    np.testing.assert_allclose(traj.evaluate(ends, 1), 0.0, atol=1e-12)
    np.testing.assert_allclose(traj.evaluate(ends, 2), 0.0, atol=1e-10)
    np.testing.assert_allclose(traj.evaluate(ends)[0], [2.0, 0.0], atol=1e-9)


def test_samples_and_breakpoints() -> None:
    traj = retimed_arc(2.0)
    s = traj.sample(50.0)
    assert s.t[-1] == 2.0 and s.p.shape == (101, 2)
    assert traj.breakpoints[0] == 0.0 and traj.breakpoints[-1] == 2.0
    assert traj.dim == 2


def test_rejects_bad_parts() -> None:
    t, u, u1, u2 = smoothstep_timing(2.0)
    with pytest.raises(InputError, match=r"timing: got u\(0\) = 0 and u\(end\) = 0.5"):
        RetimedPath.from_samples(arc_curve(), t, u / 2, u1 / 2, u2 / 2)
    wide = BSpline(np.array([0, 0, 2.0, 2.0]), np.zeros((2, 2)), 1)
    with pytest.raises(InputError, match=r"curve: got a parameter range \[0, 2\]"):
        RetimedPath.from_samples(wide, t, u, u1, u2)
    two_axes = PiecewisePolynomial(np.array([0.0, 1.0]), np.zeros((1, 2, 2)))
    with pytest.raises(InputError, match="timing: got 2 axes, expected 1"):
        RetimedPath(arc_curve(), two_axes)
    with pytest.raises(InputError, match="order: got 5"):
        retimed_arc().evaluate(np.array([0.0]), 5)
