"""Second-order cones in the solver interface: Clarabel only, checked against closed forms."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.solvers import (
    BACKENDS,
    CONIC_BACKENDS,
    QuadraticProgram,
    SecondOrderCones,
    solve_qp,
)

Array = NDArray[np.float64]


def ball_projection(z: Array, radius: float, extra_rows: int = 0) -> QuadraticProgram:
    """``min 1/2 ||x - z||^2  s.t.  ||x|| <= radius``: the answer is ``z * min(1, r / ||z||)``.

    As Clarabel reads it: ``b - A x = (r, x)`` in SOC(n + 1), i.e. ``A = [0; -I]``.
    """
    n = z.size
    A = sp.csc_array(np.vstack([np.zeros((1, n)), -np.eye(n)]))
    b = np.concatenate([[radius], np.zeros(n)])
    return QuadraticProgram(
        P=sp.csc_array(np.eye(n)),
        q=-z,
        A_eq=sp.csc_array((0, n)),
        b_eq=np.zeros(0),
        G=sp.csc_array(np.ones((extra_rows, n))),
        h=np.full(extra_rows, 100.0),
        cones=SecondOrderCones(A, b, (n + 1,)),
    )


@pytest.mark.parametrize("z", [[3.0, 4.0], [0.1, -0.2, 0.3], [-6.0, 0.0, 8.0, 0.0]])
def test_clarabel_projects_onto_the_ball(z: list[float]) -> None:
    zz = np.array(z)
    sol = solve_qp(ball_projection(zz, 1.0, extra_rows=1), "clarabel")
    assert sol.status == "optimal" and sol.x is not None
    expected = zz * min(1.0, 1.0 / float(np.linalg.norm(zz)))
    # Along the sphere the objective is flat to second order: a 1e-10 gap
    # tolerance leaves ~1e-6 there, while the cone itself holds to 1e-9.
    np.testing.assert_allclose(sol.x, expected, atol=1e-5)
    assert np.linalg.norm(sol.x) <= 1.0 + 1e-9


def test_two_cone_blocks_and_an_equality() -> None:
    """Two points, each in its own ball, their sum fixed: both land on their spheres."""
    n = 4  # x = (p, q), p, q in R^2
    rows = np.zeros((6, n))
    rows[1:3, 0:2] = -np.eye(2)
    rows[4:6, 2:4] = -np.eye(2)
    b = np.array([1.0, 0, 0, 2.0, 0, 0])
    qp = QuadraticProgram(
        P=sp.csc_array(np.eye(n)),
        q=np.zeros(n),
        A_eq=sp.csc_array(np.array([[1.0, 0, 1, 0], [0, 1, 0, 1]])),
        b_eq=np.array([3.0, 0.0]),
        G=sp.csc_array((0, n)),
        h=np.zeros(0),
        cones=SecondOrderCones(sp.csc_array(rows), b, (3, 3)),
    )
    sol = solve_qp(qp, "clarabel")
    assert sol.x is not None
    np.testing.assert_allclose(sol.x, [1.0, 0.0, 2.0, 0.0], atol=1e-5)


def test_clarabel_certifies_an_empty_cone_intersection() -> None:
    qp = ball_projection(np.zeros(2), 1.0)
    qp = QuadraticProgram(
        qp.P, qp.q, sp.csc_array(np.array([[1.0, 0.0]])), np.array([2.0]), qp.G, qp.h, qp.cones
    )
    assert solve_qp(qp, "clarabel").status == "infeasible"


@pytest.mark.parametrize("backend", sorted(set(BACKENDS) - set(CONIC_BACKENDS)))
def test_backends_without_cones_refuse_them(backend: str) -> None:
    """They would silently drop the cones, so the dispatcher says no."""
    with pytest.raises(InputError, match=rf"solver: got '{backend}' for a program with "):
        solve_qp(ball_projection(np.ones(2), 1.0), backend)


@pytest.mark.parametrize("z", [[3.0, 4.0], [0.1, -2.0, 0.3], [0.2, 0.1]])
def test_clarabel_cone_duals_close_the_stationarity_condition(z: list[float]) -> None:
    """``P x + q + G'z + A_c' z_c = 0`` (QPSolution's convention) against the closed form.

    Projection onto the unit ball, ``A_c = [0; -I]``: outside, ``z_c = (||z|| - 1,
    (1/||z|| - 1) z)``; inside, ``z_c = 0``.
    """
    zz = np.array(z)
    qp = ball_projection(zz, 1.0, extra_rows=1)
    sol = solve_qp(qp, "clarabel")
    assert sol.x is not None and sol.z is not None and sol.cone_z is not None
    assert qp.cones is not None
    assert sol.cone_z.shape == (zz.size + 1,)
    residual = qp.P @ sol.x + qp.q + qp.G.T @ sol.z + qp.cones.A.T @ sol.cone_z
    assert np.linalg.norm(residual) <= 1e-8
    norm = float(np.linalg.norm(zz))
    expected = np.concatenate([[norm - 1.0], (1.0 / norm - 1.0) * zz]) if norm > 1.0 else 0 * zz
    # As in the projection test: x (hence z_c = x - z) is flat-accurate to ~1e-6 on the sphere.
    np.testing.assert_allclose(sol.cone_z, np.resize(expected, zz.size + 1), atol=1e-5)


def test_no_cone_duals_without_cones() -> None:
    qp = ball_projection(np.array([3.0, 4.0]), 1.0)
    plain = QuadraticProgram(qp.P, qp.q, qp.A_eq, qp.b_eq, qp.G, qp.h)
    assert solve_qp(plain, "clarabel").cone_z is None
