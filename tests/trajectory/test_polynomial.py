"""PiecewisePolynomial: exact derivatives, breaks, yaw, the squared-derivative integral."""

from __future__ import annotations

import numpy as np
import pytest

from skyquill.errors import InputError
from skyquill.trajectory import PiecewisePolynomial


def test_two_pieces_evaluate_exactly() -> None:
    # x = t^2 on [0, 1], then 1 + 2 (t - 1) on [1, 3].
    coeffs = np.zeros((2, 3, 1))
    coeffs[0, 2, 0] = 1.0
    coeffs[1, :2, 0] = [1.0, 2.0]
    traj = PiecewisePolynomial(np.array([0.0, 1.0, 3.0]), coeffs)
    t = np.array([0.0, 0.5, 1.0, 2.0, 3.0])
    np.testing.assert_allclose(traj.evaluate(t)[:, 0], [0.0, 0.25, 1.0, 3.0, 5.0])
    np.testing.assert_allclose(traj.evaluate(t, 1)[:, 0], [0.0, 1.0, 2.0, 2.0, 2.0])
    np.testing.assert_allclose(traj.evaluate(t, 3), 0.0)
    assert traj.breakpoints.tolist() == [0.0, 1.0, 3.0] and traj.dim == 1 and traj.degree == 2
    assert traj.squared_derivative_integral(1) == pytest.approx(4.0 / 3.0 + 8.0)
    assert traj.squared_derivative_integral(5) == 0.0
    np.testing.assert_array_equal(traj.evaluate_yaw(t), 0.0)


def test_validation() -> None:
    with pytest.raises(InputError, match=r"breaks: got breaks\[0\] = 1, expected 0"):
        PiecewisePolynomial(np.array([1.0, 2.0]), np.zeros((1, 2, 3)))
    with pytest.raises(InputError, match=r"breaks: got breaks\[2\] = 1 after 1"):
        PiecewisePolynomial(np.array([0.0, 1.0, 1.0]), np.zeros((2, 2, 3)))
    with pytest.raises(InputError, match="coeffs: got an array of shape"):
        PiecewisePolynomial(np.array([0.0, 1.0]), np.zeros((2, 2, 3)))
    with pytest.raises(InputError, match="yaw_coeffs"):
        PiecewisePolynomial(np.array([0.0, 1.0]), np.zeros((1, 2, 3)), np.zeros((2, 2)))
    traj = PiecewisePolynomial(np.array([0.0, 1.0]), np.zeros((1, 2, 3)))
    with pytest.raises(InputError, match=r"t: got times in \[2, 2\] s"):
        traj.evaluate(np.array([2.0]))


def test_evaluate_orders_is_evaluate_order_by_order() -> None:
    rng = np.random.default_rng(3)
    breaks = np.concatenate([[0.0], np.cumsum(rng.uniform(0.1, 2.0, 30))])
    traj = PiecewisePolynomial(breaks, rng.normal(size=(30, 6, 3)))
    t = np.sort(rng.uniform(0.0, traj.duration, 500))
    got = traj.evaluate_orders(t, (0, 1, 3, 7))
    assert list(got) == [0, 1, 3, 7]
    for n, values in got.items():
        np.testing.assert_array_equal(values, traj.evaluate(t, n))
    with pytest.raises(InputError, match="order"):
        traj.evaluate_orders(t, (-1,))
