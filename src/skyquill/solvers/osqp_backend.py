"""OSQP (ADMM, C) adapter.

First-order: it reaches ``tol`` slowly on badly scaled problems, so it is not
the default; solution polishing recovers the exact active set when it can.
"""

from __future__ import annotations

import time

import numpy as np
import osqp
import scipy.sparse as sp

from skyquill.solvers.base import QPSolution, QuadraticProgram, stacked_constraints


def solve_osqp(qp: QuadraticProgram, tol: float) -> QPSolution:
    """Solve with OSQP; ``tol`` sets ``eps_abs`` and ``eps_rel``."""
    start = time.perf_counter()
    A, lower, upper = stacked_constraints(qp)
    problem = osqp.OSQP()
    problem.setup(
        sp.csc_matrix(sp.triu(qp.P, format="csc")),
        qp.q,
        sp.csc_matrix(A),
        lower,
        upper,
        verbose=False,
        eps_abs=tol,
        eps_rel=tol,
        max_iter=200_000,
        polishing=True,
    )
    # raise_error=False explicitly: osqp's default is to become True, which would
    # turn 'infeasible' / 'failed' statuses into exceptions here.
    result = problem.solve(raise_error=False)
    elapsed = time.perf_counter() - start
    name = str(result.info.status)
    if name.startswith("solved") and "inaccurate" not in name:
        # OSQP: P x + q + A' y = 0 for l <= A x <= u, y > 0 where the upper bound
        # is active; rows are [A_eq; G] (stacked_constraints).
        y = np.asarray(result.y)
        m_eq = qp.b_eq.size
        return QPSolution(
            "optimal", np.asarray(result.x), "osqp", elapsed, name, y[:m_eq], y[m_eq:]
        )
    if name.startswith("primal infeasible"):
        return QPSolution("infeasible", None, "osqp", elapsed, name)
    return QPSolution("failed", None, "osqp", elapsed, name)
