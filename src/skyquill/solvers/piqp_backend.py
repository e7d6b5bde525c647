"""PIQP (proximal interior point, C++) adapter, with a session that re-uses its setup.

PIQP takes two-sided rows ``h_l <= G x <= h_u``, so a bound pair (a box on a
hull point) is one row, not two (:attr:`QuadraticProgram.h_lower`). Its KKT
system is solved by ``sparse_ldlt_cond`` (PIQP >= 0.6), which condenses the
inequality block into the factorised matrix: on the re-segmentation QPs of a
writing mission (1089 unknowns, 3249 two-sided rows) the solve took about
half the time of the default ``sparse_ldlt``, to the same point (1e-11
relative).

A :class:`PiqpSession` keeps one PIQP instance: a later program with the
same sparsity pattern (the same knots and limits, only other point times or
weights) is passed on by ``update()``, which skips the symbolic analysis
and re-uses the allocations; only the arrays that changed are passed. The
solution is the one a fresh setup finds (PIQP recomputes its scaling on
every update), to its tolerance.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np
import piqp
import scipy.sparse as sp

from skyquill.solvers.base import QPSolution, QuadraticProgram
from skyquill.validation import FloatArray


@dataclass(frozen=True)
class _Data:
    """What was handed to PIQP: matrices (CSC) and vectors, ``None`` where absent."""

    P: sp.csc_matrix
    q: FloatArray
    A: sp.csc_matrix | None
    b: FloatArray | None
    G: sp.csc_matrix | None
    h_l: FloatArray | None
    h_u: FloatArray | None
    #: The program's own ``A_eq`` and ``G``, to recognise them when they come again.
    sources: tuple[object, object]

    @classmethod
    def of(cls, qp: QuadraticProgram, last: _Data | None) -> _Data:
        """PIQP's arguments for ``qp``; ``A_eq`` and ``G`` taken over from ``last`` when the
        program brings the very same matrices (a workspace hands them out again)."""
        rows = qp.h.size > 0
        lower = qp.h_lower if rows and qp.h_lower is not None else None
        A, G = None, None
        if last is not None and last.sources[0] is qp.A_eq:
            A = last.A
        elif qp.b_eq.size:
            A = sp.csc_matrix(qp.A_eq)
        if last is not None and last.sources[1] is qp.G:
            G = last.G
        elif rows:
            G = sp.csc_matrix(qp.G)
        return cls(
            sp.csc_matrix(qp.P),
            qp.q,
            A,
            qp.b_eq if qp.b_eq.size else None,
            G,
            lower,
            qp.h if rows else None,
            (qp.A_eq, qp.G),
        )

    def same_pattern(self, other: _Data) -> bool:
        """Whether PIQP's ``update()`` accepts ``other`` after ``self`` (same sparsity)."""
        return (
            _same_pattern(self.P, other.P)
            and _same_pattern(self.A, other.A)
            and _same_pattern(self.G, other.G)
            and (self.h_l is None) == (other.h_l is None)
        )

    def changes(self, new: _Data) -> dict[str, Any]:
        """The keyword arguments of ``update()``: what differs in ``new``."""
        out: dict[str, Any] = {}
        pairs = (("P", self.P, new.P), ("A", self.A, new.A), ("G", self.G, new.G))
        for name, old_m, new_m in pairs:
            if (
                new_m is not None
                and old_m is not None
                and not np.array_equal(old_m.data, new_m.data)
            ):
                out[name] = new_m
        vectors = (
            ("c", self.q, new.q),
            ("b", self.b, new.b),
            ("h_l", self.h_l, new.h_l),
            ("h_u", self.h_u, new.h_u),
        )
        for name, old_v, new_v in vectors:
            if new_v is not None and (old_v is None or not np.array_equal(old_v, new_v)):
                out[name] = new_v
        return out


def _same_pattern(a: sp.csc_matrix | None, b: sp.csc_matrix | None) -> bool:
    if a is b:
        return True
    if a is None or b is None:
        return a is None and b is None
    return (
        a.shape == b.shape
        and np.array_equal(a.indptr, b.indptr)
        and np.array_equal(a.indices, b.indices)
    )


class PiqpSession:
    """One PIQP instance for a sequence of programs (module docstring).

    Not thread-safe; one per sequence of solves (a re-segmentation run owns
    its own through :class:`skyquill.optimize.workspace.Workspace`).
    """

    def __init__(self) -> None:
        self._solver: Any = None
        self._data: _Data | None = None
        self._tol = 0.0
        #: Setups and updates done (for tests and benchmarks).
        self.setups = 0
        self.updates = 0

    def solve(self, qp: QuadraticProgram, tol: float) -> QPSolution:
        """Solve ``qp``; ``tol`` sets PIQP's absolute and relative tolerances."""
        start = time.perf_counter()
        data = _Data.of(qp, self._data)
        if self._data is not None and tol == self._tol and self._data.same_pattern(data):
            changes = self._data.changes(data)
            if changes:
                self._solver.update(**changes)
            self.updates += 1
        else:
            self._solver = _setup(data, tol)
            self._tol = tol
            self.setups += 1
        self._data = data
        status = self._solver.solve()
        elapsed = time.perf_counter() - start
        name = str(status).split(".")[-1]
        if name != "PIQP_SOLVED":
            # A failed instance is not trusted with the next program.
            self._solver = self._data = None
        if name == "PIQP_SOLVED":
            return _solution(self._solver.result, qp, elapsed, name)
        if name == "PIQP_PRIMAL_INFEASIBLE":
            return QPSolution("infeasible", None, "piqp", elapsed, name)
        return QPSolution("failed", None, "piqp", elapsed, name)


def _setup(data: _Data, tol: float) -> Any:
    solver = piqp.SparseSolver()
    solver.settings.verbose = False
    solver.settings.eps_abs = tol
    solver.settings.eps_rel = tol
    solver.settings.max_iter = 250
    solver.settings.kkt_solver = piqp.KKTSolver.sparse_ldlt_cond
    solver.setup(data.P, data.q, data.A, data.b, data.G, data.h_l, data.h_u)
    return solver


def _solution(result: Any, qp: QuadraticProgram, elapsed: float, name: str) -> QPSolution:
    # PIQP's stationarity is P x + c + A' y + G' (z_u - z_l) = 0 on its two-sided
    # rows: z_u - z_l is the signed multiplier of QPSolution (z_l = 0 where
    # h_l = -inf); no box constraints on x are passed.
    y = np.array(result.y) if qp.b_eq.size else np.zeros(0)
    z = np.array(result.z_u) - np.array(result.z_l) if qp.h.size else np.zeros(0)
    return QPSolution("optimal", np.array(result.x), "piqp", elapsed, name, y, z)


def solve_piqp(qp: QuadraticProgram, tol: float) -> QPSolution:
    """Solve with PIQP's sparse solver from scratch; ``tol`` sets its tolerances."""
    return PiqpSession().solve(qp, tol)
