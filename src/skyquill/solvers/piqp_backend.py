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
        result = solver.result
        # PIQP's stationarity is P x + c + A' y + G' (z_u - z_l) = 0 (two-sided
        # rows; h_l = -inf here, so z_l = 0); no box constraints are passed.
        y = np.array(result.y) if qp.b_eq.size else np.zeros(0)
        z = np.array(result.z_u) - np.array(result.z_l) if qp.h.size else np.zeros(0)
        return QPSolution("optimal", np.array(result.x), "piqp", elapsed, name, y, z)
    if name == "PIQP_PRIMAL_INFEASIBLE":
        return QPSolution("infeasible", None, "piqp", elapsed, name)
    return QPSolution("failed", None, "piqp", elapsed, name)
