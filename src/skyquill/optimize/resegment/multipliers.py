"""The multipliers the time gradient needs, from the solve's own duals.

:func:`skyquill.optimize.solve` keeps the multipliers of the problem it
solved (:attr:`FitResult.y` for the equality rows of ``kron(E, I_d)``,
:attr:`FitResult.z` for the rows of ``G_ineq``, :attr:`FitResult.cone_z` for
the second-order cone rows of exact norm limits): from the KKT solve on the
closed-form route, from the backend on the QP route. Here they are put in the
shape the envelope theorem uses, together with what it needs of the limit
rows (derivative order and ``G x``, ``A_c x``). On the QP route the point and
its multipliers are first polished (:mod:`.polish`): the backend's are
accurate to its tolerance only, which the gradient would inherit to first
order.

Each limit's rows are found by kind: a :class:`~skyquill.limits.NormLimit`
with ``sides=None`` owns a family of hull points in ``Assembled.cones``, every
other limit a family of rows of ``G_ineq``, in the order of
``problem.limits`` (corridor families follow the limit families).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from skyquill.limits import NormLimit
from skyquill.optimize.assemble import Assembled, assemble, problem_cost
from skyquill.optimize.banded import stationarity_residual
from skyquill.optimize.problem import SmoothingProblem
from skyquill.optimize.resegment.polish import polish
from skyquill.optimize.solve import FitResult, _closed_form_kkt, _to_qp
from skyquill.optimize.workspace import Workspace
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
    cone_z
        Cone multipliers, shape (m_c,), one per row of the solved QP's
        ``cones.A`` (:attr:`FitResult.cone_z`; empty without cones).
    cone_order
        Derivative order of each cone row, shape (m_c,).
    cone_values
        ``cones.A @ x``, shape (m_c,): ``(0, v_p)`` per hull point.
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
    cone_z: FloatArray
    cone_order: FloatArray
    cone_values: FloatArray
    residual: float
    cost: float


def multipliers(result: FitResult, workspace: Workspace | None = None) -> Multipliers:
    """The multipliers of ``result``'s solve (polished on the QP route), with the residual.

    ``workspace``: the one ``result`` was solved with, whose assembly of the
    same problem is then re-used.
    """
    problem = result.problem
    if result.method == "closed_form":
        cache = workspace.assembly if workspace is not None else None
        residual = stationarity_residual(problem, result.trajectory.control_points, result.y, cache)
        if residual is not None:  # nothing holds the point but the equalities
            return _equality_multipliers(result, residual)
    # Assembled again (or taken from the solve's workspace) rather than kept in
    # FitResult: the matrices are 4-5x the size of the rest of a result, which
    # missions pickle across processes.
    asm = workspace.assemble(problem) if workspace is not None else assemble(problem)
    # The QP the solve handed its backend (h tightened by the margin it needed).
    qp = _to_qp(asm, result.margin, workspace)
    C, cost = result.trajectory.control_points, result.cost
    x, y, z = C.ravel(), result.y, result.z
    cone_z = result.cone_z if result.cone_z is not None else np.zeros(0)
    if result.method == "qp":
        polished = polish(qp, x, z, result.cone_z, equality_solve=_equality_solve(asm))
        if polished is None:
            log.debug("no polished point; using the solver's point and duals")
        else:
            x, y, z = polished.x, polished.y, polished.z
            if polished.cone_z is not None:
                cone_z = polished.cone_z
            C = x.reshape(C.shape)
            cache = workspace.assembly if workspace is not None else None
            cost = problem_cost(problem, C, cache)["total"]
    orders, cone_orders = _row_orders(problem, asm)
    A_c = qp.cones.A if qp.cones is not None else None
    quad = qp.P @ x
    stationarity = quad + qp.q + qp.A_eq.T @ y + qp.G.T @ z
    if A_c is not None:
        stationarity = stationarity + A_c.T @ cone_z
    # grad J ~ 0 in the interior: measure the residual against its two parts.
    size = max(float(np.linalg.norm(quad)), float(np.linalg.norm(qp.q)), 1e-300)
    residual = float(np.linalg.norm(stationarity)) / size
    lam = y.reshape(-1, C.shape[1])
    cone_values = A_c @ x if A_c is not None else np.zeros(0)
    return Multipliers(
        C,
        lam,
        np.maximum(z, 0.0),
        orders,
        qp.G @ x,
        cone_z,
        cone_orders,
        cone_values,
        residual,
        cost,
    )


def _equality_multipliers(result: FitResult, residual: float) -> Multipliers:
    """The closed form's multipliers: its equality rows' own, no inequality or cone active.

    A banded problem's closed form (:mod:`skyquill.optimize.banded`) needs no
    assembly for them: its ``y`` solves the KKT system, which ``residual``
    measures; every inequality and cone multiplier is 0 there.
    """
    C = result.trajectory.control_points
    empty = np.zeros(0)
    return Multipliers(
        C, result.y.reshape(-1, C.shape[1]), empty, empty, empty, empty, empty, empty,
        residual, result.cost,
    )  # fmt: skip


def _equality_solve(asm: Assembled) -> Callable[[], tuple[FloatArray, FloatArray]] | None:
    """The per-axis closed form of ``asm`` for :func:`polish` when nothing is held."""
    if not asm.separable:
        return None

    def solve_per_axis() -> tuple[FloatArray, FloatArray]:
        C, y = _closed_form_kkt(asm)
        return C.ravel(), y

    return solve_per_axis


def _row_orders(problem: SmoothingProblem, asm: Assembled) -> tuple[FloatArray, FloatArray]:
    """Derivative order of each row of ``G_ineq`` (0: corridor) and of each cone row."""
    is_cone = [isinstance(lim, NormLimit) and lim.is_cone for lim in problem.limits]
    cone_limits = [lim for lim, cone in zip(problem.limits, is_cone, strict=True) if cone]
    linear_limits = [lim for lim, cone in zip(problem.limits, is_cone, strict=True) if not cone]
    orders = np.zeros(asm.G_ineq.shape[0])
    # Limit families come first, then the corridors (order 0).
    for fam, lim in zip(asm.families, linear_limits, strict=False):
        orders[fam.rows] = lim.order
    if asm.cones is None:
        return orders, np.zeros(0)
    point_orders = np.zeros(asm.cones.radius.size)
    for fam, lim in zip(asm.cones.families, cone_limits, strict=True):
        point_orders[fam.rows] = lim.order
    d = asm.F.shape[1]
    return orders, np.repeat(point_orders, d + 1)
