"""Clarabel (interior point, Rust) adapter; the one backend that also takes second-order cones."""

from __future__ import annotations

import time

import clarabel
import numpy as np
import scipy.sparse as sp

from skyquill.solvers.base import QPSolution, QuadraticProgram, fold_duals, one_sided


def solve_clarabel(qp: QuadraticProgram, tol: float) -> QPSolution:
    """Solve with Clarabel; ``tol`` sets its gap and feasibility tolerances."""
    start = time.perf_counter()
    m_rows = qp.h.size
    # Clarabel's cones are one-sided: a two-sided row becomes two rows.
    qp, below = one_sided(qp)
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = tol
    settings.tol_feas = tol
    settings.tol_ktratio = 1e-8
    settings.max_iter = 200
    blocks, rhs = [qp.A_eq, qp.G], [qp.b_eq, qp.h]
    cones = []
    if qp.b_eq.size:
        cones.append(clarabel.ZeroConeT(qp.b_eq.size))
    if qp.h.size:
        cones.append(clarabel.NonnegativeConeT(qp.h.size))
    if qp.cones is not None:
        blocks.append(qp.cones.A)
        rhs.append(qp.cones.b)
        cones.extend(clarabel.SecondOrderConeT(k) for k in qp.cones.dims)
    A = sp.csc_matrix(sp.vstack(blocks))
    b = np.concatenate(rhs)
    P = sp.csc_matrix(sp.triu(qp.P, format="csc"))
    result = clarabel.DefaultSolver(P, qp.q, A, b, cones, settings).solve()
    elapsed = time.perf_counter() - start
    name = str(result.status).split(".")[-1]
    if name in ("Solved", "AlmostSolved"):
        # Clarabel: P x + q + A' z = 0 with z in the dual cone of each row block,
        # zero cone (equalities) first, then the nonnegative cone (G x <= h), then
        # the second-order cones: already the signs of QPSolution.
        z = np.asarray(result.z)
        m_eq, m_in = qp.b_eq.size, qp.h.size
        return QPSolution(
            "optimal",
            np.asarray(result.x),
            "clarabel",
            elapsed,
            name,
            z[:m_eq],
            fold_duals(z[m_eq : m_eq + m_in], below, m_rows),
            z[m_eq + m_in :] if qp.cones is not None else None,
        )
    if "PrimalInfeasible" in name:
        return QPSolution("infeasible", None, "clarabel", elapsed, name)
    return QPSolution("failed", None, "clarabel", elapsed, name)
