"""QP backends behind one interface: ``solve_qp(qp, backend)``.

The default, PIQP, was chosen by ``make bench`` (``bench/results/engine.json``,
case 2): at the accuracy the limit guarantee needs (tolerances 1e-10) it was
the fastest of the three on every QP measured, per-axis and coupled, both
hulls; Clarabel was ~1.5x slower and OSQP (first order) 10-1000x slower.
Clarabel stays the fallback when PIQP reports a failure.
"""

from __future__ import annotations

from skyquill.errors import InputError
from skyquill.solvers.base import QPBackend, QPSolution, QuadraticProgram, SecondOrderCones
from skyquill.solvers.clarabel_backend import solve_clarabel
from skyquill.solvers.osqp_backend import solve_osqp
from skyquill.solvers.piqp_backend import PiqpSession, solve_piqp

BACKENDS: dict[str, QPBackend] = {
    "clarabel": solve_clarabel,
    "piqp": solve_piqp,
    "osqp": solve_osqp,
}
DEFAULT_BACKEND = "piqp"
#: Backends that accept :class:`SecondOrderCones` (the others would ignore them).
CONIC_BACKENDS = ("clarabel",)


def solve_qp(
    qp: QuadraticProgram,
    backend: str = DEFAULT_BACKEND,
    tol: float = 1e-10,
    *,
    session: PiqpSession | None = None,
) -> QPSolution:
    """Solve ``qp`` with the named backend.

    ``session`` (PIQP only, ignored by the others) keeps PIQP's setup between
    programs of the same sparsity pattern (:class:`PiqpSession`).
    """
    if backend not in BACKENDS:
        raise InputError(f"solver: got {backend!r}, expected one of {sorted(BACKENDS)}")
    if qp.cones is not None and backend not in CONIC_BACKENDS:
        raise InputError(
            f"solver: got {backend!r} for a program with second-order cones, expected one "
            f"of {list(CONIC_BACKENDS)}"
        )
    if session is not None and backend == "piqp":
        return session.solve(qp, tol)
    return BACKENDS[backend](qp, tol)


__all__ = [
    "BACKENDS",
    "CONIC_BACKENDS",
    "DEFAULT_BACKEND",
    "PiqpSession",
    "QPSolution",
    "QuadraticProgram",
    "SecondOrderCones",
    "solve_qp",
]
