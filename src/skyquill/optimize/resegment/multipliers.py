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
import scipy.sparse as sp

from skyquill.optimize.assemble import assemble, problem_cost
from skyquill.optimize.resegment.polish import polish
from skyquill.optimize.solve import FitResult
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
    asm = assemble(problem)
    C, cost = result.trajectory.control_points, result.cost
    d = C.shape[1]
    x, y, z = C.ravel(), result.y, result.z
    if result.method == "qp":
        polished = polish(asm, x, z, result.margin)
        if polished is None:
            log.debug("no polished point; using the solver's point and duals")
        else:
            x, y, z = polished.x, polished.y, polished.z
            C = x.reshape(C.shape)
            cost = problem_cost(problem, C)["total"]
    G = asm.G_ineq
    orders = np.zeros(G.shape[0])
    for fam, lim in zip(asm.families, problem.limits, strict=False):  # limits come first
        orders[fam.rows] = lim.order
    A_eq = sp.kron(asm.E, sp.eye_array(d), format="csr")
    quad, f = 2.0 * (asm.hessian() @ x), asm.linear()
    # grad J ~ 0 in the interior: measure the residual against its two parts.
    size = max(float(np.linalg.norm(quad)), float(np.linalg.norm(f)), 1e-300)
    residual = float(np.linalg.norm(quad + f + A_eq.T @ y + G.T @ z)) / size
    return Multipliers(C, y.reshape(-1, d), np.maximum(z, 0.0), orders, G @ x, residual, cost)
