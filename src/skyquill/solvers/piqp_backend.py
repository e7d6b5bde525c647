"""PIQP (proximal interior point, C++) adapter."""

from __future__ import annotations

import time

import numpy as np
import piqp
import scipy.sparse as sp

from skyquill.solvers.base import QPSolution, QuadraticProgram


def solve_piqp(qp: QuadraticProgram, tol: float) -> QPSolution:
    """Solve with PIQP's sparse solver; ``tol`` sets its absolute and relative tolerances."""
    start = time.perf_counter()
    solver = piqp.SparseSolver()
    solver.settings.verbose = False
    solver.settings.eps_abs = tol
    solver.settings.eps_rel = tol
    solver.settings.max_iter = 250
    solver.setup(
        sp.csc_matrix(qp.P),
        qp.q,
        sp.csc_matrix(qp.A_eq) if qp.b_eq.size else None,
        qp.b_eq if qp.b_eq.size else None,
        sp.csc_matrix(qp.G) if qp.h.size else None,
        None,
        qp.h if qp.h.size else None,
    )
    status = solver.solve()
    elapsed = time.perf_counter() - start
    name = str(status).split(".")[-1]
    if name == "PIQP_SOLVED":
        return QPSolution("optimal", np.array(solver.result.x), "piqp", elapsed, name)
    if name == "PIQP_PRIMAL_INFEASIBLE":
        return QPSolution("infeasible", None, "piqp", elapsed, name)
    return QPSolution("failed", None, "piqp", elapsed, name)
