"""The shared piecewise-polynomial evaluator against numpy.polynomial."""

from __future__ import annotations

import numpy as np
import numpy.polynomial.polynomial as npoly
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.trajectory.horner import horner, horner_at, horner_columns, power_columns


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


@settings(max_examples=60, deadline=None)
@given(
    table=st.tuples(st.integers(1, 40), st.integers(1, 8), st.sampled_from([(), (1,), (3,)])),
    samples=st.integers(0, 120),
    order=st.integers(0, 9),
    seed=st.integers(0, 2**32 - 1),
)
def test_horner_at_is_horner_of_the_gathered_pieces_bit_for_bit(
    table: tuple[int, int, tuple[int, ...]], samples: int, order: int, seed: int
) -> None:
    pieces, n_coef, axes = table
    rng = np.random.default_rng(seed)
    coeffs = rng.normal(size=(pieces, n_coef, *axes)) * 10.0 ** rng.integers(-3, 4)
    idx = rng.integers(0, pieces, samples).astype(np.intp)
    tau = rng.uniform(0.0, 3.0, samples)
    expected = horner(coeffs[idx], tau, order)
    got = horner_at(coeffs, idx, tau, order)
    assert got.shape == expected.shape
    assert np.array_equal(got, expected)
    if order < n_coef:
        columns = horner_columns(power_columns(coeffs, order), idx, tau)
        assert np.array_equal(columns, expected)
