"""The grid problem with jerk rows, solved by the pairs method (:mod:`.pairs`).

:class:`PairsGrid` answers the grid LP's :class:`~.rows.GridSolver` calls: a problem whose
jerk rows are all free (the first, jerk-free solve) goes to the reachability passes
(:mod:`.reach`), every other one to the controllable polygons of :mod:`.pairs`. The HiGHS
LP (:class:`.rows._GridLP`) is built only if one of them does not answer (passes that do
not settle; a pairs answer that stops the vehicle at an interior node, which the LP may
avoid).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable

import numpy as np

from skyquill.coverage.deadline import Deadline
from skyquill.coverage.speed.reach import AccelerationRows, ReachPass
from skyquill.coverage.speed.rows import _GridLP, jerk_coefficients
from skyquill.validation import FloatArray

_log = logging.getLogger(__name__)
#: Pseudo-jerk iterations without a new smallest change after which the iteration stops
#: (the greedy answers settle to a small cycle, see :func:`~.iteration._pseudo_jerk`).
PATIENCE = 3
#: Largest row excess of a pairs answer taken (scaled away: round-off of the Fourier-Motzkin
#: rows, up to 2e-5 at 8,000 points); past it (a fault of the polygons) HiGHS answers.
EXCESS_RTOL = 1e-2


class PairsGrid:
    """The grid problem behind the LP's interface: passes without jerk, the pairs method with
    it, the HiGHS LP for what neither answers.

    Parameters
    ----------
    acc : AccelerationRows
        The acceleration rows, ``2 q`` per interval.
    derivs : tuple of ndarray, shape (n, q)
        The limited components of ``C'``, ``C''``, ``C'''``.
    jmax : ndarray, shape (q,)
        Each component's jerk bound.
    scale : ndarray, shape (n,)
        The jerk rows' speed-like reference (as in :func:`~.rows._jerk_matrix`): the LP's
        jerk row bound ``r`` is ``|X / jmax| <= r / sqrt(scale)`` here.
    lp : callable
        Builds the HiGHS grid LP (the fallback).
    deadline : Deadline, optional
        Checked before every solve.
    """

    def __init__(
        self,
        acc: AccelerationRows,
        derivs: tuple[FloatArray, FloatArray, FloatArray],
        jmax: FloatArray,
        scale: FloatArray,
        *,
        lp: Callable[[], _GridLP],
        deadline: Deadline | None,
    ) -> None:
        self.passes = ReachPass(acc)
        self.acc = acc
        cm, cc, cp = jerk_coefficients(derivs)
        self.jerk = (cm / jmax, cc / jmax, cp / jmax)
        self.root = np.sqrt(scale[1:-1])
        self.q = cm.shape[1]
        self._build_lp = lp
        self._lp: _GridLP | None = None
        self.deadline = deadline
        self.pairs_time = 0.0
        self.pairs_solves = 0
        # Imported here: numba takes 0.6 s to import, which no other method should pay.
        from skyquill.coverage.speed.pairs import solve_pairs

        self._solve_pairs = solve_pairs

    @property
    def time(self) -> float:
        """Wall time of every solve, s."""
        return self.passes.time + self.pairs_time + (0.0 if self._lp is None else self._lp.time)

    @property
    def solves(self) -> int:
        """Problems solved (passes, pairs, LP)."""
        lp = 0 if self._lp is None else self._lp.solves
        return self.passes.solves + self.pairs_solves + lp

    @property
    def used_lp(self) -> bool:
        """Whether the HiGHS LP had to answer."""
        return self._lp is not None

    def solve(self, r: FloatArray, ub: FloatArray, *, rough: bool = False) -> FloatArray:
        """A feasible ``b`` for the LP's row bounds ``r`` and ``0 <= b <= ub`` (``rough`` is
        not used: every answer holds every row)."""
        if self.deadline is not None:
            self.deadline.check(f"speed solve {self.solves + 1}")
        n, q = ub.size, self.q
        split = 2 * q * (n - 1)
        jerk_r = r[split:]
        if not np.any(np.isfinite(jerk_r)):
            b = self.passes.solve(r[: n - 1], ub)
            if b is not None:
                return b
        else:
            start = time.perf_counter()
            acc_r = r[:split].reshape(2 * q, n - 1).T
            lim = jerk_r.reshape(q, n - 2).T / self.root[:, None]
            acc_rows = (self.acc.alpha, self.acc.beta, acc_r)
            b, excess = self._solve_pairs(acc_rows, (*self.jerk, lim), ub)
            self.pairs_time += time.perf_counter() - start
            self.pairs_solves += 1
            if excess > 1.0 + EXCESS_RTOL:
                _log.warning("the pairs method broke a row by %.3g; HiGHS answers", excess - 1.0)
            elif np.all(b[1:-1] > 0.0) or not np.all(ub[1:-1] > 0.0):
                return b
            else:
                _log.warning("the pairs method stopped the vehicle at an interior node; "
                             "HiGHS answers")  # fmt: skip
        if self._lp is None:
            self._lp = self._build_lp()
        return self._lp.solve(r, ub)
