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


def kkt_qp(seed: int, n: int = 6, m_eq: int = 2, m_in: int = 8) -> tuple[QuadraticProgram, Array]:
    """A strictly convex QP built from a chosen KKT point: half the inequalities active
    with positive multipliers, the rest slack. Returns the QP and its minimiser."""
    rng = np.random.default_rng(seed)
    B = rng.normal(size=(n, n))
    P = B.T @ B + 0.1 * np.eye(n)
    A, G = rng.normal(size=(m_eq, n)), rng.normal(size=(m_in, n))
    x, y = rng.normal(size=n), rng.normal(size=m_eq)
    active = np.arange(m_in) < m_in // 2
    z = np.where(active, rng.uniform(0.5, 2.0, m_in), 0.0)
    slack = np.where(active, 0.0, rng.uniform(0.5, 2.0, m_in))
    q = -(P @ x + A.T @ y + G.T @ z)
    return make_qp(P, q, A=A, b=A @ x, G=G, h=G @ x + slack), x


@pytest.mark.parametrize("backend", ALL)
@pytest.mark.parametrize("seed", range(8))
def test_duals_satisfy_the_kkt_conditions(backend: str, seed: int) -> None:
    """``P x + q + A_eq' y + G' z = 0``, ``z >= 0``, ``z (h - G x) = 0`` (base docstring)."""
    qp, x_ref = kkt_qp(seed)
    sol = solve_qp(qp, backend)
    assert sol.status == "optimal"
    assert sol.x is not None and sol.y is not None and sol.z is not None
    assert sol.y.shape == qp.b_eq.shape and sol.z.shape == qp.h.shape
    x, y, z = sol.x, sol.y, sol.z
    Px = qp.P @ x
    residual = Px + qp.q + qp.A_eq.T @ y + qp.G.T @ z
    scale = max(float(np.linalg.norm(Px)), float(np.linalg.norm(qp.q)), 1.0)
    assert float(np.linalg.norm(residual)) <= 1e-6 * scale
    assert z.min() >= -1e-6 * max(1.0, float(np.abs(z).max()))
    slack = qp.h - qp.G @ x
    assert float(np.abs(z * slack).max()) <= 1e-6 * scale
    assert np.abs(x - x_ref).max() <= 1e-5


@pytest.mark.parametrize("backend", ALL)
def test_duals_of_a_known_projection(backend: str) -> None:
    """Projection of ``z = (2, -3, 0.5)`` onto ``x <= 1``, ``sum x = 0``: closed form."""
    point = np.array([2.0, -3.0, 0.5])
    # Free entries: x_i - point_i + y = 0, so sum x = 1 - 2.5 - 2 y = 0 gives y = -0.75,
    # x = (1, -2.25, 1.25); the bound row: 1 - 2 + y + z_0 = 0 gives z_0 = 1.75.
    qp = make_qp(np.eye(3), -point, A=np.ones((1, 3)), b=np.zeros(1), G=np.eye(3)[:1], h=np.ones(1))
    sol = solve_qp(qp, backend)
    assert sol.x is not None and sol.y is not None and sol.z is not None
    assert np.abs(sol.x - [1.0, -2.25, 1.25]).max() <= TOL[backend]
    assert np.abs(sol.y - [-0.75]).max() <= 10 * TOL[backend]
    assert np.abs(sol.z - [1.75]).max() <= 10 * TOL[backend]


@pytest.mark.parametrize("backend", INTERIOR_POINT)
def test_no_duals_unless_optimal(backend: str) -> None:
    qp = make_qp(np.eye(1), np.zeros(1), G=np.array([[1.0], [-1.0]]), h=np.array([-1.0, -1.0]))
    sol = solve_qp(qp, backend)
    assert sol.y is None and sol.z is None
