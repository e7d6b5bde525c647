"""Tests for skyquill.spline.basis: the clamped uniform B-spline basis (paper 003 §2, §3.7).

Every quantity is checked against an independent reference: scipy's
``BSpline`` (built here from the knot vector of eq. 4 written out in the test),
finite differences, composite Gauss-Legendre quadrature and convex-hull
checks with random directions.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray
from scipy.interpolate import BSpline
from scipy.optimize import nnls

from skyquill.errors import InputError
from skyquill.spline import ClampedUniformBasis, basis_for, clamped_uniform_knots

FloatArray = NDArray[np.float64]

DEGREES = list(range(1, 8))
# (degree, n_ctrl) pairs: minimal (one span), a few spans, many spans.
CASES = [(k, m) for k in DEGREES for m in (k + 1, k + 3, k + 9)]


def _ref_knots(k: int, M: int) -> FloatArray:
    """Paper 003 eq. (4), written out independently: k+1 zeros, 1..L-1, k+1 copies of L."""
    L = M - k
    return np.concatenate([np.zeros(k + 1), np.arange(1, L, dtype=float), np.full(k + 1, L)])


def _dense_s(L: int, per_span: int = 37) -> FloatArray:
    """Dense parameters on [0, L] including both ends and every knot."""
    return np.unique(np.concatenate([np.linspace(0.0, L, per_span * L + 1), np.arange(L + 1.0)]))


def _random_ctrl(M: int, d: int, seed: int) -> FloatArray:
    return np.random.default_rng(seed).uniform(-1.0, 1.0, size=(M, d))


def _scipy_derivative(k: int, M: int, C: FloatArray, n: int, s: FloatArray) -> FloatArray:
    """n-th s-derivative of sum_i c_i N_i^k(s) by scipy, shape (N, d)."""
    spline = BSpline(_ref_knots(k, M), C, k)
    return np.asarray(spline.derivative(n)(s) if n else spline(s), dtype=float)


# ------------------------------------------------------------------ knots, basis values
@pytest.mark.parametrize(("k", "M"), CASES)
def test_knots_match_eq4(k: int, M: int) -> None:
    basis = ClampedUniformBasis(k, M)
    assert basis.n_spans == M - k
    np.testing.assert_array_equal(basis.knots, _ref_knots(k, M))
    np.testing.assert_array_equal(clamped_uniform_knots(k, M), _ref_knots(k, M))
    assert basis.knots.shape == (M + k + 1,)


@pytest.mark.parametrize(("k", "M"), CASES)
def test_partition_of_unity_and_nonnegativity(k: int, M: int) -> None:
    basis = ClampedUniformBasis(k, M)
    s = _dense_s(basis.n_spans)
    N = basis.design_matrix(s).toarray()
    assert N.shape == (s.size, M)
    assert N.min() >= -1e-12
    np.testing.assert_allclose(N.sum(axis=1), 1.0, rtol=0, atol=1e-12)
    # Clamped ends interpolate the first and last control points (eq. 40).
    np.testing.assert_allclose(N[0], np.eye(M)[0], atol=1e-12)
    np.testing.assert_allclose(N[-1], np.eye(M)[-1], atol=1e-12)


@pytest.mark.parametrize(("k", "M"), CASES)
def test_design_matrix_is_sparse_with_local_support(k: int, M: int) -> None:
    basis = ClampedUniformBasis(k, M)
    s = _dense_s(basis.n_spans, per_span=5)
    N = basis.design_matrix(s).toarray()
    # At most k+1 basis functions are non-zero on a span (§3.4).
    assert int(np.max(np.count_nonzero(np.abs(N) > 1e-15, axis=1))) <= k + 1


def test_basis_for_is_cached() -> None:
    assert basis_for(3, 10) is basis_for(3, 10)
    assert basis_for(3, 10) == ClampedUniformBasis(3, 10)


# ------------------------------------------------------------------ derivative maps
@pytest.mark.parametrize(("k", "M"), CASES)
def test_design_matrix_derivatives_match_scipy(k: int, M: int) -> None:
    basis = ClampedUniformBasis(k, M)
    C = _random_ctrl(M, 3, seed=10 * k + M)
    s = _dense_s(basis.n_spans, per_span=11)
    for n in range(k + 1):
        got = basis.design_matrix(s, n) @ C
        want = _scipy_derivative(k, M, C, n, s)
        scale = max(1.0, float(np.abs(want).max()))
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-11 * scale, err_msg=f"order {n}")


@pytest.mark.parametrize(("k", "M"), CASES)
def test_design_matrix_derivatives_match_finite_differences(k: int, M: int) -> None:
    basis = ClampedUniformBasis(k, M)
    C = _random_ctrl(M, 2, seed=7 * k + M)
    L = basis.n_spans
    # Inside spans only: the k-th derivative jumps at knots.
    u = np.linspace(0.05, 0.95, 7)
    s = (np.arange(L)[:, None] + u[None, :]).ravel()
    h = 1e-4
    for n in range(1, k + 1):
        got = basis.design_matrix(s, n) @ C
        fd = (basis.design_matrix(s + h, n - 1) @ C - basis.design_matrix(s - h, n - 1) @ C) / (
            2 * h
        )
        scale = max(1.0, float(np.abs(got).max()))
        np.testing.assert_allclose(fd, got, rtol=0, atol=1e-5 * scale, err_msg=f"order {n}")


@pytest.mark.parametrize(("k", "M"), CASES)
def test_derivative_control_points_define_the_reduced_spline(k: int, M: int) -> None:
    """Eqs. (33)-(35): Γ_n C on the knots with n copies removed at each end is S^(n)."""
    basis = ClampedUniformBasis(k, M)
    C = _random_ctrl(M, 3, seed=3 * k + M)
    s = _dense_s(basis.n_spans, per_span=13)
    knots = _ref_knots(k, M)
    for n in range(k + 1):
        Gamma = basis.derivative_map(n)
        assert Gamma.shape == (M - n, M)
        reduced_knots = knots[n : len(knots) - n]
        assert reduced_knots.size == (M - n) + (k - n) + 1
        reduced = BSpline(reduced_knots, Gamma @ C, k - n)
        want = _scipy_derivative(k, M, C, n, s)
        scale = max(1.0, float(np.abs(want).max()))
        np.testing.assert_allclose(reduced(s), want, rtol=0, atol=1e-11 * scale)
        sub = basis.reduced(n)
        if n == k:
            assert sub is None
        else:
            assert sub is not None
            np.testing.assert_array_equal(sub.knots, reduced_knots)


@pytest.mark.parametrize("k", DEGREES)
def test_first_derivative_map_is_eq34(k: int) -> None:
    """Γ_1 row i: k / (s_{i+k+1} - s_{i+1}) * (c_{i+1} - c_i)."""
    M = k + 6
    s = _ref_knots(k, M)
    want = np.zeros((M - 1, M))
    for i in range(M - 1):
        f = k / (s[i + k + 1] - s[i + 1])
        want[i, i], want[i, i + 1] = -f, f
    np.testing.assert_allclose(ClampedUniformBasis(k, M).derivative_map(1).toarray(), want)


@pytest.mark.parametrize(("k", "M"), CASES)
def test_derivative_maps_compose(k: int, M: int) -> None:
    """Γ_n is Γ_1 of the reduced basis applied after Γ_{n-1} (eq. 37, "repeating")."""
    basis = ClampedUniformBasis(k, M)
    for n in range(1, k):
        sub = basis.reduced(n)
        assert sub is not None
        lhs = basis.derivative_map(n + 1).toarray()
        rhs = sub.derivative_map(1).toarray() @ basis.derivative_map(n).toarray()
        np.testing.assert_allclose(lhs, rhs, atol=1e-12 * max(1.0, float(np.abs(lhs).max())))


# ------------------------------------------------------------------ Gram matrices
def _gram_reference(k: int, M: int, n: int, nodes_per_span: int = 30) -> FloatArray:
    """∫_0^L N_i^(n) N_j^(n) ds by composite Gauss-Legendre on scipy basis elements."""
    L = M - k
    x, w = np.polynomial.legendre.leggauss(nodes_per_span)
    u, wu = 0.5 * (x + 1.0), 0.5 * w
    s = (np.arange(L)[:, None] + u[None, :]).ravel()
    weights = np.tile(wu, L)
    elements = BSpline(_ref_knots(k, M), np.eye(M), k)  # column i = N_i^k
    D = np.asarray(elements.derivative(n)(s) if n else elements(s), dtype=float)
    return np.asarray((D * weights[:, None]).T @ D)


@pytest.mark.parametrize(("k", "M"), CASES)
def test_gram_matches_quadrature(k: int, M: int) -> None:
    basis = ClampedUniformBasis(k, M)
    for n in range(k + 1):
        V = basis.gram(n).toarray()
        ref = _gram_reference(k, M, n)
        assert V.shape == (M, M)
        scale = float(np.abs(V).max())
        assert scale > 0
        np.testing.assert_allclose(V, ref, rtol=0, atol=1e-10 * scale, err_msg=f"order {n}")
        np.testing.assert_allclose(V, V.T, rtol=0, atol=1e-14 * scale)
        assert float(np.linalg.eigvalsh(V).min()) >= -1e-10 * scale


@pytest.mark.parametrize(("k", "M"), [(k, m) for k in DEGREES for m in (4 * k + 3, 6 * k + 7)])
def test_grams_of_a_large_basis_extended_from_the_reference_match_quadrature(
    k: int, M: int
) -> None:
    """Above reference_ctrl(k) control points the Gram matrices are extended from the
    reference basis's: the same as quadrature, and V_n = Γ_n' W_n Γ_n still holds."""
    basis = ClampedUniformBasis(k, M)
    for n in range(k + 1):
        V = basis.gram(n).toarray()
        scale = float(np.abs(V).max())
        np.testing.assert_allclose(V, _gram_reference(k, M, n), rtol=0, atol=1e-10 * scale)
        D = basis.derivative_map(n).toarray()
        W = basis.reduced_gram(n).toarray()
        np.testing.assert_allclose(D.T @ W @ D, V, rtol=0, atol=1e-10 * scale)


@pytest.mark.parametrize("k", DEGREES)
def test_gram_of_order_zero_sums_to_length(k: int) -> None:
    """Σ_ij V0_ij = ∫ (Σ_i N_i)^2 = L (partition of unity)."""
    M = k + 5
    assert float(ClampedUniformBasis(k, M).gram(0).sum()) == pytest.approx(M - k, rel=1e-13)


@pytest.mark.parametrize(("k", "M"), [(k, m) for k in DEGREES for m in (k + 1, k + 4, 14)])
def test_gram_null_space_is_low_degree_polynomials(k: int, M: int) -> None:
    """V_n c = 0 exactly for the n-dimensional space of polynomials of degree < n."""
    basis = ClampedUniformBasis(k, M)
    L = basis.n_spans
    # Control points reproducing s^j (fitted through the basis: polynomials of
    # degree <= k are in the spline space).
    s = np.linspace(0.0, L, 6 * (M + 1))
    N = BSpline(_ref_knots(k, M), np.eye(M), k)(s)
    for n in range(k + 1):
        V = basis.gram(n).toarray()
        scale = float(np.abs(V).max())
        ev = np.linalg.eigvalsh(V)
        assert int(np.sum(np.abs(ev) <= 1e-11 * scale)) == n, f"order {n}: {ev[: n + 1]}"
        for j in range(n):
            c, *_ = np.linalg.lstsq(N, (s / L) ** j, rcond=None)
            np.testing.assert_allclose(V @ c, 0.0, atol=1e-11 * scale)


# ------------------------------------------------------------------ hulls
def _unit_directions(d: int, count: int, seed: int) -> FloatArray:
    w = np.random.default_rng(seed).normal(size=(count, d))
    return np.asarray(w / np.linalg.norm(w, axis=1, keepdims=True))


HULL_CASES = [(k, m) for k in DEGREES for m in (k + 1, k + 5)]


def _window_samples(s: FloatArray, top_order: bool, inner_end: bool) -> FloatArray:
    """Samples of the window ``[a, b + 1]``, but ``[a, b + 1)`` for the k-th derivative.

    The k-th derivative is piecewise constant and right-continuous: at the knot
    ``b + 1`` it already takes the value of span ``b + 1``, outside the window.
    """
    return s[:-1] if top_order and inner_end else s


@pytest.mark.parametrize("kind", ["bspline", "bezier"])
@pytest.mark.parametrize(("k", "M"), HULL_CASES)
def test_hull_contains_derivative_on_spans(k: int, M: int, kind: str) -> None:
    basis = ClampedUniformBasis(k, M)
    L = basis.n_spans
    C = _random_ctrl(M, 3, seed=100 + 10 * k + M)
    W = _unit_directions(3, 200, seed=k)
    windows = {(0, L - 1), (L // 2, L // 2), (max(0, L - 3), L - 1), (0, min(1, L - 1))}
    for a, b in sorted(windows):
        s = np.linspace(a, b + 1.0, 60 * (b - a + 1) + 1)
        for n in range(k + 1):
            H = basis.hull_map(n, a, b, kind=kind) @ C  # type: ignore[arg-type]
            X = _scipy_derivative(k, M, C, n, _window_samples(s, n == k, b + 1 < L))
            tol = 1e-12 * max(1.0, float(np.abs(H).max()))
            support_curve = (X @ W.T).max(axis=0)
            support_hull = (H @ W.T).max(axis=0)
            assert np.all(support_curve <= support_hull + tol), (kind, a, b, n)


@pytest.mark.parametrize(("k", "M"), HULL_CASES)
def test_bspline_hull_rows_are_active_derivative_points(k: int, M: int) -> None:
    basis = ClampedUniformBasis(k, M)
    L = basis.n_spans
    for n in range(k + 1):
        full = basis.derivative_map(n).toarray()
        np.testing.assert_array_equal(basis.hull_map(n).toarray(), full)
        for a in range(L):
            for b in range(a, L):
                got = basis.hull_map(n, a, b).toarray()
                # Span j of the degree-(k-n) derivative spline involves points j..j+k-n.
                np.testing.assert_array_equal(got, full[a : b + k - n + 1])


@pytest.mark.parametrize(("k", "M"), HULL_CASES)
def test_bezier_points_are_convex_combinations_of_bspline_points(k: int, M: int) -> None:
    basis = ClampedUniformBasis(k, M)
    L = basis.n_spans
    C = _random_ctrl(M, 3, seed=200 + 10 * k + M)
    for n in range(k + 1):
        p = k - n
        bez = basis.hull_map(n, kind="bezier").toarray()
        assert bez.shape == (L * (p + 1), M)
        for j in range(L):
            span_bez = bez[j * (p + 1) : (j + 1) * (p + 1)]
            span_bsp = basis.hull_map(n, j, j).toarray()
            assert span_bsp.shape == (p + 1, M)
            # As maps: span_bez = Λ span_bsp with Λ row-stochastic and >= 0.
            lam = span_bez @ np.linalg.pinv(span_bsp)
            scale = max(1.0, float(np.abs(span_bsp).max()))
            np.testing.assert_allclose(lam @ span_bsp, span_bez, atol=1e-10 * scale)
            assert lam.min() >= -1e-10
            np.testing.assert_allclose(lam.sum(axis=1), 1.0, atol=1e-10)
            # And for one random C, by non-negative least squares with a sum row.
            P, Q = span_bsp @ C, span_bez @ C
            A = np.vstack([P.T, np.ones(p + 1)])
            for q in Q:
                _, residual = nnls(A, np.append(q, 1.0))
                assert residual <= 1e-9 * scale


@pytest.mark.parametrize(("k", "M"), HULL_CASES)
def test_bezier_end_points_are_curve_values(k: int, M: int) -> None:
    basis = ClampedUniformBasis(k, M)
    L = basis.n_spans
    C = _random_ctrl(M, 2, seed=300 + 10 * k + M)
    for n in range(k):  # order k is piecewise constant, checked below
        p = k - n
        Q = basis.hull_map(n, kind="bezier") @ C
        starts = _scipy_derivative(k, M, C, n, np.arange(L, dtype=float))
        ends = _scipy_derivative(k, M, C, n, np.arange(1, L + 1, dtype=float))
        scale = max(1.0, float(np.abs(Q).max()))
        np.testing.assert_allclose(Q[:: p + 1], starts, atol=1e-11 * scale)
        np.testing.assert_allclose(Q[p :: p + 1], ends, atol=1e-11 * scale)


@pytest.mark.parametrize(("k", "M"), HULL_CASES)
def test_bezier_hull_of_top_order_is_span_values(k: int, M: int) -> None:
    basis = ClampedUniformBasis(k, M)
    L = basis.n_spans
    C = _random_ctrl(M, 3, seed=400 + k + M)
    Q = basis.hull_map(k, kind="bezier") @ C
    want = _scipy_derivative(k, M, C, k, np.arange(L) + 0.5)
    assert Q.shape == (L, 3)
    np.testing.assert_allclose(Q, want, atol=1e-11 * max(1.0, float(np.abs(want).max())))


@pytest.mark.parametrize(("k", "M"), HULL_CASES)
def test_bezier_points_reproduce_each_span(k: int, M: int) -> None:
    """The Bézier points of span j, in the Bernstein basis, are the curve on that span."""
    basis = ClampedUniformBasis(k, M)
    L = basis.n_spans
    C = _random_ctrl(M, 2, seed=500 + k + M)
    u = np.linspace(0.0, 1.0, 9)
    for n in range(k + 1):
        p = k - n
        Q = basis.hull_map(n, kind="bezier") @ C
        bern = np.array(
            [[math.comb(p, i) * x**i * (1 - x) ** (p - i) for i in range(p + 1)] for x in u]
        )
        for j in range(L):
            got = bern @ Q[j * (p + 1) : (j + 1) * (p + 1)]
            # Order k is constant on a span (and jumps at knots): evaluate inside.
            s = j + u if n < k else np.full(u.size, j + 0.5)
            want = _scipy_derivative(k, M, C, n, s)
            scale = max(1.0, float(np.abs(Q).max()))
            np.testing.assert_allclose(got, want, atol=1e-10 * scale)


# ------------------------------------------------------------------ spans_in_window
@pytest.mark.parametrize(
    ("s_start", "s_end", "want"),
    [
        (0.0, 5.0, (0, 4)),  # the whole parameter range: ends at L
        (2.0, 3.0, (2, 2)),  # both ends on knots: the window ending on knot 3 stays in span 2
        (2.0, 4.0, (2, 3)),
        (1.25, 1.75, (1, 1)),  # inside one span
        (1.25, 2.0, (1, 1)),
        (1.25, 2.0001, (1, 2)),
        (0.999, 1.001, (0, 1)),
        (4.5, 5.0, (4, 4)),  # end at L
        (5.0, 5.0, (4, 4)),  # a point at the right end belongs to the last span
        (3.0, 3.0, (3, 3)),  # empty window on a knot
        (0.0, 0.0, (0, 0)),
    ],
)
def test_spans_in_window(s_start: float, s_end: float, want: tuple[int, int]) -> None:
    basis = ClampedUniformBasis(3, 8)  # L = 5
    assert basis.spans_in_window(s_start, s_end) == want


def test_spans_in_window_rejects_window_outside_range() -> None:
    basis = ClampedUniformBasis(3, 8)
    with pytest.raises(InputError, match="s_start"):
        basis.spans_in_window(-0.5, 1.0)


# ------------------------------------------------------------------ input errors
@pytest.mark.parametrize("degree", [0, 8, -1])
def test_bad_degree(degree: int) -> None:
    with pytest.raises(InputError, match=rf"degree: got {degree}, expected an integer from 1 to 7"):
        ClampedUniformBasis(degree, 10)


def test_non_integer_degree() -> None:
    with pytest.raises(InputError, match=r"degree: got 3\.0, expected an integer"):
        ClampedUniformBasis(3.0, 10)  # type: ignore[arg-type]


@pytest.mark.parametrize(("k", "M"), [(3, 3), (1, 1), (7, 7), (2, 0)])
def test_too_few_control_points(k: int, M: int) -> None:
    with pytest.raises(
        InputError, match=rf"n_ctrl: got {M}, expected an integer .*degree \+ 1 = {k + 1}"
    ):
        ClampedUniformBasis(k, M)


@pytest.mark.parametrize("order", [-1, 4, 10])
@pytest.mark.parametrize("method", ["design_matrix", "derivative_map", "gram", "hull_map"])
def test_order_out_of_range(order: int, method: str) -> None:
    basis = ClampedUniformBasis(3, 6)
    pattern = rf"order: got {order}, expected an integer from 0 to the degree 3"
    with pytest.raises(InputError, match=pattern):
        if method == "design_matrix":
            basis.design_matrix(np.array([0.5]), order)
        else:
            getattr(basis, method)(order)


@pytest.mark.parametrize("bad", [[-0.1, 1.0], [0.0, 3.0 + 1e-9], [5.0]])
def test_s_out_of_range(bad: list[float]) -> None:
    basis = ClampedUniformBasis(3, 6)  # L = 3
    with pytest.raises(InputError, match=r"s: got values in \[.*\], expected within \[0, 3\]"):
        basis.design_matrix(np.array(bad))


@pytest.mark.parametrize("bad", [[0.5, np.nan], [np.inf], [[0.5]]])
def test_s_non_finite_or_wrong_rank(bad: list[float]) -> None:
    basis = ClampedUniformBasis(3, 6)
    with pytest.raises(InputError, match=r"s: got shape .* expected a finite 1-D array"):
        basis.design_matrix(np.array(bad))


def test_design_matrix_accepts_both_ends() -> None:
    basis = ClampedUniformBasis(3, 6)
    for n in range(4):
        assert basis.design_matrix(np.array([0.0, 3.0]), n).shape == (2, 6)


def test_design_matrix_accepts_empty() -> None:
    assert ClampedUniformBasis(3, 6).design_matrix(np.array([])).shape == (0, 6)


@pytest.mark.parametrize(("first", "last"), [(-1, 1), (2, 1), (0, 3), (3, 3)])
def test_hull_span_range_errors(first: int, last: int) -> None:
    basis = ClampedUniformBasis(3, 6)  # spans 0..2
    with pytest.raises(InputError, match=r"span range: got \[.*\], expected 0 <= first <= last"):
        basis.hull_map(1, first, last)


def test_hull_kind_error() -> None:
    with pytest.raises(InputError, match=r"kind: got 'polygon', expected 'bspline' or 'bezier'"):
        ClampedUniformBasis(3, 6).hull_map(1, kind="polygon")  # type: ignore[arg-type]


# ------------------------------------------------------------------ property test
@settings(max_examples=40, deadline=None)
@given(
    k=st.integers(1, 7),
    extra=st.integers(0, 6),
    seed=st.integers(0, 2**32 - 1),
    data=st.data(),
)
def test_convex_hull_property_per_axis(k: int, extra: int, seed: int, data: st.DataObject) -> None:
    """Paper 003 eqs. (29)-(31): the n-th derivative stays within its hull points' box."""
    M = k + 1 + extra
    n = data.draw(st.integers(0, k), label="order")
    basis = basis_for(k, M)
    L = basis.n_spans
    rng = np.random.default_rng(seed)
    C = rng.uniform(-3.0, 3.0, size=(M, 3)) * rng.uniform(0.1, 10.0, size=3)
    a = data.draw(st.integers(0, L - 1), label="first_span")
    b = data.draw(st.integers(a, L - 1), label="last_span")
    s = np.linspace(a, b + 1.0, 50 * (b - a + 1) + 1)
    curve = _scipy_derivative(k, M, C, n, _window_samples(s, n == k, b + 1 < L))
    for kind in ("bspline", "bezier"):
        hull = basis.hull_map(n, a, b, kind=kind) @ C  # type: ignore[arg-type]
        tol = 1e-12 * max(1.0, float(np.abs(hull).max()))
        assert np.all(curve <= hull.max(axis=0) + tol), kind
        assert np.all(curve >= hull.min(axis=0) - tol), kind
