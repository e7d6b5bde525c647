"""Polish a QP solution: the exact minimiser on the active set of the solver's duals.

An interior-point solution is optimal only to the solver's tolerance: with
PIQP at tolerance 1e-10 the time gradient from its own point and duals was
off by up to 7e-5 relative (1e-5 with Clarabel) against central differences
of the exact optimal cost, on the random limited problems of
``tests/optimize/resegment``; the gradient is first-order in that error
where the cost is only second-order. So the rows with a positive multiplier
are held at their (tightened) bounds and the equality-constrained QP is
solved exactly by one KKT solve (:func:`skyquill.optimize.kkt.solve_equality_qp`),
which also gives the multipliers: the gradient error drops to ~1e-10.

Rows the polished point violates are added and rows with a negative
multiplier dropped until neither happens (a primal-dual active-set
iteration started from the solver's active set; one pass in the usual case).
If it does not settle, the KKT matrix is singular (the active rows are
dependent: no LICQ), or the polished point strays from the solver's, there
is no polished point and the solver's own point and duals are used.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from skyquill.optimize.kkt import SingularKKTError, solve_equality_qp
from skyquill.solvers import QuadraticProgram
from skyquill.validation import FloatArray

#: A row is active when its multiplier exceeds this fraction of the largest.
_ACTIVE_DUAL_RTOL = 1e-6
_ITERATIONS = 10
#: The polished point may move this far (relative) from the solver's.
_MAX_MOVE = 1e-3


@dataclass(frozen=True)
class Polished:
    """The exact minimiser on an active set and its multipliers.

    Attributes
    ----------
    x
        Minimiser, shape (n,) (the control points, vectorised).
    y
        Multipliers of the rows of ``A_eq``, shape (m_eq,).
    z
        Multipliers of the rows of ``G``, shape (m_in,), ``>= 0``; zero off
        the active set.
    """

    x: FloatArray
    y: FloatArray
    z: FloatArray


def polish(qp: QuadraticProgram, x0: FloatArray, z0: FloatArray) -> Polished | None:
    """Polish the solution ``x0`` (n,) with inequality duals ``z0`` (m_in,) of ``qp``.

    Parameters
    ----------
    qp
        The QP that was solved (with the solve's tightened ``h``:
        :func:`skyquill.optimize.solve._to_qp`).
    x0
        The solver's point, shape (n,).
    z0
        The solver's inequality multipliers, shape (m_in,).

    Returns
    -------
    Polished or None
        ``None`` when there is no polished point (module docstring).
    """
    G, h = qp.G, qp.h
    scale = np.maximum(np.abs(h), 1e-3)
    m = qp.b_eq.size
    active = np.flatnonzero(z0 > _ACTIVE_DUAL_RTOL * float(z0.max(initial=0.0)))
    for _ in range(_ITERATIONS):
        rows = sp.csr_array(sp.vstack([qp.A_eq, G[active.tolist(), :]], format="csr"))
        try:
            sol = solve_equality_qp(
                sp.csr_array(qp.P), qp.q, rows, np.concatenate([qp.b_eq, h[active]])
            )
        except SingularKKTError:
            return None
        z_active = sol.y[m:]
        violated = np.setdiff1d(np.flatnonzero((G @ sol.x - h) / scale > 1e-12), active)
        negative = z_active < -1e-9 * max(float(np.abs(z_active).max(initial=0.0)), 1e-300)
        if violated.size == 0 and not np.any(negative):
            return _accept(sol.x, x0, y=sol.y[:m], z=z_active, active=active, m_in=G.shape[0])
        active = np.union1d(active[~negative], violated)
    return None


def _accept(
    x: FloatArray,
    x0: FloatArray,
    *,
    y: FloatArray,
    z: FloatArray,
    active: NDArray[np.intp],
    m_in: int,
) -> Polished | None:
    """The polished point with ``z`` (active rows) spread over all ``m_in`` rows,
    unless it strays from the solver's ``x0``."""
    if float(np.linalg.norm(x - x0)) > _MAX_MOVE * max(1.0, float(np.linalg.norm(x0))):
        return None
    z_all = np.zeros(m_in)
    z_all[active] = np.maximum(z, 0.0)
    return Polished(x, y, z_all)
