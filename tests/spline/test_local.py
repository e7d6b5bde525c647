"""The local basis rows against scipy's own B-spline evaluation (an independent reference)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import BSpline

from skyquill.spline.basis import clamped_uniform_knots
from skyquill.spline.local import local_basis, rows_times, uniform_local_basis


def _reference(degree: int, n_ctrl: int, s: np.ndarray, order: int) -> np.ndarray:
    """Dense (N, M): the ``order``-th derivative of every basis function, by scipy."""
    knots = clamped_uniform_knots(degree, n_ctrl)
    eye = np.eye(n_ctrl)
    return np.column_stack(
        [BSpline(knots, eye[i], degree).derivative(order)(s) if order else
         BSpline(knots, eye[i], degree)(s) for i in range(n_ctrl)]
    )  # fmt: skip


def _dense(first: np.ndarray, values: np.ndarray, n_ctrl: int) -> np.ndarray:
    out = np.zeros((first.size, n_ctrl))
    for r in range(values.shape[1]):
        out[np.arange(first.size), first + r] += values[:, r]
    return out


@settings(max_examples=60, deadline=None)
@given(
    degree=st.integers(1, 7),
    extra=st.integers(0, 30),
    fractions=st.lists(st.floats(0.0, 1.0), min_size=1, max_size=20),
    on_knots=st.booleans(),
)
def test_rows_match_scipy_everywhere(
    degree: int, extra: int, fractions: list[float], on_knots: bool
) -> None:
    """Both evaluations agree with scipy's derivative splines at random parameters, at the
    knots (right-derivatives: scipy's convention) and at both ends, for every order."""
    n_ctrl = degree + 1 + extra
    n_spans = n_ctrl - degree
    s = np.array(fractions) * n_spans
    if on_knots:
        s = np.concatenate([s, np.arange(n_spans + 1.0)])
    knots = clamped_uniform_knots(degree, n_ctrl)
    general = local_basis(knots, degree, s, degree)
    uniform = uniform_local_basis(degree, n_spans, s, degree)
    np.testing.assert_array_equal(general.first, uniform.first)
    for order in range(degree + 1):
        ref = _reference(degree, n_ctrl, s, order)
        scale = max(1.0, float(np.abs(ref).max()))
        for got in (general, uniform):
            err = np.abs(_dense(got.first, got.values[order], n_ctrl) - ref).max()
            assert err <= 1e-10 * scale, (order, err)


@settings(max_examples=40, deadline=None)
@given(
    degree=st.integers(1, 7),
    extra=st.integers(0, 30),
    fractions=st.lists(st.floats(0.0, 1.0), min_size=1, max_size=20),
    dim=st.integers(1, 3),
    seed=st.integers(0, 2**16),
)
def test_rows_times_is_the_design_matrix_times_the_control_points(
    degree: int, extra: int, fractions: list[float], dim: int, seed: int
) -> None:
    """The curve from the local rows is the dense rows times ``C``, for one order and for
    a stack of orders (the gradient's derivatives 0-3 at once)."""
    n_ctrl = degree + 1 + extra
    s = np.array(fractions) * (n_ctrl - degree)
    basis = uniform_local_basis(degree, n_ctrl - degree, s, degree)
    C = np.random.default_rng(seed).normal(size=(n_ctrl, dim))
    stacked = rows_times(basis.first, basis.values, C)
    assert stacked.shape == (degree + 1, s.size, dim)
    for order in range(degree + 1):
        ref = _dense(basis.first, basis.values[order], n_ctrl) @ C
        scale = max(1.0, float(np.abs(ref).max()))
        np.testing.assert_allclose(
            rows_times(basis.first, basis.values[order], C), ref, atol=1e-12 * scale
        )
        np.testing.assert_array_equal(
            stacked[order], rows_times(basis.first, basis.values[order], C)
        )
