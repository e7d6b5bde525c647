"""The one KKT solver: an equality-constrained quadratic by one LU factorisation.

``min 1/2 x'Px + q'x  s.t.  A x = b`` is solved through its KKT system

    [[P, A'], [A, 0]] [x; y] = [-q; b],   i.e.   P x + q + A' y = 0,

so ``y`` are the equality multipliers in the sign convention of
:class:`skyquill.solvers.QPSolution`. The closed form of
:func:`skyquill.optimize.solve` and the polish step of the re-segmentation
gradient both use it.

Both blocks are equilibrated first: the cost is divided by its largest
diagonal entry (with jerk or snap costs at fine knot spacing the raw entries
grow like ``alpha^5`` or ``alpha^7``) and every constraint row is scaled to
unit norm (limit rows carry ``alpha^n``). Neither changes ``x``; ``y`` is
scaled back.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import structural_rank

from skyquill.errors import SolverError
from skyquill.validation import FloatArray

#: Below this many unknowns LAPACK's dense LU is faster than building
#: SuperLU's structures (0.02 ms against 0.34 ms for 59 unknowns, ``make bench``).
DENSE_KKT = 300


class SingularKKTError(SolverError):
    """The KKT matrix is singular (no unique minimiser, or dependent rows).

    Callers catch it and say what the rows mean (a message of their own, or a
    fallback), since only they know.
    """


@dataclass(frozen=True)
class KKTSolution:
    """Minimiser and multipliers of an equality-constrained quadratic.

    Attributes
    ----------
    x
        Minimiser, shape (n,) or (n, k) for ``k`` right-hand sides.
    y
        Multipliers, shape (m,) or (m, k): ``P x + q + A' y = 0``.
    """

    x: FloatArray
    y: FloatArray


def solve_equality_qp(
    P: sp.csr_array, q: FloatArray, A: sp.csr_array, b: FloatArray
) -> KKTSolution:
    """Minimise ``1/2 x'Px + q'x`` subject to ``A x = b`` (module docstring).

    Parameters
    ----------
    P
        Symmetric, shape (n, n); positive definite on the null space of ``A``.
    q
        Shape (n,), or (n, k) to solve ``k`` problems with the same matrices
        at once (one factorisation).
    A
        Shape (m, n), ``m <= n``, rows linearly independent.
    b
        Shape (m,), or (m, k) with ``q``.

    Returns
    -------
    KKTSolution

    Raises
    ------
    SingularKKTError
        The KKT matrix is singular (numerically, or structurally, or more rows
        than unknowns), or the solution is not finite.
    """
    n, m = P.shape[0], A.shape[0]
    if m > n:
        raise SingularKKTError(f"{m} equality rows for {n} unknowns")
    diagonal = float(np.abs(P.diagonal()).max(initial=0.0))
    cost = 1.0 / diagonal if diagonal > 0.0 else 1.0
    K, norms = (_dense_kkt if n + m <= DENSE_KKT else _sparse_kkt)(P, A, cost)
    row_scale = norms[:, None] if b.ndim == 2 else norms
    sol = _lu_solve(K, np.concatenate([-cost * q, b / row_scale]))
    if not np.all(np.isfinite(sol)):
        raise SingularKKTError("the solution is not finite (ill-conditioned KKT matrix)")
    return KKTSolution(sol[:n], sol[n:] / (cost * row_scale))


def _dense_kkt(P: sp.csr_array, A: sp.csr_array, cost: float) -> tuple[FloatArray, FloatArray]:
    """Equilibrated ``[[cost P, (D A)'], [D A, 0]]`` as a dense array, and the row norms ``1/D``.

    Below ``DENSE_KKT`` unknowns the scaling is done on dense arrays: each
    sparse operation costs tens of microseconds, as much as the dense LU.
    """
    n, m = P.shape[0], A.shape[0]
    K = np.zeros((n + m, n + m))
    K[:n, :n] = cost * P.toarray()
    rows = A.toarray()
    norms = np.linalg.norm(rows, axis=1)
    norms[norms == 0.0] = 1.0
    K[n:, :n] = rows / norms[:, None]
    K[:n, n:] = K[n:, :n].T
    return K, norms


def _sparse_kkt(P: sp.csr_array, A: sp.csr_array, cost: float) -> tuple[sp.csc_array, FloatArray]:
    """The sparse twin of :func:`_dense_kkt` (CSC, for SuperLU)."""
    norms = np.sqrt(np.asarray(A.multiply(A).sum(axis=1)).ravel())
    norms[norms == 0.0] = 1.0
    A_s = sp.csr_array(sp.diags_array(1.0 / norms) @ A)
    K = sp.csc_array(sp.block_array([[cost * P, A_s.T], [A_s, None]], format="csc"))
    return K, norms


def _lu_solve(K: FloatArray | sp.csc_array, rhs: FloatArray) -> FloatArray:
    """Solve ``K u = rhs`` by LU: LAPACK for a dense ``K``, else SuperLU (COLAMD ordering).

    With the equilibration of :func:`solve_equality_qp` the relative residual
    is ~1e-15 even for snap at 100 spans/s, so no refinement step is needed.
    """
    try:
        if isinstance(K, np.ndarray):
            with warnings.catch_warnings():
                # LAPACK's condition estimate: treat "ill-conditioned" as singular.
                warnings.simplefilter("error", scipy.linalg.LinAlgWarning)
                return np.asarray(scipy.linalg.solve(K, rhs, check_finite=False))
        # SuperLU (scipy 1.17) segfaults on some structurally singular matrices
        # instead of raising (seen with a 0.01 m/s^3 jerk limit: rank 6660 of
        # 6704); a maximum matching finds them first (~1-2% of a solve()).
        if structural_rank(K) < K.shape[0]:
            raise SingularKKTError("the KKT matrix is structurally singular")
        return np.asarray(spla.splu(K).solve(rhs))
    except (RuntimeError, np.linalg.LinAlgError, scipy.linalg.LinAlgWarning) as exc:
        raise SingularKKTError(str(exc)) from exc


__all__ = ["DENSE_KKT", "KKTSolution", "SingularKKTError", "solve_equality_qp"]
