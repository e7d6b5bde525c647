"""A linear program built once and re-solved as its bounds change.

``min c'x  s.t.  row_lower <= A x <= row_upper,  col_lower <= x <= col_upper``.
An iteration that only moves bounds between solves (a sequential
linearisation, a local tightening) keeps one :class:`LinearProgram`:

* ``"highspy"`` passes the model to HiGHS once; every later solve hands it
  only the bounds that changed, so the dual simplex restarts from the previous
  optimal basis (tens of pivots instead of a cold solve).  A solve that ends
  neither optimal nor infeasible (a stalled hot start: more simplex
  iterations than :data:`HOT_SOLVE_ITERATIONS_PER_COLUMN` per column) switches
  the instance to ``"linprog"`` for good, unless the caller gives a point to
  start again from (``restart``). The stall is told by iterations,
  not wall time, so that the same problem takes the same path on a busy
  machine (a 0.5 s limit sent plans to the slow cold solves under load).
* ``"linprog"`` rebuilds the rows for :func:`scipy.optimize.linprog` (HiGHS,
  presolve on) and solves from scratch every time: the reference, and the
  fallback when highspy is not installed.

A solve returns a typed :class:`LPSolution` with a status; raising (and saying
which problem failed) is the caller's job.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from scipy import sparse
from scipy.optimize import linprog

from skyquill.errors import InputError
from skyquill.validation import FloatArray

try:  # optional fast path: one HiGHS model, hot-started between re-solves
    import highspy as _highspy
except ImportError:  # pragma: no cover - exercised only without highspy
    _highspy = None  # type: ignore[assignment]

# scipy-stubs do not list a sparse A_ub; HiGHS accepts it.
_linprog: Callable[..., Any] = linprog

logger = logging.getLogger(__name__)

LPBackend = Literal["highspy", "linprog"]
LPStatus = Literal["optimal", "infeasible", "time_limit", "failed"]
#: Backend names :func:`resolve_backend` accepts.
LP_BACKENDS = ("auto", "highspy", "linprog")
#: Simplex iterations per column after which a hot start counts as stalled (cold
#: solves of the coverage speed LP took 0.6-1.7 per column, hot ones a few in all).
HOT_SOLVE_ITERATIONS_PER_COLUMN = 20
#: With a point to start again from (``restart`` of :meth:`LinearProgram.solve`), the
#: simplex iterations per column after which a hot start is given up for it: 860
#: warm-started re-solves of the coverage speed LP on three keep-out fields took at most
#: 0.31 per column; one stalled at 20 (40,000 pivots, 8.6 s, then linprog for every solve
#: after it) where starting again from the interior point's answer took 0.14 s, about the
#: time of 500 pivots, so giving up early costs little.
RESTART_ITERATIONS_PER_COLUMN = 0.5

#: HiGHS's ``simplex_dual_edge_weight_strategy`` for Devex pricing. Its default picks dual
#: steepest edge, whose weights cost an extra solve with the basis every pivot and are
#: computed again for every row when rows are added: on the coverage speed LPs (tens of
#: thousands of rows, a few thousand columns) a re-solve after :meth:`LinearProgram.add_rows`
#: took 35-40 ms whatever its pivots, against 2-7 ms with Devex, and the eleven largest speed
#: plans of ``holes_1_3ha`` took 5.6 s of HiGHS and the rest instead of 6.7 s with every row
#: held (the same flights); the 2,000- and 4,000-point spiral, per axis, 0.26 / 0.34 s
#: instead of 0.30 / 0.52 s.
DEVEX = 1

__all__ = [
    "DEVEX",
    "HOT_SOLVE_ITERATIONS_PER_COLUMN",
    "LP_BACKENDS",
    "RESTART_ITERATIONS_PER_COLUMN",
    "LPBackend",
    "LPSolution",
    "LPStatus",
    "LinearProgram",
    "highspy_available",
    "resolve_backend",
    "vertex_basis",
]


def _quiet_highs() -> Any:
    """A HiGHS instance that has printed nothing.

    ``highspy.Highs()`` enables its Python callbacks in its constructor, a HiGHS
    call that prints the "Running HiGHS" banner on stdout before ``output_flag``
    can be cleared (ERGO-Code/HiGHS#1702, #2749): it landed in the middle of
    ``skyquill cover``'s output. The binding's base class has every method this
    backend calls and no callbacks to enable.
    """
    core = getattr(_highspy, "_core", None)
    plain = getattr(core, "_Highs", None)
    return plain() if plain is not None else _highspy.Highs()  # type: ignore[no-untyped-call]


def highspy_available() -> bool:
    """Whether the hot-starting highspy backend is installed."""
    return _highspy is not None


def resolve_backend(name: str, *, argument: str = "lp_backend") -> LPBackend:
    """The backend ``name`` stands for: ``"auto"`` takes highspy when installed.

    Raises
    ------
    InputError
        Unknown name, or ``"highspy"`` without highspy installed; the message
        names ``argument``.
    """
    if name not in LP_BACKENDS:
        raise InputError(f"{argument}: got {name!r}, expected one of {LP_BACKENDS}")
    if name == "highspy" and not highspy_available():
        raise InputError(
            f"{argument}: got 'highspy', expected 'auto' or 'linprog' (highspy is not installed)"
        )
    if name == "auto":
        return "highspy" if highspy_available() else "linprog"
    return "highspy" if name == "highspy" else "linprog"


@dataclass(frozen=True, eq=False)
class LPSolution:
    """What one solve returns.

    Attributes
    ----------
    status : {"optimal", "infeasible", "time_limit", "failed"}
        ``"time_limit"``: stopped at :attr:`LinearProgram.time_limit_s`;
        ``"failed"``: anything else (see ``message``).
    x : ndarray, shape (n,), or None
        The solution clipped into the column bounds; None unless optimal.
    solver : {"highspy", "linprog"}
        The backend that produced it.
    solve_time_s : float
        Wall time of the solve, s.
    message : str
        The backend's own status text.
    """

    status: LPStatus
    x: FloatArray | None
    solver: LPBackend
    solve_time_s: float
    message: str = ""


class LinearProgram:
    """``min c'x`` s.t. ``row_lower <= A x <= row_upper``, ``col_lower <= x <= col_upper``.

    Built once; :meth:`update_bounds` changes bounds and :meth:`solve`
    re-solves (hot-started with highspy).  Rows start free, columns at
    ``[0, inf)``.

    Parameters
    ----------
    a : sparse matrix or ndarray, shape (m, n)
        Constraint rows.
    cost : array_like, shape (n,)
        Objective ``c`` (minimised).
    backend : {"auto", "highspy", "linprog"}, default "auto"
        See the module docstring.
    time_limit_s : float, default inf
        Wall-time limit of one solve, s (a caller's remaining budget): a solve
        stopped by it returns status ``"time_limit"``.
    """

    def __init__(
        self,
        a: Any,
        cost: Any,
        *,
        backend: str = "auto",
        time_limit_s: float = math.inf,
    ) -> None:
        self.a = sparse.csr_array(a)
        m, n = self.a.shape
        self.cost = np.asarray(cost, dtype=np.float64)
        if self.cost.shape != (n,):
            raise InputError(f"cost: got shape {self.cost.shape}, expected ({n},)")
        if not time_limit_s > 0.0:
            raise InputError(f"time_limit_s: got {time_limit_s!r}, expected a positive number")
        self.backend: LPBackend = resolve_backend(backend, argument="backend")
        self.time_limit_s = float(time_limit_s)
        self.solve_time_s = 0.0
        self.solves = 0
        self.row_lower = np.full(m, -np.inf)
        self.row_upper = np.full(m, np.inf)
        self.col_lower = np.zeros(n)
        self.col_upper = np.full(n, np.inf)
        self._highs: _HighsModel | None = (
            _HighsModel(self.a, self.cost) if self.backend == "highspy" else None
        )

    def update_bounds(
        self,
        *,
        row_lower: FloatArray | None = None,
        row_upper: FloatArray | None = None,
        col_lower: FloatArray | None = None,
        col_upper: FloatArray | None = None,
    ) -> None:
        """Replace the given bounds (``+-inf``: unbounded); the others stay."""
        for name, value in (
            ("row_lower", row_lower),
            ("row_upper", row_upper),
            ("col_lower", col_lower),
            ("col_upper", col_upper),
        ):
            if value is None:
                continue
            old = getattr(self, name)
            new = np.asarray(value, dtype=np.float64)
            if new.shape != old.shape:
                raise InputError(f"{name}: got shape {new.shape}, expected {old.shape}")
            setattr(self, name, new.copy())

    def add_rows(self, a: Any, lower: FloatArray, upper: FloatArray) -> None:
        """Append the rows ``a`` (k, n) with bounds ``lower``, ``upper`` (k,).

        With highspy the basis stays valid (the new rows' slacks are basic), so
        the next solve is a dual-simplex hot start from the last optimum: a
        row that the last optimum breaks is a primal infeasibility it repairs
        in a few pivots (a cutting plane).
        """
        rows = sparse.csr_array(a)
        lo, hi = (np.asarray(x, dtype=np.float64) for x in (lower, upper))
        k = rows.shape[0]
        if rows.shape[1] != self.a.shape[1] or lo.shape != (k,) or hi.shape != (k,):
            raise InputError(
                f"a: got {rows.shape} rows with bounds {lo.shape}, {hi.shape}, "
                f"expected (k, {self.a.shape[1]}) and (k,)"
            )
        self.a = sparse.vstack([self.a, rows], format="csr")
        self.row_lower = np.concatenate([self.row_lower, lo])
        self.row_upper = np.concatenate([self.row_upper, hi])
        if self._highs is not None:
            self._highs.add_rows(rows, lo, hi)

    def solve(
        self,
        start: FloatArray | None = None,
        restart: Callable[[], FloatArray | None] | None = None,
    ) -> LPSolution:
        """Solve with the current bounds (hot start from the last basis with highspy).

        Parameters
        ----------
        start : ndarray, shape (n,), optional
            A point near an optimal vertex (an interior-point method's answer):
            highspy starts from that vertex's basis (:func:`vertex_basis`)
            instead of the last one.  Where the bounds changed a lot, this saves
            the thousands of pivots the last basis needs (a coverage piece's
            first jerk-limited LP: 4,140 pivots and 0.76 s, against 4 pivots
            and 0.1 s with the factorisation).  linprog does not use it.
        restart : callable, optional
            Gives such a point (or None) where highspy's hot start stalls, told
            by :data:`RESTART_ITERATIONS_PER_COLUMN`: highspy solves again from
            its vertex before linprog takes over.
        """
        if self._highs is not None:
            began = time.perf_counter()
            per_column = None if restart is None else RESTART_ITERATIONS_PER_COLUMN
            sol = self._highs.solve(self, self.time_limit_s, start, per_column=per_column)
            if sol is None and restart is not None and (point := restart()) is not None:
                logger.info("highspy stalled; from the vertex of the restart point")
                left = max(self.time_limit_s - (time.perf_counter() - began), 1e-3)
                sol = self._highs.solve(self, left, point)
            if sol is not None:  # None: stalled
                return self._count(sol)
            logger.info("highspy stalled; linprog for the remaining solves")
            self._highs = None
            self.backend = "linprog"
        return self._count(_solve_linprog(self, self.time_limit_s))

    def _count(self, sol: LPSolution) -> LPSolution:
        self.solve_time_s += sol.solve_time_s
        self.solves += 1
        return sol


def _normalised_rows(lp: LinearProgram) -> tuple[Any, FloatArray]:
    """``A_ub x <= b_ub`` from the finite row bounds, each row scaled to ``|b_ub| = 1``.

    (linprog's presolve and scaling prefer right-hand sides of one.)
    """
    blocks, rhs = [], []
    for bound, sign in ((lp.row_upper, 1.0), (lp.row_lower, -1.0)):
        keep = np.isfinite(bound)
        size = np.abs(bound[keep])
        scale = sign / np.where(size > 0.0, size, 1.0)
        blocks.append(sparse.diags_array(scale) @ lp.a[keep])
        rhs.append(bound[keep] * scale)
    return sparse.vstack(blocks, format="csr"), np.concatenate(rhs)


def _solve_linprog(lp: LinearProgram, limit_s: float) -> LPSolution:
    """One cold solve with :func:`scipy.optimize.linprog` (HiGHS, presolve on), within
    ``limit_s`` seconds."""
    a_ub, b_ub = _normalised_rows(lp)
    lower = np.where(np.isfinite(lp.col_lower), lp.col_lower, np.nan)
    upper = np.where(np.isfinite(lp.col_upper), lp.col_upper, np.nan)
    bounds = [
        (None if np.isnan(lo) else lo, None if np.isnan(hi) else hi)
        for lo, hi in zip(lower.tolist(), upper.tolist(), strict=True)
    ]
    t0 = time.perf_counter()
    options = {} if math.isinf(limit_s) else {"time_limit": limit_s}
    res = _linprog(lp.cost, A_ub=a_ub, b_ub=b_ub, bounds=bounds, method="highs", options=options)
    dt = time.perf_counter() - t0
    if res.status == 2:
        return LPSolution("infeasible", None, "linprog", dt, str(res.message))
    if res.status == 1 and not math.isinf(limit_s):  # linprog's "iteration or time limit"
        return LPSolution("time_limit", None, "linprog", dt, str(res.message))
    if res.status != 0 or res.x is None:
        return LPSolution("failed", None, "linprog", dt, str(res.message))
    x = np.clip(np.asarray(res.x, dtype=np.float64), lp.col_lower, lp.col_upper)
    return LPSolution("optimal", x, "linprog", dt, str(res.message))


class _HighsModel:
    """One silent HiGHS instance; only the bounds that changed are passed on a re-solve.

    Presolve is off: it would discard the basis of the hot starts, and the
    cold first solve is no faster with it (72 vs 81 ms on a 2000-column
    speed LP). The dual simplex prices by Devex weights (:data:`DEVEX`).
    """

    def __init__(self, a: Any, cost: FloatArray) -> None:
        assert _highspy is not None  # resolve_backend checked it
        csc = sparse.csc_array(a)
        m, n = csc.shape
        inf = _highspy.kHighsInf
        model = _highspy.HighsLp()
        model.num_col_ = n
        model.num_row_ = m
        model.col_cost_ = cost
        model.col_lower_ = np.zeros(n)
        model.col_upper_ = np.full(n, inf)
        model.row_lower_ = np.full(m, -inf)
        model.row_upper_ = np.full(m, inf)
        model.a_matrix_.format_ = _highspy.MatrixFormat.kColwise
        model.a_matrix_.start_ = csc.indptr
        model.a_matrix_.index_ = csc.indices
        model.a_matrix_.value_ = csc.data
        self.highs: Any = _quiet_highs()
        self.highs.setOptionValue("output_flag", False)
        self.highs.setOptionValue("presolve", "off")
        self.highs.setOptionValue("simplex_dual_edge_weight_strategy", DEVEX)
        self.highs.passModel(model)
        # Bounds the instance holds now.
        self.rows = (np.full(m, -np.inf), np.full(m, np.inf))
        self.cols = (np.zeros(n), np.full(n, np.inf))

    def solve(
        self,
        lp: LinearProgram,
        limit_s: float,
        start: FloatArray | None = None,
        *,
        per_column: float | None = None,
    ) -> LPSolution | None:
        """Pass the changed bounds and re-solve within ``limit_s`` s, from the basis of the
        vertex nearest ``start`` if given; None when HiGHS stalled (more simplex iterations
        than ``per_column`` per column, by default :data:`HOT_SOLVE_ITERATIONS_PER_COLUMN`)."""
        assert _highspy is not None
        self._pass_bounds(lp)
        t0 = time.perf_counter()
        if start is None:
            status = self._run(limit_s, per_column)
        else:
            status = self._run_from(lp, start, limit_s)
        dt = time.perf_counter() - t0
        statuses = _highspy.HighsModelStatus
        if status == statuses.kTimeLimit:
            return LPSolution("time_limit", None, "highspy", dt, "time limit reached")
        if status not in (statuses.kOptimal, statuses.kInfeasible):
            # A hot start can stall, or end "Unknown", on some problems where a
            # cold linprog solve (presolve on) does not.
            logger.info("highspy: %s", self.highs.modelStatusToString(status))
            return None
        message = str(self.highs.modelStatusToString(status))
        if status == statuses.kInfeasible:
            return LPSolution("infeasible", None, "highspy", dt, message)
        x = np.asarray(self.highs.getSolution().col_value, dtype=np.float64)
        return LPSolution("optimal", np.clip(x, lp.col_lower, lp.col_upper), "highspy", dt, message)

    def add_rows(self, rows: Any, lower: FloatArray, upper: FloatArray) -> None:
        """Append the CSR ``rows`` with bounds ``lower``, ``upper`` (the basis stays valid)."""
        assert _highspy is not None
        inf = _highspy.kHighsInf
        k = rows.shape[0]
        self.highs.addRows(k, _finite(lower, inf), _finite(upper, inf), rows.nnz,
                           rows.indptr[:-1].astype(np.int32), rows.indices.astype(np.int32),
                           rows.data)  # fmt: skip
        self.rows = (np.concatenate([self.rows[0], lower]), np.concatenate([self.rows[1], upper]))

    def _pass_bounds(self, lp: LinearProgram) -> None:
        assert _highspy is not None
        inf = _highspy.kHighsInf
        lo, hi = lp.row_lower, lp.row_upper
        idx = np.flatnonzero((lo != self.rows[0]) | (hi != self.rows[1])).astype(np.int32)
        if idx.size:
            self.highs.changeRowsBounds(idx.size, idx, _finite(lo[idx], inf), _finite(hi[idx], inf))
        self.rows = (lo.copy(), hi.copy())
        lo, hi = lp.col_lower, lp.col_upper
        idx = np.flatnonzero((lo != self.cols[0]) | (hi != self.cols[1])).astype(np.int32)
        if idx.size:
            self.highs.changeColsBounds(idx.size, idx, _finite(lo[idx], inf), _finite(hi[idx], inf))
        self.cols = (lo.copy(), hi.copy())

    def _run_from(self, lp: LinearProgram, start: FloatArray, limit_s: float) -> Any:
        """Run from the basis of the vertex nearest ``start``; where HiGHS cannot go on
        from it (a basis too ill-conditioned: "excessive dual values"), run again from
        the basis it had."""
        assert _highspy is not None
        statuses = _highspy.HighsModelStatus
        basis = vertex_basis(lp, start)
        if basis is None:
            return self._run(limit_s)
        last = self.highs.getBasis()
        self.highs.setBasis(basis)
        status = self._run(limit_s)
        if status in (statuses.kOptimal, statuses.kInfeasible, statuses.kTimeLimit):
            return status
        logger.info("highspy: %s from the vertex's basis; from its last basis",
                    self.highs.modelStatusToString(status))  # fmt: skip
        if last.valid:
            self.highs.setBasis(last)
        else:
            self.highs.clearSolver()
        return self._run(limit_s)

    def _run(self, limit_s: float, per_column: float | None = None) -> Any:
        """Run HiGHS for at most ``limit_s`` more seconds and ``per_column`` simplex
        iterations per column (:data:`HOT_SOLVE_ITERATIONS_PER_COLUMN` by default); its
        model status.

        HiGHS's ``time_limit`` counts the instance's run time over all solves,
        so the limit is set relative to the time already spent; its iteration
        count starts again at every run.
        """
        per_column = HOT_SOLVE_ITERATIONS_PER_COLUMN if per_column is None else per_column
        iterations = math.ceil(per_column * self.highs.getNumCol())
        self.highs.setOptionValue("simplex_iteration_limit", iterations)
        self.highs.setOptionValue("time_limit", float(self.highs.getRunTime()) + limit_s)
        self.highs.run()
        return self.highs.getModelStatus()


def vertex_basis(lp: LinearProgram, x: FloatArray) -> Any | None:
    """The HiGHS basis of the vertex nearest ``x`` (shape (n,)): the ``n`` rows and columns
    nearest a bound are nonbasic at it, the others basic.

    "Nearest" is the slack relative to the larger of the bound's size and ``x``'s
    largest entry (a bound of 0 has no size of its own).  From an interior-point
    answer converged to about 1e-9 this is the optimal basis: the slacks of the
    binding rows are 1e-7 or less, the others 1e-5 or more (at 1e-6 the two
    overlap, and HiGHS could not go on from the basis picked). HiGHS factorises
    the basis it is given and repairs a singular one, so a poor guess costs
    pivots, not the answer. None where fewer than ``n`` bounds are finite (no
    vertex).
    """
    assert _highspy is not None
    values = np.concatenate([x, lp.a @ x])
    lower = np.concatenate([lp.col_lower, lp.row_lower])
    upper = np.concatenate([lp.col_upper, lp.row_upper])
    size = np.maximum(_finite_abs(lower), _finite_abs(upper))
    scale = np.maximum(size, max(float(np.max(np.abs(x), initial=0.0)), 1e-300))
    below, above = (values - lower) / scale, (upper - values) / scale
    at_upper = above < below
    slack = np.where(at_upper, above, below)
    if np.count_nonzero(np.isfinite(slack)) < x.size:
        return None  # fewer bounds than columns: no vertex
    nonbasic = np.argpartition(slack, x.size - 1)[: x.size]
    codes = np.ones(values.size, dtype=np.intp)  # basic
    codes[nonbasic] = np.where(at_upper[nonbasic], 2, 0)
    status = _highspy.HighsBasisStatus
    table = np.array([status.kLower, status.kBasic, status.kUpper], dtype=object)
    basis = _highspy.HighsBasis()
    basis.col_status = table[codes[: x.size]].tolist()
    basis.row_status = table[codes[x.size :]].tolist()
    basis.valid = True
    return basis


def _finite_abs(x: FloatArray) -> FloatArray:
    """``|x|``, 0 where ``x`` is infinite."""
    return np.where(np.isfinite(x), np.abs(x), 0.0)


def _finite(x: FloatArray, inf: float) -> FloatArray:
    """``+-inf`` as HiGHS's infinity."""
    return np.where(np.isposinf(x), inf, np.where(np.isneginf(x), -inf, x))
