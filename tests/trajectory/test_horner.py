"""The shared piecewise-polynomial evaluator against numpy.polynomial."""

from __future__ import annotations

import numpy as np
import numpy.polynomial.polynomial as npoly

from skyquill.trajectory.horner import horner


def test_horner_matches_numpy_for_every_derivative() -> None:
    rng = np.random.default_rng(0)
    coeffs = rng.normal(size=(50, 8, 3))
    tau = rng.uniform(0.0, 2.0, 50)
    for order in range(10):
        expected = np.array(
            [
                [npoly.polyval(tau[i], npoly.polyder(coeffs[i, :, a], order)) for a in range(3)]
                for i in range(50)
            ]
        )
        assert np.allclose(horner(coeffs, tau, order), expected, rtol=1e-12, atol=1e-9)


def test_horner_on_scalar_pieces() -> None:
    coeffs = np.array([[1.0, 2.0, 3.0]])  # 1 + 2 t + 3 t^2
    assert horner(coeffs, np.array([2.0])).tolist() == [17.0]
    assert horner(coeffs, np.array([2.0]), 1).tolist() == [14.0]
