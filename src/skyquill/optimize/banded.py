"""The closed form of a separable smoothing problem by banded Cholesky (paper 003 eqs. 44-54).

When every cost term acts on each axis alone (the smoothness Gram matrices,
point deviations -- with or without an acceleration gain) and the only
equalities are a few boundary rows, the closed form's KKT system
``[[2 G, E'], [E, 0]] [C; Y] = [-F; e]`` (:mod:`skyquill.optimize.kkt`) has a
structure that needs neither the system nor a sparse factorisation:

* the Hessian ``G`` of each group of axes that share their gains is an
  ``(M, M)`` band of half-width ``k`` (the degree): every point touches
  ``k + 1`` consecutive control points. It is summed straight into LAPACK's
  band storage from the local basis rows at the points
  (:meth:`~skyquill.optimize.assemble.AssemblyCache.local_basis`), the
  smoothness band added once per basis;
* ``G = U'U`` by LAPACK's banded Cholesky (``pbtrf``), ``O(M k^2)``;
* the ``m`` equality rows are eliminated through their Schur complement
  ``S = E (2G)^-1 E'`` (``m x m``, ``m = 6`` for rest-to-rest): ``Y = S^-1
  (-e - E (2G)^-1 F)``, ``C = -(2G)^-1 (F + E'Y)``, with one banded solve for
  ``F`` and ``E'`` together.

The multipliers are those of :func:`~skyquill.optimize.solve._closed_form`
(row ``i`` of ``E`` on axis ``j`` is entry ``i d + j``). A problem of another
form, or whose Hessian is not safely positive definite (a control point no
term reaches, :data:`MIN_PIVOT_RATIO`), is left to the KKT route
(``None``): nothing here changes what is solved, only how
(``tests/optimize/test_banded.py`` compares both).

For a writing route (700 knot spans, 5,000 samples) this is ~1 ms where
assembling the sparse matrices and factoring the KKT system took ~30 ms.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import scipy.linalg
import scipy.sparse as sp
from numpy.typing import NDArray

from skyquill.optimize.assemble import AssemblyCache, _Fixed, point_model
from skyquill.optimize.problem import PointDeviation, SmoothingProblem
from skyquill.spline.local import LocalBasis, rows_times
from skyquill.validation import FloatArray

#: Above this many equality rows the Schur complement is not "a few" (interpolated
#: points belong to the KKT route).
MAX_EQUALITY_ROWS = 64
#: Smallest ratio of the Cholesky factor's squared pivots (~ 1 / the condition
#: number) accepted. A Hessian that is singular but for the equalities (a
#: smoothness cost alone, the boundary fixing its null space) factors with
#: pivots ~1e-16 of the largest, or not at all, and its Schur complement is
#: meaningless: the KKT route solves it. Writing routes measure ~7e-8
#: (condition ~3e8, 濑 and 中 at 0.05 s knots).
MIN_PIVOT_RATIO = 1e-12


@dataclass(frozen=True)
class BandedSolution:
    """The closed form and the blocks it met the equalities of.

    Attributes
    ----------
    C
        Control points, shape (M, d).
    y
        Equality multipliers, shape (m_eq d,), in :attr:`FitResult.y`'s order.
    fixed
        The problem's time-independent blocks (equality, inequality and cone
        rows), for the caller's checks of the limits.
    deviation
        The point deviations' cost at ``C``, ``sum_n w_n ||R_n C - p_n||^2``, from
        the rows the solve summed (what :func:`~skyquill.optimize.assemble.problem_cost`
        gives up to rounding, without evaluating the curve again).
    """

    C: FloatArray
    y: FloatArray
    fixed: _Fixed
    deviation: float


def banded_closed_form(
    problem: SmoothingProblem, cache: AssemblyCache | None = None
) -> BandedSolution | None:
    """Minimise ``problem``'s cost subject to its equalities (module docstring); ``None``
    when it is not of the banded form or its Hessian is not positive definite.

    ``cache`` re-uses the time-independent blocks and the local basis rows.
    """
    if problem.interpolation or not all(isinstance(t, PointDeviation) for t in problem.deviations):
        return None
    cache = cache if cache is not None else AssemblyCache()
    fixed = cache.fixed(problem)
    if fixed.E.shape[0] > MAX_EQUALITY_ROWS:
        return None
    smooth = cache.band(fixed.smooth, problem.degree, _band)
    M, d = problem.n_ctrl, problem.dim
    terms = [t for t in problem.deviations if isinstance(t, PointDeviation) and t.weight > 0]
    if not terms:
        return None  # a smoothness cost alone is singular but for the equalities
    locals_ = cache.local_bases(problem, [t.times for t in terms])
    F = np.zeros((M, d))
    C = np.zeros((M, d))
    Y = np.zeros((fixed.E.shape[0], d))
    E = cache.kept("dense equality rows", (fixed,), (), fixed.E.toarray)  # per route, not solve
    first = np.concatenate([local.first for local in locals_])
    points = np.concatenate([t.points for t in terms])
    weights = np.concatenate([np.full(t.times.size, t.weight) for t in terms])
    deviation = 0.0
    for axes in _axis_groups(terms, d):
        # Every term's rows at once (N, k + 1): one sum for the band, one per axis for F.
        rows = np.concatenate(
            [_rows(problem, t, local, axes[0]) for t, local in zip(terms, locals_, strict=True)]
        )
        F[:, axes] = -2.0 * _transpose_times(first, rows * weights[:, None], points[:, axes], M)
        # The factor depends on the rows and weights, not on the points: the same for
        # every solve at these times (a writing plan's polish passes change the points).
        gains = tuple(_gain(t, axes[0]) for t in terms)
        hessian = _Hessian(smooth, first, rows, weights, E)
        factored = cache.kept(
            "banded factor",
            (fixed, smooth, *locals_),
            (problem.alpha, tuple(t.weight for t in terms), gains),
            hessian.factored,
        )
        if factored is None:
            return None  # not (safely) positive definite: the KKT route decides
        solved = _solve(factored, F[:, axes], E, fixed.e[:, axes])
        if solved is None:
            return None
        C[:, axes], Y[:, axes] = solved
        deviation += _deviation(first, rows, weights, points[:, axes], C[:, axes])
    if not np.all(np.isfinite(C)):
        return None
    return BandedSolution(C, Y.ravel(), fixed, deviation)


def stationarity_residual(
    problem: SmoothingProblem, C: FloatArray, y: FloatArray, cache: AssemblyCache | None = None
) -> float | None:
    """``|2 G C + F + E'Y| / max(|2 G C|, |F|)`` of a banded problem's closed form; ``None``
    for a problem of another form.

    The closed form's own check (the KKT route measures the same on its
    assembled matrices, :func:`skyquill.optimize.resegment.multipliers.multipliers`),
    without assembling them: ``2 G C + F = 2 S C + 2 sum_n w_n R_n' (R_n C - p_n)``
    with ``S`` the smoothness block and ``R_n`` each point's row (with its gain).
    """
    if problem.interpolation or not all(isinstance(t, PointDeviation) for t in problem.deviations):
        return None
    cache = cache if cache is not None else AssemblyCache()
    fixed = cache.fixed(problem)
    M, d = C.shape
    quad = 2.0 * (fixed.smooth @ C)
    linear = np.zeros((M, d))
    for term in problem.deviations:
        assert isinstance(term, PointDeviation)
        if term.weight <= 0:
            continue
        local = cache.local_basis(problem, term.times)
        model = point_model(problem, term, C, cache)
        for mask, _ in term.axis_groups():
            axes = np.flatnonzero(mask)
            rows = _rows(problem, term, local, int(axes[0]))
            both = np.hstack([model[:, axes], term.points[:, axes]])
            pull = 2.0 * term.weight * _transpose_times(local.first, rows, both, M)
            quad[:, axes] += pull[:, : axes.size]
            linear[:, axes] -= pull[:, axes.size :]
    Y = y.reshape(-1, d)
    stationarity = quad + linear + np.asarray(Y.T @ fixed.E).T
    size = max(float(np.linalg.norm(quad)), float(np.linalg.norm(linear)), 1e-300)
    return float(np.linalg.norm(stationarity)) / size


@dataclass(frozen=True)
class _Factored:
    """A Hessian's banded Cholesky factor ``G = U'U`` (upper band storage) and the
    equalities' parts that depend only on it: ``W_E = (2G)^-1 E'`` (M, m) and the
    Schur complement ``S = E W_E`` (m, m)."""

    factor: FloatArray
    W_E: FloatArray
    S: FloatArray


@dataclass(frozen=True)
class _Hessian:
    """What a group of axes' Hessian band is summed from (:func:`_gram_band`)."""

    smooth: FloatArray
    first: NDArray[np.intp]
    rows: FloatArray
    weights: FloatArray
    E: FloatArray

    def factored(self) -> _Factored | None:
        """:func:`_factor` of the smoothness band plus the points' rows."""
        M = self.smooth.shape[1]
        return _factor(self.smooth + _gram_band(self.first, self.rows, self.weights, M), self.E)


def _factor(band: FloatArray, E: FloatArray) -> _Factored | None:
    """:class:`_Factored` of the Hessian ``band``; ``None`` when it is not positive
    definite, or so nearly singular that only the equalities determine the point."""
    factor, info = scipy.linalg.lapack.dpbtrf(band, lower=0)
    if info != 0:
        return None
    pivots = factor[-1] ** 2
    if not pivots.min() >= MIN_PIVOT_RATIO * pivots.max():
        return None
    if E.shape[0] == 0:
        return _Factored(factor, np.zeros((band.shape[1], 0)), np.zeros((0, 0)))
    W, info = scipy.linalg.lapack.dpbtrs(factor, E.T, lower=0)
    if info != 0:
        return None
    W_E = 0.5 * W
    return _Factored(factor, W_E, E @ W_E)


def _solve(
    factored: _Factored, F: FloatArray, E: FloatArray, e: FloatArray
) -> tuple[FloatArray, FloatArray] | None:
    """``C`` (M, g) and ``Y`` (m, g) of ``min C'GC + F'C s.t. E C = e`` from ``G = U'U``."""
    W, info = scipy.linalg.lapack.dpbtrs(factored.factor, F, lower=0)
    if info != 0:
        return None
    W_F = 0.5 * W  # (2G)^-1 F
    if E.shape[0] == 0:
        return -W_F, np.zeros((0, F.shape[1]))
    try:
        Y = np.linalg.solve(factored.S, -e - E @ W_F)
    except np.linalg.LinAlgError:
        return None  # dependent equality rows: the KKT route drops them
    return -(W_F + factored.W_E @ Y), np.asarray(Y, dtype=float)


def _axis_groups(terms: list[PointDeviation], d: int) -> list[list[int]]:
    """The axes whose gains agree in every term: they share one Hessian."""
    groups: dict[tuple[float, ...], list[int]] = {}
    for axis in range(d):
        key = tuple(0.0 if t.accel_gain is None else float(t.accel_gain[axis]) for t in terms)
        groups.setdefault(key, []).append(axis)
    return list(groups.values())


def _gain(term: PointDeviation, axis: int) -> float:
    """The term's acceleration gain on ``axis`` (0 without one), s^2."""
    return 0.0 if term.accel_gain is None else float(term.accel_gain[axis])


def _rows(
    problem: SmoothingProblem, term: PointDeviation, local: LocalBasis, axis: int
) -> FloatArray:
    """The term's nonzero row entries on ``axis`` (N, k + 1): ``B + c alpha^2 B''``."""
    gain = _gain(term, axis)
    if gain == 0.0:
        return np.asarray(local.values[0])
    return np.asarray(local.values[0] + gain * problem.alpha**2 * local.values[2])


def _gram_band(
    first: NDArray[np.intp], rows: FloatArray, weights: FloatArray, M: int
) -> FloatArray:
    """``sum_n w_n R_n' R_n`` in upper band storage (k + 1, M) for the rows ``R`` (N, k + 1)
    at columns ``first`` (N,): entry ``(i, j)``, ``j >= i``, is ``band[k + i - j, j]``."""
    k = rows.shape[1] - 1
    a, b = _pairs(k)
    products = weights[:, None] * rows[:, a] * rows[:, b]
    # Each pair's flat offset computed once (k + 1 choose 2 entries), then one add per row.
    where = first[:, None] + ((k + a - b) * M + b)
    sums = np.bincount(where.ravel(), weights=products.ravel(), minlength=(k + 1) * M)
    return np.asarray(sums.reshape(k + 1, M))


@lru_cache(maxsize=8)
def _pairs(k: int) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """The index pairs ``a <= b`` of a (k + 1)-square's upper triangle."""
    a, b = np.triu_indices(k + 1)
    return a, b


def _deviation(
    first: NDArray[np.intp],
    rows: FloatArray,
    weights: FloatArray,
    points: FloatArray,
    C: FloatArray,
) -> float:
    """``sum_n w_n ||R_n C - p_n||^2`` for the rows ``R`` (N, k + 1) at ``first``, the
    points ``P`` (N, g) and the control points ``C`` (M, g)."""
    residual = rows_times(first, rows, C) - points
    return float(weights @ np.sum(residual**2, axis=1))


def _transpose_times(
    first: NDArray[np.intp], rows: FloatArray, points: FloatArray, M: int
) -> FloatArray:
    """``R' P`` (M, g) for the rows ``R`` (N, k + 1) at ``first`` and points ``P`` (N, g)."""
    columns = (first[:, None] + np.arange(rows.shape[1])).ravel()
    return np.column_stack(
        [np.bincount(columns, weights=(rows * p[:, None]).ravel(), minlength=M) for p in points.T]
    )


def _band(matrix: sp.csr_array, k: int) -> FloatArray:
    """The upper band (k + 1, M) of a symmetric matrix of half-bandwidth ``k``."""
    M = matrix.shape[0]
    band = np.zeros((k + 1, M))
    for q in range(k + 1):
        band[k - q, q:] = matrix.diagonal(q)
    return band


__all__ = ["MAX_EQUALITY_ROWS", "BandedSolution", "banded_closed_form", "stationarity_residual"]
