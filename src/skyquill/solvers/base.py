"""The one small interface every QP backend adapter implements.

A :class:`QuadraticProgram` is ``min 1/2 x'Px + q'x  s.t.  A_eq x = b_eq,
G x <= h`` (rows optionally two-sided, ``h_lower <= G x <= h``); a backend
returns a typed :class:`QPSolution` whose ``status`` is one of
``"optimal"``, ``"infeasible"`` or ``"failed"`` (qpsolvers' ``Solution`` and
rotorpy's ``ExitStatus`` do the same).

Duals, one sign convention for every backend (qpsolvers' ``Solution.y``,
``Solution.z``): at an optimum ``x`` with equality multipliers ``y`` and
inequality multipliers ``z >= 0``,

    P x + q + A_eq' y + G' z = 0,      z * (h - G x) = 0.

On two-sided rows (``h_lower``) the multiplier is signed, ``z = z_upper -
z_lower``: ``>= 0`` where the upper bound holds the row, ``<= 0`` where the
lower bound does (the row ``-G x <= -h_lower`` of the one-sided form with
multiplier ``-z``).

With second-order cones ``b_c - A_c x in K`` (:class:`SecondOrderCones`,
Clarabel's form) the cone multipliers ``z_c`` (in the dual cone, which is
``K`` itself) add ``A_c' z_c`` to stationarity,

    P x + q + A_eq' y + G' z + A_c' z_c = 0,      z_c' (b_c - A_c x) = 0,

i.e. the Lagrangian is ``1/2 x'Px + q'x + y'(A_eq x - b_eq) + z'(G x - h) +
z_c'(A_c x - b_c)``.

Each adapter converts its solver's own signs and row order to this.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Literal, Protocol

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

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
    h_lower
        Optional lower bounds of the rows of ``G``, shape (m_in,) (``-inf``:
        none): ``h_lower <= G x <= h``. A bound pair is one row, so a solver
        with two-sided rows (PIQP, OSQP) gets half the rows of the one-sided
        form (:func:`one_sided`).
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
    h_lower: FloatArray | None = None

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
        tolerance (signed on two-sided rows, module docstring), or ``None``
        unless optimal.
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
    below = qp.h_lower if qp.h_lower is not None else np.full(qp.h.size, -np.inf)
    lower = np.concatenate([qp.b_eq, below])
    upper = np.concatenate([qp.b_eq, qp.h])
    return A, lower, upper


def one_sided(qp: QuadraticProgram) -> tuple[QuadraticProgram, NDArray[np.intp]]:
    """``qp`` with every finite lower bound as a row ``-G_i x <= -h_lower_i`` below ``G``.

    Returns the program and the indices ``i`` of those rows in ``G``: its
    multipliers fold back to the signed ones of ``qp`` by :func:`fold_duals`.
    """
    if qp.h_lower is None:
        return qp, np.zeros(0, np.intp)
    below = np.flatnonzero(np.isfinite(qp.h_lower))
    G = sp.csc_array(sp.vstack([qp.G, -qp.G[below.tolist(), :]]))
    h = np.concatenate([qp.h, -qp.h_lower[below]])
    return replace(qp, G=G, h=h, h_lower=None), below


def fold_duals(z: FloatArray, below: NDArray[np.intp], m_in: int) -> FloatArray:
    """Signed multipliers (m_in,) of two-sided rows from those of :func:`one_sided`'s rows."""
    folded = z[:m_in].copy()
    folded[below] -= z[m_in:]
    return folded
