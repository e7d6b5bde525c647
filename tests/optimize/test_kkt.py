"""The one KKT solver against dense references, on both factorisation paths."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from numpy.typing import NDArray

from skyquill.errors import SolverError
from skyquill.optimize.kkt import DENSE_KKT, SingularKKTError, solve_equality_qp

Array = NDArray[np.float64]


def banded_qp(n: int, m: int, seed: int, k: int = 0) -> tuple[Array, Array, Array, Array]:
    """A banded positive definite ``P`` with badly scaled entries, random rows ``A``."""
    rng = np.random.default_rng(seed)
    main = rng.uniform(1.0, 2.0, n) * 1e6
    P = np.diag(main) + np.diag(np.full(n - 1, -0.4e6), 1) + np.diag(np.full(n - 1, -0.4e6), -1)
    A = np.zeros((m, n))
    for i, col in enumerate(np.linspace(0, n - 4, m).astype(int)):
        A[i, col : col + 4] = rng.normal(size=4) * 10.0 ** rng.uniform(-2, 3)
    shape = (n, k) if k else (n,)
    b_shape = (m, k) if k else (m,)
    return P, A, rng.normal(size=shape), rng.normal(size=b_shape)


@pytest.mark.parametrize("n", [20, DENSE_KKT + 200])  # the dense and the sparse path
@pytest.mark.parametrize("k", [0, 3])
def test_matches_the_dense_kkt_solution(n: int, k: int) -> None:
    P, A, q, b = banded_qp(n, n // 5, seed=n + k, k=k)
    sol = solve_equality_qp(sp.csr_array(P), q, sp.csr_array(A), b)
    m = A.shape[0]
    K = np.block([[P, A.T], [A, np.zeros((m, m))]])
    ref = np.linalg.solve(K, np.concatenate([-q, b]))
    assert sol.x.shape == q.shape and sol.y.shape == b.shape
    np.testing.assert_allclose(sol.x, ref[:n], rtol=1e-9, atol=1e-12 * np.abs(ref[:n]).max())
    np.testing.assert_allclose(sol.y, ref[n:], rtol=1e-7, atol=1e-9 * np.abs(ref[n:]).max())
    # The sign convention of QPSolution: P x + q + A' y = 0.
    stationarity = P @ sol.x + q + A.T @ sol.y
    assert np.abs(stationarity).max() <= 1e-8 * np.abs(q).max() + 1e-8 * np.abs(P @ sol.x).max()


@pytest.mark.parametrize("n", [10, DENSE_KKT + 50])
def test_dependent_rows_raise(n: int) -> None:
    P, A, q, b = banded_qp(n, 3, seed=1)
    A = np.vstack([A, 2.0 * A[:1]])
    with pytest.raises(SingularKKTError):
        solve_equality_qp(sp.csr_array(P), q, sp.csr_array(A), np.append(b, 2.0 * b[0]))


def test_structurally_singular_sparse_matrix_raises_instead_of_crashing() -> None:
    """An unknown that no cost and no row touches: a zero row and column in K, which
    SuperLU (scipy 1.17) can crash on; the structural-rank guard sees it first."""
    n = DENSE_KKT + 50
    P, A, q, b = banded_qp(n, 5, seed=2)
    P[:, 7] = P[7, :] = 0.0
    A[:, 7] = 0.0
    with pytest.raises(SingularKKTError, match="structurally singular"):
        solve_equality_qp(sp.csr_array(P), q, sp.csr_array(A), b)


def test_more_rows_than_unknowns_raise() -> None:
    with pytest.raises(SingularKKTError, match="4 equality rows for 3 unknowns"):
        solve_equality_qp(
            sp.csr_array(np.eye(3)), np.zeros(3), sp.csr_array(np.ones((4, 3))), np.ones(4)
        )


def test_is_a_solver_error() -> None:
    assert issubclass(SingularKKTError, SolverError)
