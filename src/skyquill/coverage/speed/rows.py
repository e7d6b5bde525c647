"""The grid LP: its constraint rows, row and column bounds, and the solve."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray
from scipy import sparse

from skyquill.coverage.deadline import TIME_LIMIT, Deadline
from skyquill.errors import InfeasibleError, SolverError
from skyquill.solvers.lp import LinearProgram
from skyquill.validation import FloatArray


def _acc_matrix(u: FloatArray, derivs: tuple[FloatArray, FloatArray], amax: FloatArray) -> Any:
    """Rows ``(C'' b + 0.5 C' b') / amax`` of the piecewise-linear-``b`` model (bound ``|.| <= 1``).

    Every interval is checked at its two ends, each with the interval's own
    slope ``b' = (b_{k+1} - b_k) / h``.  Rows are ordered (left end, right
    end) x axis, ``n - 1`` rows each.  (Midpoint rows change the optimum by
    ~1e-6 relative on the spiral but cost ~40 % of every simplex pivot; an
    excess between the nodes is left to the refinement.)
    """
    c1, c2 = derivs
    n, d = c1.shape
    h = u[1] - u[0]
    k_idx = np.arange(n - 1)
    ri = np.concatenate([k_idx, k_idx])
    ci = np.concatenate([k_idx, k_idx + 1])
    rows = []
    for p1, p2, wl in ((c1[:-1], c2[:-1], 1.0), (c1[1:], c2[1:], 0.0)):
        left = p2 * wl - 0.5 * p1 / h
        right = p2 * (1.0 - wl) + 0.5 * p1 / h
        for ax in range(d):
            data = np.concatenate([left[:, ax], right[:, ax]]) / amax[ax]
            rows.append(sparse.csr_array((data, (ri, ci)), shape=(n - 1, n)))
    return sparse.vstack(rows, format="csr")


def _jerk_matrix(
    derivs: tuple[FloatArray, FloatArray, FloatArray], jmax: FloatArray, scale: FloatArray
) -> Any:
    """Pseudo-jerk rows ``sqrt(scale_i) X_i(b) / jmax`` at the interior nodes, axis by axis.

    ``X_i = C3 b_i + 1.5 C2 (b_{i+1} - b_{i-1}) / (2h)
    + 0.5 C1 (b_{i+1} - 2 b_i + b_{i-1}) / h**2`` with ``Ck`` the k-th
    derivative of the curve.  The linearisation ``sqrt(ref_i) |X_i| <= jmax``
    becomes the row bound ``sqrt(scale_i / ref_i)``, so the iteration only
    changes bounds; ``scale`` (a fixed speed-like reference) keeps the rows
    well scaled.
    """
    n, d = derivs[0].shape
    i_idx = np.arange(1, n - 1)
    cm, cc, cp = jerk_coefficients(derivs)
    r = np.sqrt(scale[1:-1])
    ri = np.tile(np.arange(n - 2), 3)
    ci = np.concatenate([i_idx - 1, i_idx, i_idx + 1])
    blocks = []
    for ax in range(d):
        sc = r / jmax[ax]
        data = np.concatenate([cm[:, ax] * sc, cc[:, ax] * sc, cp[:, ax] * sc])
        blocks.append(sparse.csr_array((data, (ri, ci)), shape=(n - 2, n)))
    return sparse.vstack(blocks, format="csr")


def jerk_coefficients(
    derivs: tuple[FloatArray, FloatArray, FloatArray],
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Coefficients of ``b_{i-1}``, ``b_i``, ``b_{i+1}`` in ``X_i`` at the interior nodes.

    ``X_i = C3 b_i + 1.5 C2 (b_{i+1} - b_{i-1}) / (2h) + 0.5 C1 (b_{i+1} - 2 b_i + b_{i-1})
    / h**2`` on the uniform grid of ``[0, 1]`` (``h = 1 / (n - 1)``).

    Parameters
    ----------
    derivs : tuple of ndarray, shape (n, q)
        ``C'``, ``C''``, ``C'''`` (or their limited components) at the nodes.

    Returns
    -------
    tuple of ndarray, shape (n - 2, q)
        The three coefficients of every component at nodes ``1 .. n - 2``.
    """
    c1, c2, c3 = derivs
    h = 1.0 / (c1.shape[0] - 1)
    cm = -1.5 * c2[1:-1] / (2 * h) + 0.5 * c1[1:-1] / h**2
    cc = c3[1:-1] - c1[1:-1] / h**2
    cp = 1.5 * c2[1:-1] / (2 * h) + 0.5 * c1[1:-1] / h**2
    return cm, cc, cp


@dataclass
class _Bounds:
    """Row and column bounds of the grid LP, with the per-node refinement factors.

    ``acc`` (per interval), ``jerk`` and ``speed`` (per node) multiply the
    limits handed to the LP; they start at 1 and are lowered where the
    time-domain check finds an excess.
    """

    ub: FloatArray
    jerk_ref: FloatArray | None
    d: int
    acc: FloatArray
    jerk: FloatArray
    speed: FloatArray

    def rows(self, ref: FloatArray | None) -> FloatArray:
        """Row bounds; ``ref`` is the pseudo-jerk linearisation point (None: jerk rows free)."""
        acc = np.tile(self.acc, 2 * self.d)
        if self.jerk_ref is None:
            return acc
        if ref is None:
            return np.concatenate([acc, np.full(self.d * (self.ub.size - 2), np.inf)])
        r = ref[1:-1]
        with np.errstate(divide="ignore"):
            jr = np.where(r > 0.0, self.jerk[1:-1] * np.sqrt(self.jerk_ref[1:-1] / r), np.inf)
        return np.concatenate([acc, np.tile(jr, self.d)])

    def cols(self) -> FloatArray:
        """Column upper bounds (speed/chord limits, rest ends, refinement)."""
        return self.ub * self.speed**2


def _ones(n: int) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Initial refinement factors: acceleration per interval, jerk and speed per node."""
    return np.ones(n - 1), np.ones(n), np.ones(n)


def _speed_bounds(
    c1: FloatArray, c2: FloatArray, vmax: float, *, chord_error: float | None, period: float
) -> tuple[FloatArray, FloatArray]:
    """Column bounds from the speed (and chord-error) limit, and ``vmax**2 / |C'|**2``."""
    speed2 = np.sum(c1 * c1, axis=1)
    ub = vmax**2 / speed2
    vb = ub.copy()
    if chord_error is not None:
        cross2 = np.maximum(speed2 * np.sum(c2 * c2, axis=1) - np.sum(c1 * c2, axis=1) ** 2, 0.0)
        with np.errstate(divide="ignore"):
            rho = np.where(cross2 > 0.0, speed2**1.5 / np.sqrt(cross2), np.inf)
        ub = np.minimum(ub, 8.0 * rho * float(chord_error) / period**2 / speed2)
    ub[0] = 0.0
    ub[-1] = 0.0
    return ub, vb


def _end_caps(ub: FloatArray, c1: FloatArray, jmax: FloatArray) -> None:
    """Cap ``b`` at nodes 1 and ``n - 2`` so the rest-end acceleration ramps at <= jmax.

    The first/last interval is crossed in ``dt = 2h / sqrt(b_1)`` with
    acceleration ``0.5 C' b_1 / h`` that must build up from 0 at <= jmax:
    ``0.5 |C'_k| b_1 / h <= jmax_k * 2 h / sqrt(b_1)``.
    """
    n = ub.size
    h = 1.0 / (n - 1)
    for node in (1, n - 2):
        with np.errstate(divide="ignore"):
            cap = (4.0 * jmax * h * h / np.abs(c1[node])) ** (2.0 / 3.0)
        ub[node] = min(ub[node], float(np.min(cap)))


class GridSolver(Protocol):
    """What solves the grid problem for given bounds: the LP, or the reachability passes."""

    @property
    def time(self) -> float:
        """Wall time spent solving, s."""
        ...

    @property
    def solves(self) -> int:
        """Problems solved."""
        ...

    def solve(self, r: FloatArray, ub: FloatArray, *, rough: bool = False) -> FloatArray:
        """``b`` for row bounds ``|A b| <= r`` and column bounds ``0 <= b <= ub``; ``rough``:
        an iterate of a fixed-point iteration, which a solver may answer less precisely."""
        ...


class _GridLP:
    """``max sum(b)`` s.t. ``|A b| <= r`` row-wise, ``0 <= b <= ub``; re-solved as bounds change.

    One :class:`~skyquill.solvers.lp.LinearProgram` (hot-started with
    highspy) for the whole plan: a pseudo-jerk iteration or a refinement round
    only changes bounds.

    With ``rows``, HiGHS holds only those rows of ``A`` (the ones that can
    bind); every answer is checked against all of them, and a row it breaks is
    added and the problem solved again (a dual-simplex hot start), until none
    is broken: the optimum of the rows held that breaks no other row is the
    optimum of the whole LP. With a norm limit held by a 16-gon, few of its 8
    directions per node can bind (:data:`~.banded_grid.HELD`); HiGHS's cost per
    solve, even one without a pivot (4.7 ms at 48,000 rows), and per pivot
    grows with its rows.
    """

    def __init__(
        self,
        a: Any,
        *,
        backend: str,
        deadline: Deadline | None = None,
        rows: NDArray[np.intp] | None = None,
    ) -> None:
        self.deadline = deadline
        self.a = sparse.csr_array(a)
        self.rows = rows
        held = self.a if rows is None else self.a[rows]
        self.lp = LinearProgram(held, -np.ones(a.shape[1]), backend=backend)
        self._outside = None if rows is None else np.ones(a.shape[0], dtype=bool)
        if self._outside is not None:
            self._outside[rows] = False

    @property
    def time(self) -> float:
        """Wall time spent in the LP solver, s."""
        return self.lp.solve_time_s

    @property
    def solves(self) -> int:
        """LPs solved."""
        return self.lp.solves

    def solve(
        self,
        r: FloatArray,
        ub: FloatArray,
        *,
        rough: bool = False,
        start: FloatArray | None = None,
        restart: Callable[[], FloatArray | None] | None = None,
    ) -> FloatArray:
        """Solve with row bounds ``-r <= A b <= r`` (``inf`` = free row) and ``b <= ub``; from
        the basis of the vertex nearest ``start`` (shape (n,)) if given, and from the one
        nearest ``restart()`` where the hot start stalls
        (:meth:`~skyquill.solvers.lp.LinearProgram.solve`).

        With a deadline, no solve is started once it is spent, nor given more
        than what is left of it.
        """
        b = self._solve(r, ub, start, restart)
        while (broken := self._broken(r, b)).size:
            self._hold(broken, r)
            b = self._solve(r, ub, None, restart)
        return b

    def _hold(self, rows: NDArray[np.intp], r: FloatArray) -> None:
        """Give HiGHS the rows ``rows`` of ``A`` too, with their bounds in ``r``."""
        assert self.rows is not None and self._outside is not None
        self.lp.add_rows(self.a[rows], -r[rows], r[rows])
        self.rows = np.concatenate([self.rows, rows])
        self._outside[rows] = False

    def _broken(self, r: FloatArray, b: FloatArray) -> NDArray[np.intp]:
        """The rows HiGHS does not hold that ``b`` breaks by more than its own feasibility
        tolerance (relative, :data:`ROW_TOLERANCE`)."""
        if self._outside is None:
            return np.zeros(0, dtype=np.intp)
        excess = np.abs(self.a @ b) > r * (1.0 + ROW_TOLERANCE)
        return np.flatnonzero(excess & self._outside)

    def _solve(
        self,
        r: FloatArray,
        ub: FloatArray,
        start: FloatArray | None,
        restart: Callable[[], FloatArray | None] | None,
    ) -> FloatArray:
        """One solve on the rows HiGHS holds."""
        step = f"speed LP solve {self.lp.solves + 1}"
        if self.deadline is not None:
            self.deadline.check(step)
            self.lp.time_limit_s = max(self.deadline.remaining(), 1e-3)
        held = r if self.rows is None else r[self.rows]
        self.lp.update_bounds(row_lower=-held, row_upper=held, col_upper=ub)
        sol = self.lp.solve(start, restart)
        if sol.status == "time_limit" and self.deadline is not None:
            self.deadline.check(step)  # spent: raises with the step's name
            raise InfeasibleError(f"time_limit: stopped at {step}", (TIME_LIMIT,))
        if sol.status == "infeasible":
            raise InfeasibleError("speed-planning LP is infeasible", ("speed_lp",))
        if sol.x is None:
            raise SolverError(f"HiGHS failed on the speed-planning LP: {sol.message}")
        return sol.x


#: A row HiGHS does not hold counts as broken beyond this excess over its bound, relative
#: (HiGHS's own primal feasibility tolerance, 1e-7, applies to the rows it holds).
ROW_TOLERANCE = 1e-7
