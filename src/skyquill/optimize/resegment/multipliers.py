"""The multipliers the time gradient needs, from the solve's own duals.

:func:`skyquill.optimize.solve` keeps the multipliers of the problem it
solved (:attr:`FitResult.y` for the equality rows of ``kron(E, I_d)``,
:attr:`FitResult.z` for the rows of ``G_ineq``): from the KKT solve on the
closed-form route, from the backend on the QP route. Here they are put in the
shape the envelope theorem uses, together with what it needs of the limit
rows (derivative order and ``G x``). On the QP route the point and its
multipliers are first polished (:mod:`.polish`): the backend's are accurate to
its tolerance only, which the gradient would inherit to first order.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from skyquill.optimize.assemble import assemble, problem_cost
from skyquill.optimize.resegment.polish import polish
from skyquill.optimize.solve import FitResult, _to_qp
from skyquill.validation import FloatArray

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Multipliers:
    """Control points and multipliers where the gradient is taken.

    Attributes
    ----------
    C
        Control points, shape (M, d), m.
    lam
        Equality multipliers, shape (m_eq, d): one row per row of the
        engine's ``E`` (boundary rows, then the interpolated points it kept),
        one column per axis.
    mu
        Inequality multipliers ``>= 0``, shape (m_in,), one per row of ``G_ineq``.
    order
        Derivative order of each inequality row, shape (m_in,) (0: corridor).
    Gx
        ``G_ineq @ x``, shape (m_in,).
    residual
        Relative stationarity residual (:attr:`TimeGradient.stationarity_residual`).
    cost
        Cost at ``C`` (the solve's own cost when ``C`` is its point).
    """

    C: FloatArray
    lam: FloatArray
    mu: FloatArray
    order: FloatArray
    Gx: FloatArray
    residual: float
    cost: float


def multipliers(result: FitResult) -> Multipliers:
    """The multipliers of ``result``'s solve (polished on the QP route), with the residual."""
    problem = result.problem
    # Assembled again rather than kept in FitResult: the matrices are 4-5x the
    # size of the rest of a result, which missions pickle across processes.
    asm = assemble(problem)
    # The QP the solve handed its backend (h tightened by the margin it needed).
    qp = _to_qp(asm, result.margin)
    C, cost = result.trajectory.control_points, result.cost
    x, y, z = C.ravel(), result.y, result.z
    if result.method == "qp":
        polished = polish(qp, x, z)
        if polished is None:
            log.debug("no polished point; using the solver's point and duals")
        else:
            x, y, z = polished.x, polished.y, polished.z
            C = x.reshape(C.shape)
            cost = problem_cost(problem, C)["total"]
    orders = np.zeros(qp.h.size)
    for fam, lim in zip(asm.families, problem.limits, strict=False):  # limits come first
        orders[fam.rows] = lim.order
    quad = qp.P @ x
    # grad J ~ 0 in the interior: measure the residual against its two parts.
    size = max(float(np.linalg.norm(quad)), float(np.linalg.norm(qp.q)), 1e-300)
    residual = float(np.linalg.norm(quad + qp.q + qp.A_eq.T @ y + qp.G.T @ z)) / size
    lam = y.reshape(-1, C.shape[1])
    return Multipliers(C, lam, np.maximum(z, 0.0), orders, qp.G @ x, residual, cost)
