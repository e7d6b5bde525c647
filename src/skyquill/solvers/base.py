"""The one small interface every QP backend adapter implements.

A :class:`QuadraticProgram` is ``min 1/2 x'Px + q'x  s.t.  A_eq x = b_eq,
G x <= h``; a backend returns a typed :class:`QPSolution` whose ``status``
is one of ``"optimal"``, ``"infeasible"`` or ``"failed"`` (qpsolvers'
``Solution`` and rotorpy's ``ExitStatus`` do the same).

Duals, one sign convention for every backend (qpsolvers' ``Solution.y``,
``Solution.z``): at an optimum ``x`` with equality multipliers ``y`` and
inequality multipliers ``z >= 0``,

    P x + q + A_eq' y + G' z = 0,      z * (h - G x) = 0.

With second-order cones ``b_c - A_c x in K`` (:class:`SecondOrderCones`,
Clarabel's form) the cone multipliers ``z_c`` (in the dual cone, which is
``K`` itself) add ``A_c' z_c`` to stationarity,

    P x + q + A_eq' y + G' z + A_c' z_c = 0,      z_c' (b_c - A_c x) = 0,

i.e. the Lagrangian is ``1/2 x'Px + q'x + y'(A_eq x - b_eq) + z'(G x - h) +
z_c'(A_c x - b_c)``.

Each adapter converts its solver's own signs and row order to this.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, Protocol

import numpy as np
import scipy.sparse as sp

from skyquill.validation import FloatArray

QPStatus = Literal["optimal", "infeasible", "failed"]


@dataclass(frozen=True)
class SecondOrderCones:
    """``b - A x`` in a product of second-order cones (Clarabel's convention).

    Consecutive blocks of rows of sizes ``dims`` each lie in
    ``{(t, u) : ||u||_2 <= t}``.

    Attributes
    ----------
    A
        Shape (m, n), CSC.
    b
        Shape (m,).
    dims
        Block sizes (each >= 2), summing to ``m``.
    """

    A: sp.csc_array
    b: FloatArray
    dims: tuple[int, ...]


@dataclass(frozen=True)
class QuadraticProgram:
    """``min 1/2 x'Px + q'x  s.t.  A_eq x = b_eq,  G x <= h``.

    Attributes
    ----------
    P
        Symmetric positive semi-definite, shape (n, n), CSC.
    q
        Shape (n,).
    A_eq, b_eq
        Shapes (m_eq, n), (m_eq,).
    G, h
        Shapes (m_in, n), (m_in,).
    cones
        Optional second-order cone constraints (a conic program: only the
        backends in ``skyquill.solvers.CONIC_BACKENDS`` take it).
    """

    P: sp.csc_array
    q: FloatArray
    A_eq: sp.csc_array
    b_eq: FloatArray
    G: sp.csc_array
    h: FloatArray
    cones: SecondOrderCones | None = None

    @property
    def n(self) -> int:
        """Number of variables."""
        return int(self.q.size)

    def objective(self, x: FloatArray) -> float:
        """``1/2 x'Px + q'x``."""
        return float(0.5 * x @ (self.P @ x) + self.q @ x)


@dataclass(frozen=True)
class QPSolution:
    """What a backend returns.

    Attributes
    ----------
    status
        ``"optimal"``, ``"infeasible"`` (certified primal infeasible) or
        ``"failed"`` (anything else; see ``message``).
    x
        Solution, shape (n,), or ``None`` unless optimal.
    solver
        Backend name.
    solve_time_s
        Wall time of the backend's setup and solve.
    message
        The backend's own status text.
    y
        Equality multipliers, shape (m_eq,), or ``None`` unless optimal
        (module docstring: ``P x + q + A_eq' y + G' z = 0``).
    z
        Inequality multipliers, shape (m_in,), ``>= 0`` up to the solver's
        tolerance, or ``None`` unless optimal.
    cone_z
        Second-order cone multipliers, shape (m_c,), one per row of
        ``qp.cones.A`` in its row order, each block in the cone (module
        docstring: ``... + A_c' z_c = 0``); ``None`` without cones or unless
        optimal.
    """

    status: QPStatus
    x: FloatArray | None
    solver: str
    solve_time_s: float
    message: str = ""
    y: FloatArray | None = None
    z: FloatArray | None = None
    cone_z: FloatArray | None = None


class QPBackend(Protocol):
    """A function that solves a :class:`QuadraticProgram` to high accuracy."""

    def __call__(self, qp: QuadraticProgram, tol: float) -> QPSolution: ...


def stacked_constraints(qp: QuadraticProgram) -> tuple[sp.csc_array, FloatArray, FloatArray]:
    """``l <= [A_eq; G] x <= u`` form used by several backends."""
    A = sp.csc_array(sp.vstack([qp.A_eq, qp.G]))
    lower = np.concatenate([qp.b_eq, np.full(qp.h.size, -np.inf)])
    upper = np.concatenate([qp.b_eq, qp.h])
    return A, lower, upper
