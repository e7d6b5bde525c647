"""The grid problem with jerk rows, solved by the banded interior-point method.

:class:`BandedGrid` answers the grid LP's :class:`~.rows.GridSolver` calls:
a problem whose jerk rows are all free (the first, jerk-free solve) goes to
the reachability passes (:mod:`.reach`), every other one to the banded
interior-point method (:mod:`.banded`). The HiGHS LP (:class:`.rows._GridLP`)
is built only if one of them does not answer (passes that do not settle, an
interior-point solve that does not converge).

The rows are the LP's own (:func:`~.rows._acc_matrix`,
:func:`~.rows._jerk_matrix`), laid out per node: ``2 q`` acceleration rows
of interval ``i`` (its left and its right end, ``q`` components each) centred
on node ``i``, and ``q`` jerk rows centred on node ``i``; the row bounds come
in the LP's order and are mapped onto that layout.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from skyquill.coverage.deadline import Deadline
from skyquill.coverage.speed.active_rows import (
    KEEP,
    Mask,
    nearest_rows,
    row_ratios,
    solve_active_rows,
)
from skyquill.coverage.speed.banded import (
    TOLERANCE,
    BandedRows,
    BandedSolution,
    solve_banded_lp,
)
from skyquill.coverage.speed.reach import AccelerationRows, ReachPass
from skyquill.coverage.speed.rows import _GridLP, jerk_coefficients
from skyquill.validation import FloatArray

_log = logging.getLogger(__name__)
#: Relative gap of the pseudo-jerk iterates (the iteration stops at a change of 1e-3 of
#: ``sqrt(b)``; the certification LP is solved to :data:`~.banded.TOLERANCE`).
ROUGH_TOLERANCE = 1e-6


#: Rows of each block per node (of a polygon's directions) HiGHS is given at first with
#: ``hand_over``; the rows an answer breaks are added (:class:`~.rows._GridLP`). An added
#: row costs a re-solve of a few pivots, a row held costs every solve: the eleven largest
#: speed plans of ``holes_1_3ha`` took 3.8 / 3.9 / 4.4 s with 1 / 2 / 3 held (all 8: 5.6 s),
#: the fifteen of ``holes_10ha`` 5.4 s with 1 and 6.4 s with 3 (the same flights).
HELD = 1
#: Decimals of the ratios (row over bound) by which the rows held are picked.
RATIO_DECIMALS = 6


def banded_rows(
    acc: AccelerationRows,
    derivs: tuple[FloatArray, FloatArray, FloatArray],
    jmax: FloatArray,
    scale: FloatArray,
) -> BandedRows:
    """The grid LP's rows (acceleration, then pseudo-jerk) in the per-node layout.

    Parameters
    ----------
    acc : AccelerationRows
        The acceleration rows, ``2 q`` per interval.
    derivs : tuple of ndarray, shape (n, q)
        The limited components of ``C'``, ``C''``, ``C'''``.
    jmax : ndarray, shape (q,)
        Each component's jerk bound.
    scale : ndarray, shape (n,)
        The jerk rows' speed-like reference (as in :func:`~.rows._jerk_matrix`).

    Returns
    -------
    BandedRows
        ``R = 3 q`` rows per node.
    """
    n, q = derivs[0].shape
    rows = 3 * q
    lower, centre, upper = (np.zeros((rows, n)) for _ in range(3))
    centre[: 2 * q, :-1] = acc.alpha.T
    upper[: 2 * q, :-1] = acc.beta.T
    cm, cc, cp = jerk_coefficients(derivs)
    factor = np.sqrt(scale[1:-1])[:, None] / jmax
    lower[2 * q :, 1:-1] = (cm * factor).T
    centre[2 * q :, 1:-1] = (cc * factor).T
    upper[2 * q :, 1:-1] = (cp * factor).T
    return BandedRows(lower=lower, centre=centre, upper=upper)


def row_bounds(r: FloatArray, n: int, q: int) -> FloatArray:
    """The LP's row bounds (acceleration blocks of ``n - 1``, jerk blocks of ``n - 2``) per
    node, shape (3 q, n); rows that do not exist are free (``inf``)."""
    out = np.full((3 * q, n), np.inf)
    acc = 2 * q * (n - 1)
    out[: 2 * q, :-1] = r[:acc].reshape(2 * q, n - 1)
    if r.size > acc:
        out[2 * q :, 1:-1] = r[acc:].reshape(q, n - 2)
    return out


def lp_rows(mask: Mask, q: int) -> NDArray[np.intp]:
    """The LP's indices of the rows of ``mask`` (3 q, n), the per-node layout (the inverse of
    :func:`row_bounds`: ``2 q`` acceleration blocks of ``n - 1`` rows, then ``q`` jerk blocks
    of ``n - 2``), ascending."""
    n = mask.shape[1]
    acc = np.flatnonzero(mask[: 2 * q, :-1])
    jerk = np.flatnonzero(mask[2 * q :, 1:-1]) + 2 * q * (n - 1)
    return np.concatenate([acc, jerk])


class BandedGrid:
    """The grid problem behind the LP's interface: passes without jerk, the banded interior
    point with it, the HiGHS LP for what neither answers.

    With ``hand_over`` (``method="warm"``), the interior point answers only the
    first problem with jerk rows, and the HiGHS LP every one after it, started
    from the basis of that answer's vertex and hot-started from its own basis
    after that. That first problem is the jump from the jerk-free optimum to a
    jerk-limited one: from the jerk-free basis the simplex needs thousands of
    pivots for it (a coverage piece: 4,140 pivots, 0.76 s, most of its plan),
    while every later problem moves the bounds a little and is re-solved in a
    few hundred pivots at most, where the interior point starts from scratch.

    Parameters
    ----------
    acc : AccelerationRows
        The acceleration rows (for the passes).
    rows : BandedRows
        Every row in the per-node layout.
    lp : callable
        Builds the HiGHS grid LP (the fallback; with ``hand_over``, the solver) on all
        rows (None) or on the LP's rows given (:class:`~.rows._GridLP`).
    deadline : Deadline, optional
        Checked before every solve.
    hand_over : bool, default False
        Hand the problems over to the HiGHS LP after the first with jerk rows.
    """

    def __init__(
        self,
        acc: AccelerationRows,
        rows: BandedRows,
        lp: Callable[[NDArray[np.intp] | None], _GridLP],
        deadline: Deadline | None,
        *,
        hand_over: bool = False,
    ) -> None:
        self.hand_over = hand_over
        self._fell_back = False
        self.passes = ReachPass(acc)
        self.rows = rows
        self.q = rows.centre.shape[0] // 3
        self._build_lp = lp
        self._lp: _GridLP | None = None
        self.deadline = deadline
        self.ipm_time = 0.0
        self.ipm_solves = 0
        self.ipm_iterations = 0
        #: The last interior-point solution: the guess of the rows that bind in the next
        #: solve (the jerk-free optimum is no guess: it breaks most jerk rows).
        self._last: FloatArray | None = None

    @property
    def time(self) -> float:
        """Wall time of every solve, s."""
        return self.passes.time + self.ipm_time + (0.0 if self._lp is None else self._lp.time)

    @property
    def solves(self) -> int:
        """Problems solved (passes, interior point, LP)."""
        lp = 0 if self._lp is None else self._lp.solves
        return self.passes.solves + self.ipm_solves + lp

    @property
    def used_lp(self) -> bool:
        """Whether the HiGHS LP had to answer (a pass or an interior-point solve failed)."""
        return self._fell_back

    def solve(self, r: FloatArray, ub: FloatArray, *, rough: bool = False) -> FloatArray:
        """The optimum for the LP's row bounds ``r`` and ``0 <= b <= ub`` (to
        :data:`ROUGH_TOLERANCE` when ``rough``)."""
        if self.deadline is not None:
            self.deadline.check(f"speed solve {self.solves + 1}")
        if self.hand_over and self._lp is not None:
            return self._lp.solve(r, ub, restart=lambda: self._restart_point(r, ub))
        n = ub.size
        bound = row_bounds(r, n, self.q)
        if not np.any(np.isfinite(bound[2 * self.q :])):
            b = self.passes.solve(r[: n - 1], ub)
            if b is not None:
                return b
        # The LP's vertex is read from the answer: only a tight one tells it (vertex_basis).
        sol = self._interior(
            bound, ub, ROUGH_TOLERANCE if rough and not self.hand_over else TOLERANCE
        )
        if sol.status != "optimal":
            _log.info("banded interior point did not converge (%s); HiGHS answers", sol.status)
            return self._highs(r, ub)
        if not self.hand_over:
            return sol.b
        self._lp = self._build_lp(self._binding_rows(bound, sol.b))
        return self._lp.solve(r, ub, start=sol.b)

    def _binding_rows(self, bound: FloatArray, b: FloatArray) -> NDArray[np.intp] | None:
        """The LP's rows HiGHS is given at first: with a polygon's directions, the
        :data:`HELD` of each block nearest their bound at ``b`` (per-node bounds ``bound``
        (3 q, n)); None (all) otherwise.

        The ratios to the bounds are rounded to :data:`RATIO_DECIMALS` first: the last bits
        of the interior point's answer depend on the BLAS's threads (its dot products), and
        where directions tie (a node without acceleration: every ratio is round-off) they
        would pick the row held, and so the last bits of the plan: a piece planned in a
        pool worker (one BLAS thread) differed from the same piece planned here.
        """
        if self.q <= KEEP:
            return None
        ratio = np.round(row_ratios(self.rows, bound, b), RATIO_DECIMALS)
        return lp_rows(nearest_rows(ratio, 3, HELD), self.q)

    def _interior(self, bound: FloatArray, ub: FloatArray, tolerance: float) -> BandedSolution:
        """The interior point's answer for the per-node row bounds ``bound`` (3 q, n)."""
        start = time.perf_counter()
        if self._last is not None and self.q > KEEP:
            # A polygon's directions: only the few nearest the vector can bind.
            sol, solves = solve_active_rows(self.rows, bound, ub, guess=self._last, blocks=3,
                                            tolerance=tolerance)  # fmt: skip
        else:
            sol, solves = (
                solve_banded_lp(self.rows, bound, ub, np.ones(ub.size), tolerance=tolerance),
                1,
            )
        self.ipm_time += time.perf_counter() - start
        self.ipm_solves += solves
        self.ipm_iterations += sol.iterations
        if sol.status == "optimal":
            self._last = sol.b
        return sol

    def _restart_point(self, r: FloatArray, ub: FloatArray) -> FloatArray | None:
        """Where HiGHS's hot start stalled: the interior point's answer (None if it has
        none), whose vertex HiGHS starts again from."""
        sol = self._interior(row_bounds(r, ub.size, self.q), ub, TOLERANCE)
        return sol.b if sol.status == "optimal" else None

    def _highs(self, r: FloatArray, ub: FloatArray) -> FloatArray:
        """The HiGHS LP's answer where the passes or the interior point gave none."""
        self._fell_back = True
        if self._lp is None:
            self._lp = self._build_lp(None)
        return self._lp.solve(r, ub)
