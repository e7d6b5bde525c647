"""Every QP backend on tiny problems whose optimum is known in closed form."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.solvers import BACKENDS, DEFAULT_BACKEND, QuadraticProgram, solve_qp

Array = NDArray[np.float64]
ALL = sorted(BACKENDS)
INTERIOR_POINT = ["clarabel", "piqp"]
# OSQP is first-order: its iterate is accurate to about the square root of
# what the interior-point backends reach; polishing usually recovers more.
TOL = {"clarabel": 1e-8, "piqp": 1e-8, "osqp": 1e-6}


def make_qp(
    P: Array,
    q: Array,
    *,
    A: Array | None = None,
    b: Array | None = None,
    G: Array | None = None,
    h: Array | None = None,
) -> QuadraticProgram:
    n = q.size
    return QuadraticProgram(
        P=sp.csc_array(P),
        q=np.asarray(q, dtype=float),
        A_eq=sp.csc_array(A if A is not None else np.zeros((0, n))),
        b_eq=np.asarray(b if b is not None else np.zeros(0), dtype=float),
        G=sp.csc_array(G if G is not None else np.zeros((0, n))),
        h=np.asarray(h if h is not None else np.zeros(0), dtype=float),
    )


def box_projection(z: Array, lo: Array, hi: Array) -> QuadraticProgram:
    """``min 1/2 ||x - z||^2  s.t.  lo <= x <= hi``: the answer is ``clip(z, lo, hi)``."""
    n = z.size
    eye = np.eye(n)
    return make_qp(eye, -z, G=np.vstack([eye, -eye]), h=np.concatenate([hi, -lo]))


def simplex_projection_reference(z: Array) -> Array:
    """Euclidean projection onto the probability simplex (sort-based, Held et al.)."""
    u = np.sort(z)[::-1]
    css = np.cumsum(u) - 1.0
    rho = np.nonzero(u - css / np.arange(1, z.size + 1) > 0)[0][-1]
    return np.maximum(z - css[rho] / (rho + 1.0), 0.0)


def simplex_projection(z: Array) -> QuadraticProgram:
    n = z.size
    return make_qp(np.eye(n), -z, A=np.ones((1, n)), b=np.ones(1), G=-np.eye(n), h=np.zeros(n))


def test_default_backend_is_registered() -> None:
    assert DEFAULT_BACKEND in BACKENDS
    assert set(BACKENDS) == {"clarabel", "piqp", "osqp"}


@pytest.mark.parametrize("backend", ALL)
def test_box_projection(backend: str) -> None:
    z = np.array([2.0, -3.0, 0.5, 0.0])
    lo, hi = np.full(4, -1.0), np.array([1.0, 1.0, 1.0, 2.0])
    sol = solve_qp(box_projection(z, lo, hi), backend)
    assert sol.status == "optimal"
    assert sol.solver == backend
    assert sol.x is not None
    assert sol.solve_time_s >= 0.0
    assert np.abs(sol.x - np.clip(z, lo, hi)).max() <= TOL[backend]


@pytest.mark.parametrize("backend", ALL)
def test_simplex_projection(backend: str) -> None:
    z = np.array([0.9, 0.6, -0.2, 0.1])
    sol = solve_qp(simplex_projection(z), backend)
    assert sol.status == "optimal"
    assert sol.x is not None
    ref = simplex_projection_reference(z)
    np.testing.assert_allclose(ref, [0.65, 0.35, 0.0, 0.0], atol=1e-12)
    assert np.abs(sol.x - ref).max() <= TOL[backend]


@pytest.mark.parametrize("backend", ALL)
@settings(max_examples=20, deadline=None)
@given(z=hnp.arrays(np.float64, st.integers(1, 6), elements=st.floats(-5, 5)))
def test_random_simplex_projections(backend: str, z: Array) -> None:
    """Random projections, including degenerate ones (``z = (0, 1)``: a bound active with
    a zero multiplier), where an interior-point iterate is only accurate to about the
    square root of the gap tolerance; the objective is accurate to the tolerance.
    """
    qp = simplex_projection(z)
    sol = solve_qp(qp, backend)
    assert sol.status == "optimal"
    assert sol.x is not None
    ref = simplex_projection_reference(z)
    assert np.abs(sol.x - ref).max() <= 1e-4
    assert abs(sol.x.sum() - 1.0) <= 1e-8
    assert sol.x.min() >= -1e-8
    assert qp.objective(sol.x) - qp.objective(ref) <= 1e-8


@pytest.mark.parametrize("backend", ALL)
def test_equality_only(backend: str) -> None:
    """``min 1/2 ||x - z||^2  s.t.  sum x = 1``: ``x = z + (1 - sum z) / n``."""
    z = np.array([2.0, -3.0, 0.5])
    sol = solve_qp(make_qp(np.eye(3), -z, A=np.ones((1, 3)), b=np.ones(1)), backend)
    assert sol.status == "optimal"
    assert sol.x is not None
    assert np.abs(sol.x - (z + (1.0 - z.sum()) / 3.0)).max() <= TOL[backend]


@pytest.mark.parametrize("backend", ALL)
def test_unconstrained(backend: str) -> None:
    """``min 1/2 x'Px + q'x`` with P positive definite: ``x = -P^-1 q``."""
    P = np.array([[4.0, 1.0], [1.0, 3.0]])
    q = np.array([1.0, -2.0])
    sol = solve_qp(make_qp(P, q), backend)
    assert sol.status == "optimal"
    assert sol.x is not None
    assert np.abs(sol.x - np.linalg.solve(P, -q)).max() <= TOL[backend]


@pytest.mark.parametrize("backend", ALL)
def test_objective_helper(backend: str) -> None:
    qp = box_projection(np.array([3.0, 0.0]), np.full(2, -1.0), np.full(2, 1.0))
    sol = solve_qp(qp, backend)
    assert sol.x is not None
    # 1/2 ||x||^2 - z'x at x = (1, 0): 0.5 - 3.
    assert qp.objective(sol.x) == pytest.approx(-2.5, abs=10 * TOL[backend])
    assert qp.n == 2


@pytest.mark.parametrize("backend", INTERIOR_POINT)
def test_infeasible_inequalities(backend: str) -> None:
    qp = make_qp(np.eye(1), np.zeros(1), G=np.array([[1.0], [-1.0]]), h=np.array([-1.0, -1.0]))
    sol = solve_qp(qp, backend)
    assert sol.status == "infeasible"
    assert sol.x is None
    assert sol.message


@pytest.mark.parametrize("backend", INTERIOR_POINT)
def test_infeasible_equalities_and_inequalities(backend: str) -> None:
    """``x0 + x1 = 3`` with ``0 <= x <= 1``."""
    eye = np.eye(2)
    qp = make_qp(
        eye,
        np.zeros(2),
        A=np.ones((1, 2)),
        b=np.array([3.0]),
        G=np.vstack([eye, -eye]),
        h=np.array([1.0, 1.0, 0.0, 0.0]),
    )
    sol = solve_qp(qp, backend)
    assert sol.status == "infeasible"
    assert sol.x is None


def test_osqp_reports_infeasible_too() -> None:
    qp = make_qp(np.eye(1), np.zeros(1), G=np.array([[1.0], [-1.0]]), h=np.array([-1.0, -1.0]))
    assert solve_qp(qp, "osqp").status == "infeasible"


@pytest.mark.parametrize("backend", ALL)
def test_unbounded_is_a_failure_not_optimal(backend: str) -> None:
    """``min x  s.t.  x <= 0`` has no minimiser: dual infeasible."""
    qp = make_qp(np.zeros((1, 1)), np.ones(1), G=np.ones((1, 1)), h=np.zeros(1))
    sol = solve_qp(qp, backend)
    assert sol.status == "failed"
    assert sol.x is None


@pytest.mark.parametrize("name", ["gurobi", "Clarabel", "", "qpsolvers"])
def test_unknown_backend(name: str) -> None:
    qp = box_projection(np.zeros(1), -np.ones(1), np.ones(1))
    with pytest.raises(InputError, match=rf"solver: got '{name}', expected one of \['clarabel'"):
        solve_qp(qp, name)
