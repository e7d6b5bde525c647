"""Two-sided rows ``h_lower <= G x <= h`` on every backend, and PIQP's re-used setup."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from numpy.typing import NDArray

from skyquill.solvers import BACKENDS, PiqpSession, QuadraticProgram, solve_qp
from skyquill.solvers.base import fold_duals, one_sided

Array = NDArray[np.float64]
TOL = {"clarabel": 1e-8, "piqp": 1e-8, "osqp": 1e-6}


def band_projection(z: Array, lo: Array, hi: Array) -> QuadraticProgram:
    """``min 1/2 ||x - z||^2  s.t.  lo <= M x <= hi`` with ``M`` the first differences
    plus the identity (a coupled band, not a box on ``x``)."""
    n = z.size
    diff = np.eye(n, k=1)[: n - 1] - np.eye(n)[: n - 1]
    M = sp.csc_array(np.vstack([np.eye(n), diff]))
    return QuadraticProgram(
        P=sp.csc_array(sp.eye_array(n)),
        q=-z,
        A_eq=sp.csc_array((0, n)),
        b_eq=np.zeros(0),
        G=M,
        h=hi,
        h_lower=lo,
    )


def _case() -> QuadraticProgram:
    rng = np.random.default_rng(4)
    n = 6
    z = rng.normal(0.0, 2.0, n)
    m = 2 * n - 1
    lo = np.full(m, -1.0)
    lo[1] = -np.inf  # one row bounded above only
    return band_projection(z, lo, np.full(m, 1.0))


@pytest.mark.parametrize("backend", sorted(BACKENDS))
def test_two_sided_rows_match_the_one_sided_program(backend: str) -> None:
    qp = _case()
    expanded, below = one_sided(qp)
    assert expanded.h.size == qp.h.size + below.size
    ref = solve_qp(expanded, "clarabel", tol=1e-10)
    sol = solve_qp(qp, backend)
    assert sol.status == "optimal" and sol.x is not None and sol.z is not None
    assert ref.x is not None and ref.z is not None
    assert np.allclose(sol.x, ref.x, atol=TOL[backend])
    # Signed multipliers (KKT; the duals of this program are not unique):
    # stationarity, z > 0 only on rows at their upper bound, z < 0 at their lower.
    atol = 1e3 * TOL[backend]
    assert np.abs(qp.P @ sol.x + qp.q + qp.G.T @ sol.z).max() <= atol
    Gx = qp.G @ sol.x
    assert qp.h_lower is not None
    assert np.all((sol.z <= atol) | (Gx >= qp.h - 1e-6))
    assert np.all((sol.z >= -atol) | (Gx <= qp.h_lower + 1e-6))
    assert np.any(sol.z < -0.1) and np.any(sol.z > 0.1)  # both sides bind somewhere
    folded = fold_duals(ref.z, below, qp.h.size)
    assert np.abs(qp.P @ ref.x + qp.q + qp.G.T @ folded).max() <= 1e-7


def test_piqp_session_updates_a_program_of_the_same_pattern() -> None:
    qp = _case()
    session = PiqpSession()
    first = session.solve(qp, 1e-10)
    moved = QuadraticProgram(
        qp.P, qp.q + 0.5, qp.A_eq, qp.b_eq, qp.G, 0.9 * qp.h, h_lower=qp.h_lower
    )
    updated = session.solve(moved, 1e-10)
    fresh = solve_qp(moved, "piqp")
    assert (session.setups, session.updates) == (1, 1)
    assert first.x is not None and updated.x is not None and fresh.x is not None
    assert np.allclose(updated.x, fresh.x, rtol=0.0, atol=1e-10)
    assert updated.z is not None and fresh.z is not None
    assert np.allclose(updated.z, fresh.z, rtol=0.0, atol=1e-8)


def test_piqp_session_sets_up_again_when_the_pattern_changes() -> None:
    qp = _case()
    session = PiqpSession()
    session.solve(qp, 1e-10)
    fewer = QuadraticProgram(qp.P, qp.q, qp.A_eq, qp.b_eq, sp.csc_array(qp.G[:4]), qp.h[:4])
    sol = session.solve(fewer, 1e-10)
    assert (session.setups, session.updates) == (2, 0)
    ref = solve_qp(fewer, "clarabel")
    assert sol.x is not None and ref.x is not None
    assert np.allclose(sol.x, ref.x, atol=1e-8)


def test_piqp_session_starts_afresh_after_a_failure() -> None:
    n = 2
    infeasible = QuadraticProgram(
        P=sp.csc_array(sp.eye_array(n)),
        q=np.zeros(n),
        A_eq=sp.csc_array((0, n)),
        b_eq=np.zeros(0),
        G=sp.csc_array(np.array([[1.0, 0.0]])),
        h=np.array([-1.0]),
        h_lower=np.array([1.0]),
    )
    session = PiqpSession()
    assert session.solve(infeasible, 1e-10).status == "infeasible"
    feasible = QuadraticProgram(
        infeasible.P,
        infeasible.q,
        infeasible.A_eq,
        infeasible.b_eq,
        infeasible.G,
        np.array([1.0]),
        h_lower=np.array([-1.0]),
    )
    assert session.solve(feasible, 1e-10).status == "optimal"
    assert session.setups == 2
