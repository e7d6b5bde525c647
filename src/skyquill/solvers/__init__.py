"""QP backends behind one interface: ``solve_qp(qp, backend)``.

The default, Clarabel, was chosen by ``make bench`` (see
``bench/results/engine.json``): it was the fastest of the three at the
accuracy the limit guarantee needs (gap and feasibility 1e-10).
"""

from __future__ import annotations

from skyquill.errors import InputError
from skyquill.solvers.base import QPBackend, QPSolution, QuadraticProgram
from skyquill.solvers.clarabel_backend import solve_clarabel
from skyquill.solvers.osqp_backend import solve_osqp
from skyquill.solvers.piqp_backend import solve_piqp

BACKENDS: dict[str, QPBackend] = {
    "clarabel": solve_clarabel,
    "piqp": solve_piqp,
    "osqp": solve_osqp,
}
DEFAULT_BACKEND = "clarabel"


def solve_qp(
    qp: QuadraticProgram, backend: str = DEFAULT_BACKEND, tol: float = 1e-10
) -> QPSolution:
    """Solve ``qp`` with the named backend."""
    if backend not in BACKENDS:
        raise InputError(f"solver: got {backend!r}, expected one of {sorted(BACKENDS)}")
    return BACKENDS[backend](qp, tol)


__all__ = ["BACKENDS", "DEFAULT_BACKEND", "QPSolution", "QuadraticProgram", "solve_qp"]
