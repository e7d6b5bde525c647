"""The local basis rows against scipy's own B-spline evaluation (an independent reference)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import BSpline

from skyquill.spline.basis import clamped_uniform_knots
from skyquill.spline.local import local_basis, uniform_local_basis


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
