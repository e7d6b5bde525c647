"""Clamped uniform B-spline basis in the path parameter ``s`` (paper 003 §2).

Everything here works in the *normalised* parameter ``s`` in ``[0, L]`` where
``L = M - k`` is the number of knot spans; the linear time scale
``s = alpha * t`` (paper 003 eq. 5) is applied by the caller, which multiplies
an ``n``-th derivative map by ``alpha**n`` and a Gram matrix of order ``n`` by
``alpha**(2n - 1)``.

Every map returned is a sparse matrix acting on the control points of one
axis, shape ``(rows, M)``; the axis-coupled problem uses their Kronecker
product with ``I_d`` (paper 003 eq. 9). The rows at sample parameters come
from the span polynomials of :mod:`skyquill.spline.local`; the Gram matrices
from :meth:`scipy.interpolate.BSpline.design_matrix` at Gauss nodes.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property, lru_cache
from typing import Literal

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.interpolate import BSpline

from skyquill.errors import InputError
from skyquill.spline.local import LocalBasis, uniform_local_basis

FloatArray = NDArray[np.float64]
HullKind = Literal["bspline", "bezier"]

MAX_DEGREE = 7
#: Far beyond any drawing (1e5 samples fit with 1e4 spans); guards memory.
MAX_CTRL = 2_000_000


def clamped_uniform_knots(degree: int, n_ctrl: int) -> FloatArray:
    """Knot vector of paper 003 eq. (4).

    ``[0]*(k+1), 1, 2, ..., L-1, [L]*(k+1)`` with ``L = M - k`` spans.

    Parameters
    ----------
    degree
        Spline degree ``k`` (the paper's "order").
    n_ctrl
        Number of control points ``M``; at least ``k + 1``.

    Returns
    -------
    numpy.ndarray, shape (M + k + 1,)
    """
    n_spans = n_ctrl - degree
    return np.concatenate(
        [np.zeros(degree), np.arange(n_spans + 1, dtype=float), np.full(degree, float(n_spans))]
    )


def _bernstein_matrix(degree: int, u: FloatArray) -> FloatArray:
    """Bernstein basis of ``degree`` at parameters ``u`` in [0, 1]; shape (len(u), degree + 1)."""
    from math import comb

    i = np.arange(degree + 1)
    binom = np.array([comb(degree, j) for j in i], dtype=float)
    return binom * u[:, None] ** i * (1.0 - u[:, None]) ** (degree - i)


@dataclass(frozen=True)
class ClampedUniformBasis:
    """Clamped uniform B-spline basis of degree ``k`` with ``M`` control points.

    Parameters
    ----------
    degree
        Degree ``k``, 1 to 7.
    n_ctrl
        Number of control points ``M >= k + 1``.
    """

    degree: int
    n_ctrl: int

    def __post_init__(self) -> None:
        if not isinstance(self.degree, int | np.integer) or not 1 <= self.degree <= MAX_DEGREE:
            raise InputError(
                f"degree: got {self.degree!r}, expected an integer from 1 to {MAX_DEGREE}"
            )
        if not isinstance(self.n_ctrl, int | np.integer) or not (
            self.degree + 1 <= self.n_ctrl <= MAX_CTRL
        ):
            raise InputError(
                f"n_ctrl: got {self.n_ctrl!r}, expected an integer from degree + 1 = "
                f"{self.degree + 1} to {MAX_CTRL}"
            )

    @property
    def n_spans(self) -> int:
        """Number of knot spans ``L = M - k``; the parameter runs over ``[0, L]``."""
        return self.n_ctrl - self.degree

    @cached_property
    def knots(self) -> FloatArray:
        """Knot vector, shape (M + k + 1,)."""
        return clamped_uniform_knots(self.degree, self.n_ctrl)

    def reduced(self, order: int) -> ClampedUniformBasis | None:
        """Basis of the ``order``-th derivative spline (degree ``k - order``, ``M - order`` points).

        Returns ``None`` for ``order == k`` (degree 0 is handled by the callers
        directly, since this class requires degree >= 1).
        """
        if order == self.degree:
            return None
        return ClampedUniformBasis(self.degree - order, self.n_ctrl - order)

    def _check_order(self, order: int) -> None:
        if not isinstance(order, int | np.integer) or not 0 <= order <= self.degree:
            raise InputError(
                f"order: got {order!r}, expected an integer from 0 to the degree {self.degree}"
            )

    def design_matrix(self, s: FloatArray, order: int = 0) -> sp.csr_array:
        """Rows of basis-function derivatives at parameters ``s``.

        Parameters
        ----------
        s
            Parameters, shape (N,), each in ``[0, L]``.
        order
            Derivative order with respect to ``s``, 0 to ``k``.

        Returns
        -------
        scipy.sparse.csr_array, shape (N, M)
            ``row @ C`` is the ``order``-th ``s``-derivative of the spline at ``s``.
        """
        self._check_order(order)
        s = np.asarray(s, dtype=float)
        if s.ndim != 1 or not np.all(np.isfinite(s)):
            raise InputError(
                f"s: got shape {s.shape} with non-finite values or wrong rank, "
                "expected a finite 1-D array"
            )
        if s.size and (s.min() < 0.0 or s.max() > self.n_spans):
            raise InputError(
                f"s: got values in [{s.min():g}, {s.max():g}], expected within [0, {self.n_spans}]"
            )
        if s.size == 0:
            return sp.csr_array((0, self.n_ctrl))
        local = self.local_values(s, order)
        return self.rows(local.first, local.values[order])

    def local_values(self, s: FloatArray, max_order: int) -> LocalBasis:
        """The ``k + 1`` nonzero basis functions and their ``s``-derivatives up to
        ``max_order`` at parameters ``s`` (N,) in ``[0, L]`` (validated by the caller):
        first columns (N,) and values (max_order + 1, N, k + 1)
        (:func:`skyquill.spline.local.uniform_local_basis`)."""
        return uniform_local_basis(self.degree, self.n_spans, np.asarray(s, dtype=float), max_order)

    def rows(self, first: NDArray[np.intp], values: FloatArray) -> sp.csr_array:
        """Sparse rows (N, M) whose nonzeros are ``values`` (N, k + 1) from columns ``first``."""
        n, width = values.shape
        indices = (first[:, None] + np.arange(width)).ravel()
        indptr = np.arange(0, n * width + 1, width)
        return sp.csr_array((values.ravel(), indices, indptr), shape=(n, self.n_ctrl))

    def _derivative_basis(self, s: FloatArray, order: int) -> sp.csr_array:
        """Basis of the ``order``-th derivative spline (degree k - n, knots eq. 35) at ``s``."""
        p = self.degree - order
        if p == 0:
            # Piecewise-constant basis: column = span index (right end -> last span).
            cols = np.minimum(np.floor(s).astype(int), self.n_spans - 1)
            return sp.csr_array(
                (np.ones(s.size), (np.arange(s.size), cols)), shape=(s.size, self.n_ctrl - order)
            )
        knots = self.knots[order : len(self.knots) - order]
        return sp.csr_array(BSpline.design_matrix(s, knots, p))

    def derivative_map(self, order: int) -> sp.csr_array:
        """Map Γ_n from control points to those of the ``order``-th ``s``-derivative.

        Paper 003 eqs. (34)-(37) with ``alpha = 1``: applying eq. (34)
        ``order`` times. The derivative spline has degree ``k - order`` and the
        knot vector of eq. (35).

        Returns
        -------
        scipy.sparse.csr_array, shape (M - order, M)
        """
        self._check_order(order)
        if order not in self._derivative_maps:
            band = self._derivative_bands[order]
            rows, width = band.shape
            indices = (np.arange(rows)[:, None] + np.arange(width)).ravel()
            indptr = np.arange(0, rows * width + 1, width)
            matrix = sp.csr_array((band.ravel(), indices, indptr), shape=(rows, self.n_ctrl))
            self._derivative_maps[order] = matrix
        return self._derivative_maps[order]

    @cached_property
    def _derivative_maps(self) -> dict[int, sp.csr_array]:
        return {}

    @cached_property
    def _derivative_bands(self) -> tuple[FloatArray, ...]:
        """Γ_n as bands (M - n, n + 1): ``band[i, o] = Γ_n[i, i + o]``, n = 0 .. k.

        Eq. (34) row by row: Γ_n = S_n Γ_(n-1) with the bidiagonal ``S_n`` (``-c_i`` at
        ``i``, ``c_i`` at ``i + 1``), so ``band_n[i, o] = -c_i band_(n-1)[i, o] +
        c_i band_(n-1)[i + 1, o - 1]``: the same products and sums as the sparse
        product, in O(M k) instead of five sparse products (3-4 ms at M = 700).
        """
        knots = self.knots
        bands = [np.ones((self.n_ctrl, 1))]
        for j in range(1, self.degree + 1):
            p = self.degree - j + 1  # degree before this differentiation
            m = self.n_ctrl - j + 1  # control points before it
            t = knots[j - 1 : len(knots) - j + 1]
            scale = (p / (t[p + 1 : p + m] - t[1:m]))[:, None]  # eq. (34)
            before = bands[-1]
            band = np.zeros((m - 1, j + 1))
            band[:, :j] = -scale * before[:-1]
            band[:, 1:] += scale * before[1:]
            bands.append(band)
        for band in bands:
            band.setflags(write=False)
        return tuple(bands)

    def end_rows(self, order: int) -> tuple[FloatArray, FloatArray]:
        """First and last rows of :meth:`derivative_map`, dense, each (M,): the
        ``order``-th ``s``-derivative at ``s = 0`` and ``s = L`` (paper 003 eq. 41). Cached.
        """
        self._check_order(order)
        return self._end_rows[order]

    @cached_property
    def _end_rows(self) -> tuple[tuple[FloatArray, FloatArray], ...]:
        rows = []
        for order, band in enumerate(self._derivative_bands):
            first, last = np.zeros(self.n_ctrl), np.zeros(self.n_ctrl)
            first[: order + 1] = band[0]
            last[self.n_ctrl - order - 1 :] = band[-1]
            first.setflags(write=False)
            last.setflags(write=False)
            rows.append((first, last))
        return tuple(rows)

    def gram(self, order: int) -> sp.csr_array:
        """Exact Gram matrix of the ``order``-th derivative (paper 003 eq. 10, ``alpha = 1``).

        ``V[i, j] = ∫_0^L N_i^(n)(s) N_j^(n)(s) ds``. The integrand is a
        polynomial of degree ``2(k - n)`` on each span, so Gauss-Legendre with
        ``k - n + 1`` nodes per span integrates it exactly (up to round-off).
        With at least :func:`reference_ctrl` control points it is the reference
        basis's, its interior row repeated (:func:`_extended_band`).

        Returns
        -------
        scipy.sparse.csr_array, shape (M, M), symmetric positive semi-definite.
        """
        self._check_order(order)
        if order not in self._grams:  # built on first use: a problem needs one or two orders
            reference = reference_ctrl(self.degree)
            if self.n_ctrl > reference:
                small = basis_for(self.degree, reference).gram(order)
                self._grams[order] = _extended_band(small, self.n_ctrl, self.degree)
            else:
                D = self.derivative_map(order)
                self._grams[order] = sp.csr_array(D.T @ self.reduced_gram(order) @ D)
        return self._grams[order]

    @cached_property
    def _grams(self) -> dict[int, sp.csr_array]:
        return {}

    def reduced_gram(self, order: int) -> sp.csr_array:
        """Gram matrix ``W_n`` of the derivative spline's own basis, shape (M - n, M - n).

        ``V_n = Gamma_n' W_n Gamma_n``. ``W_n`` is positive definite, so a
        cost evaluated as ``D' W_n D`` on the derivative control points
        ``D = Gamma_n C`` does not suffer the cancellation of ``C' V_n C``
        (large ``C`` nearly in the polynomial null space of ``V_n``). Like
        :meth:`gram`, extended from the reference basis's when ``M`` is larger.
        """
        self._check_order(order)
        if order not in self._reduced_grams:
            reference = reference_ctrl(self.degree)
            if self.n_ctrl > reference:
                small = basis_for(self.degree, reference).reduced_gram(order)
                extended = _extended_band(small, self.n_ctrl - order, self.degree - order)
                self._reduced_grams[order] = extended
                return extended
            n_nodes = self.degree - order + 1
            nodes, weights = np.polynomial.legendre.leggauss(n_nodes)
            u = 0.5 * (nodes + 1.0)  # on [0, 1]
            spans = np.arange(self.n_spans)
            s = (spans[:, None] + u[None, :]).ravel()
            w = np.tile(0.5 * weights, self.n_spans)
            B = self._derivative_basis(s, order)
            self._reduced_grams[order] = sp.csr_array(B.T @ sp.diags_array(w) @ B)
        return self._reduced_grams[order]

    @cached_property
    def _reduced_grams(self) -> dict[int, sp.csr_array]:
        return {}

    def hull_map(
        self,
        order: int,
        first_span: int = 0,
        last_span: int | None = None,
        kind: HullKind = "bspline",
    ) -> sp.csr_array:
        """Points whose convex hull contains the ``order``-th derivative on spans.

        The curve ``d^n S / ds^n`` restricted to ``s`` in
        ``[first_span, last_span + 1]`` lies in the convex hull of the rows of
        ``hull_map(...) @ C``; this is what makes a linear inequality on these
        points hold on the whole interval (paper 003 eqs. 29-31, 39).

        Parameters
        ----------
        order
            Derivative order ``n``, 0 to ``k``.
        first_span, last_span
            Inclusive span range; defaults to all spans.
        kind
            ``"bspline"``: the control points of the derivative spline that
            are active on those spans (the papers' hull, eq. 39).
            ``"bezier"``: the Bézier control points of each span's polynomial
            piece. Each is a convex combination of the B-spline points active
            on its span, so the Bézier hull is contained in the B-spline hull
            and the constraint is never looser; it is exact at the span ends.

        Returns
        -------
        scipy.sparse.csr_array, shape (P, M)
        """
        self._check_order(order)
        last = self.n_spans - 1 if last_span is None else last_span
        if not 0 <= first_span <= last <= self.n_spans - 1:
            raise InputError(
                f"span range: got [{first_span}, {last}], expected 0 <= first <= last <= "
                f"{self.n_spans - 1}"
            )
        p = self.degree - order
        if kind == "bspline":
            # Derivative control points active on spans first..last (eq. 35 knots).
            rows = np.arange(first_span, min(last + p, self.n_ctrl - order - 1) + 1)
            D = self.derivative_map(order)
            if rows.size == D.shape[0]:  # all of them (a limit on the whole curve)
                return D.copy()
            return sp.csr_array(D[rows, :])
        if kind != "bezier":
            raise InputError(f"kind: got {kind!r}, expected 'bspline' or 'bezier'")
        # Sample each span's polynomial at p+1 interior points, then invert the
        # Bernstein matrix: exact Bézier points of a degree-p polynomial.
        u = (np.arange(p + 1) + 0.5) / (p + 1)
        to_bezier = np.linalg.inv(_bernstein_matrix(p, u))
        n_sel = last - first_span + 1
        s = (np.arange(first_span, last + 1)[:, None] + u[None, :]).ravel()
        values = self.design_matrix(s, order)
        blocks = sp.block_diag([to_bezier] * n_sel, format="csr")
        return sp.csr_array(blocks @ values)

    def spans_in_window(self, s_start: float, s_end: float) -> tuple[int, int]:
        """Inclusive range of spans that intersect ``[s_start, s_end)`` (paper 003 §3.4).

        The paper's ``eta(tau) = floor(alpha tau) + k`` indexes the knot; here
        the span index is ``floor(s)``. A window ending exactly on a knot does
        not reach into the next span.
        """
        if not (np.isfinite(s_start) and np.isfinite(s_end)) or not (
            0.0 <= s_start <= s_end <= self.n_spans
        ):
            raise InputError(
                f"window: got s_start={s_start:g}, s_end={s_end:g}, expected "
                f"0 <= s_start <= s_end <= {self.n_spans}"
            )
        first = min(int(np.floor(s_start)), self.n_spans - 1)
        last = max(first, min(int(np.ceil(s_end)) - 1, self.n_spans - 1))
        return first, last


@lru_cache(maxsize=32)
def uniform_design(degree: int, n_ctrl: int, order: int, n_samples: int) -> sp.csr_array:
    """Cached :meth:`ClampedUniformBasis.design_matrix` at ``n_samples`` uniform ``s`` in [0, L].

    The dense check samples every trajectory of a given basis at the same
    parameters; caching the sparse matrix turns each derivative into one
    sparse product.
    """
    basis = basis_for(degree, n_ctrl)
    basis._check_order(order)
    local = _uniform_local(degree, n_ctrl, n_samples, max(order, min(_DENSE_ORDERS, degree)))
    return basis.rows(local.first, local.values[order])


#: Derivatives the dense check asks for together (velocity, acceleration, jerk).
_DENSE_ORDERS = 3


@lru_cache(maxsize=4)
def _uniform_local(degree: int, n_ctrl: int, n_samples: int, max_order: int) -> LocalBasis:
    """The nonzero basis functions and their derivatives up to ``max_order`` at
    ``n_samples`` uniform ``s``.

    One evaluation for the orders of the dense check: it asks for velocity,
    acceleration and jerk of the same basis, and the span powers and classes are
    most of the cost.
    """
    basis = basis_for(degree, n_ctrl)
    return basis.local_values(np.linspace(0.0, basis.n_spans, n_samples), max_order)


@lru_cache(maxsize=64)
def basis_for(degree: int, n_ctrl: int) -> ClampedUniformBasis:
    """Shared, cached basis: its derivative maps and Gram matrices are built once."""
    return ClampedUniformBasis(degree, n_ctrl)


def reference_ctrl(degree: int) -> int:
    """Control points of the basis whose Gram matrices larger bases of ``degree`` extend.

    Basis functions ``k .. M - k - 1`` are translates of one another (their knots
    are uniform), so a Gram entry of two of them depends only on ``j - i``; the
    first and last ``k`` functions see the clamped ends. ``4 k + 2`` points hold
    both ends apart and one interior row between them (:func:`_extended_band`).
    """
    return 4 * degree + 2


def _extended_band(small: sp.csr_array, size: int, width: int) -> sp.csr_array:
    """A symmetric band matrix of ``size`` rows extended from ``small`` (m0, m0), m0 <= size.

    The entries within ``2 width`` rows of either end are ``small``'s at the same
    distance from that end; every row between repeats ``small``'s middle row, shifted
    (see :func:`reference_ctrl`: there both functions are translates). ``width``:
    the half-bandwidth, the degree of the basis the matrix is of.
    """
    m0 = small.shape[0]
    ref = small.toarray()
    offsets = np.arange(-width, width + 1)
    middle = m0 // 2
    rows = np.arange(size)
    band = np.tile(ref[middle, middle + offsets], (size, 1))
    edge = min(2 * width, size)
    cols = rows[:edge, None] + offsets
    inside = (cols >= 0) & (cols < m0)
    band[:edge][inside] = ref[np.nonzero(inside)[0], cols[inside]]
    far = rows[size - edge :, None] + (m0 - size)  # the same rows counted from the end
    far_cols = far + offsets
    inside = (far_cols >= 0) & (far_cols < m0)
    band[size - edge :][inside] = ref[far[np.nonzero(inside)[0], 0], far_cols[inside]]
    cols = rows[:, None] + offsets
    keep = (cols >= 0) & (cols < size)
    indptr = np.concatenate([[0], np.cumsum(keep.sum(axis=1))])
    return sp.csr_array((band[keep], cols[keep], indptr), shape=(size, size))
