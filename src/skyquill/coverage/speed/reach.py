"""The speed-and-acceleration grid problem by a backward and a forward reachability pass.

The grid LP without jerk rows (:mod:`.rows`) couples only neighbouring nodes:
every acceleration row of interval ``k`` reads ``|alpha x + beta y| <= r``
with ``x = b_k``, ``y = b_{k+1}``, and the speed, chord and rest-end limits
are column bounds ``0 <= b <= ub``.  This is the classical time-optimal path
parameterisation in ``b = s_dot**2`` (Bobrow; Pham & Pham's TOPP-RA): a
backward pass gives every node the largest ``b`` from which the rest of the
path can still be followed, a forward pass then takes the largest ``b`` each
step allows.

Why it is exact.  A row whose coefficients have opposite signs
(``alpha beta < 0``: the tangential part ``0.5 C' (y - x) / h`` dominates,
which is every row of a grid finer than the path's curvature) splits into two
*monotone* bounds, ``y <= g(x)`` and ``x <= f(y)`` with ``f``, ``g``
non-decreasing.  Constraints of that kind are closed under the element-wise
maximum, so the feasible set has a greatest element; it is the greatest fixed
point of ``b_k <= min(ub_k, f_k(b_{k+1}), g_{k-1}(b_{k-1}))``, which alternate
backward and forward sweeps reach from ``ub`` (one sweep each, in practice).
The greatest element maximises ``sum(b)``: it is the LP's optimum.

A row whose coefficients have the same sign (a direction almost normal to the
path at a sharp turn, where ``|C''| h > 0.5 |C'|`` along it) is not monotone.
It is replaced by the box ``max(x, y) <= r / (|alpha| + |beta|)``, which lies
inside it (``|alpha x + beta y| <= (|alpha| + |beta|) max(x, y)``): the plan
stays feasible for the LP and is at most the LP's optimum; the two differ only
where ``x != y`` on such a row (tests compare both durations; see
``docs/coverage-speed.md`` for the measured gap).

The passes are sequential; each step takes the minimum of a few affine
functions of the neighbour (pieces that cannot bind below the column bound
are dropped beforehand, vectorised), so a pass costs a few microseconds a node.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from skyquill.coverage.deadline import Deadline
from skyquill.coverage.speed.rows import _GridLP
from skyquill.validation import FloatArray

_log = logging.getLogger(__name__)
#: Per interval, the pieces' constants or slopes (Python floats, for the passes).
_Rows = list[list[float]]

#: Alternating sweeps before the passes give up (they converge in one in practice).
MAX_SWEEPS = 50
#: Piece changes a backward step may take to find its fixed point.
MAX_PIECE_STEPS = 16
#: Relative slack of the fixed-point check (round-off of the affine pieces).
FIXED_POINT_RTOL = 1e-12


@dataclass(frozen=True)
class AccelerationRows:
    """The grid's acceleration rows of every interval, ``|alpha x + beta y| <= r``.

    Attributes
    ----------
    alpha, beta : ndarray, shape (n - 1, m)
        Coefficients of ``x = b_k`` and ``y = b_{k+1}`` of the ``m`` rows of
        interval ``k`` (row bound 1 before the refinement's factors).
    """

    alpha: FloatArray
    beta: FloatArray


def acceleration_rows(
    p1: FloatArray, p2: FloatArray, h: float, limits: FloatArray
) -> AccelerationRows:
    """The rows of :func:`~skyquill.coverage.speed.rows._acc_matrix`, interval by interval.

    Parameters
    ----------
    p1, p2 : ndarray, shape (n, q)
        The limited components (axes, or projections on the polygon's normals)
        of ``C'`` and ``C''`` at the grid nodes.
    h : float
        Grid step in the planning parameter.
    limits : ndarray, shape (q,)
        Each component's bound.

    Returns
    -------
    AccelerationRows
        ``m = 2 q`` rows per interval: each component at the interval's left
        end and at its right end, both with the interval's slope.
    """
    half = 0.5 / h
    left_a = (p2[:-1] - half * p1[:-1]) / limits
    left_b = half * p1[:-1] / limits
    right_a = -half * p1[1:] / limits
    right_b = (p2[1:] + half * p1[1:]) / limits
    return AccelerationRows(alpha=np.hstack([left_a, right_a]), beta=np.hstack([left_b, right_b]))


@dataclass(frozen=True)
class _Pieces:
    """Monotone bounds ``b_k <= min_j(f_c + f_s b_{k+1})``, ``b_{k+1} <= min_j(g_c + g_s b_k)``.

    Arrays of shape (n - 1, m) with slopes >= 0, idle pieces at ``c = inf``;
    ``ub`` holds the column bounds tightened by the boxes of the non-monotone
    rows.
    """

    f_c: FloatArray
    f_s: FloatArray
    g_c: FloatArray
    g_s: FloatArray
    ub: FloatArray

    def rows(self) -> tuple[_Rows, _Rows, _Rows, _Rows]:
        """``f_c, f_s, g_c, g_s`` as lists of rows for the passes, binding pieces first, cut to
        the most any row has."""
        out = []
        for c, s in ((self.f_c, self.f_s), (self.g_c, self.g_s)):
            finite = np.isfinite(c)
            keep = np.argsort(~finite, axis=1, kind="stable")[:, : max(int(finite.sum(1).max()), 1)]
            out += [
                np.take_along_axis(c, keep, 1).tolist(),
                np.take_along_axis(s, keep, 1).tolist(),
            ]
        return out[0], out[1], out[2], out[3]


def _pieces(rows: AccelerationRows, r: FloatArray, ub: FloatArray) -> _Pieces:
    """Split every row into monotone bounds (boxes for the non-monotone ones), drop the idle."""
    sign = np.where(rows.beta < 0.0, -1.0, 1.0)
    a = rows.alpha * sign  # the row as a x + b y with b >= 0
    b = np.abs(rows.beta)
    rr = np.broadcast_to(np.asarray(r, dtype=np.float64)[:, None], a.shape)
    inf = np.inf
    with np.errstate(divide="ignore", invalid="ignore"):
        monotone = (a <= 0.0) | (b == 0.0)
        # y <= (r - a x) / b: a y-bound increasing in x (b > 0); b == 0 bounds x alone.
        g_c = np.where(monotone & (b > 0.0), rr / b, inf)
        g_s = np.where(monotone & (b > 0.0), -a / b, 0.0)
        # -r <= a x + b y with a < 0: x <= (r + b y) / |a|.
        f_c = np.where(monotone & (a < 0.0), rr / -a, inf)
        f_s = np.where(monotone & (a < 0.0), b / -a, 0.0)
        box = np.where(monotone, inf, rr / (np.abs(a) + b))
        x_box = np.where(b == 0.0, rr / np.abs(a), inf)
    ub = ub.copy()
    ub[:-1] = np.minimum(ub[:-1], np.min(np.minimum(box, x_box), axis=1))
    ub[1:] = np.minimum(ub[1:], np.min(box, axis=1))
    g_c, g_s = _binding(g_c, g_s, ub[:-1], ub[1:])
    f_c, f_s = _binding(f_c, f_s, ub[1:], ub[:-1])
    return _Pieces(f_c=f_c, f_s=f_s, g_c=g_c, g_s=g_s, ub=ub)


def _binding(
    c: FloatArray, s: FloatArray, domain: FloatArray, cap: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """The pieces ``c + s t`` (n - 1, m) that can give the minimum for ``t`` in ``[0, domain]``.

    A piece is dropped (``c = inf``) where it is >= ``cap`` at ``t = 0`` (its
    least value: it never binds), or where another piece is no larger at both
    ends of the domain (lines: then nowhere larger in between). The survivors
    are the Pareto front of (value at 0, value at ``domain``): in the order of
    the value at 0, each one lower at ``domain`` than all before it.
    """
    c = np.where(c >= cap[:, None], np.inf, c)
    hi = c + s * domain[:, None]
    order = np.argsort(c, axis=1, kind="stable")
    hi_sorted = np.take_along_axis(hi, order, 1)
    before = np.minimum.accumulate(hi_sorted, axis=1)
    front = np.ones_like(hi_sorted, dtype=bool)
    front[:, 1:] = hi_sorted[:, 1:] < before[:, :-1]
    keep = np.zeros_like(front)
    np.put_along_axis(keep, order, front, 1)
    idle = ~keep | ~np.isfinite(c)
    return np.where(idle, np.inf, c), np.where(idle, 0.0, s)


def _backward(b: list[float], f_c: _Rows, f_s: _Rows, g_c: _Rows, g_s: _Rows) -> None:
    """The largest ``b_k`` from which node ``k + 1`` stays within its bound, from the end.

    ``b_k <= f_k(b_{k+1})`` alone is not enough: the step forward from
    ``b_k`` must also reach a ``y <= g_k(b_k)`` whose own ``f_k(y)`` still
    admits ``b_k``. The largest such ``b_k`` is the fixed point of
    ``x -> f_k(min(b_{k+1}, g_k(x)))``, found piece by piece (the map is
    concave and non-decreasing, and is >= x at 0). Inner loops are written
    out: a pass costs a few microseconds a node.
    """
    y = b[-1]
    for k in range(len(f_c) - 1, -1, -1):
        fc, fs, gc, gs = f_c[k], f_s[k], g_c[k], g_s[k]
        x = b[k]
        for c, s in zip(fc, fs, strict=True):
            v = c + s * y
            if v < x:  # noqa: PLR1730 (a call to min() per piece doubles the pass)
                x = v
        reach = y
        for c, s in zip(gc, gs, strict=True):
            v = c + s * x
            if v < reach:  # noqa: PLR1730
                reach = v
        if reach < y:  # the step forward from x falls short of y: is x still allowed?
            back = x
            for c, s in zip(fc, fs, strict=True):
                v = c + s * reach
                if v < back:  # noqa: PLR1730
                    back = v
            if back < x:
                x = _fixed_point(x, y, (fc, fs), (gc, gs))
        b[k] = x
        y = x


def _fixed_point(
    x: float, y: float, f: tuple[list[float], list[float]], g: tuple[list[float], list[float]]
) -> float:
    """The largest ``x' <= x`` with ``x' <= f(min(y, g(x')))``, piece by piece (the map is
    concave, non-decreasing and >= x' at 0: the fixed point of its active pieces is below)."""
    fc, fs = f
    gc, gs = g
    for _ in range(MAX_PIECE_STEPS):
        reach, jg = y, -1
        for j, (c, s) in enumerate(zip(gc, gs, strict=True)):
            v = c + s * x
            if v < reach:
                reach, jg = v, j
        back, jf = x, -1
        for j, (c, s) in enumerate(zip(fc, fs, strict=True)):
            v = c + s * reach
            if v < back:
                back, jf = v, j
        if jf < 0:
            return x  # f(min(y, g(x))) >= x: consistent
        if jg < 0:  # g(x) >= y: f(y) is the bound
            x = back
            continue
        den = 1.0 - fs[jf] * gs[jg]
        x = min(max((fc[jf] + fs[jf] * gc[jg]) / den, 0.0), back) if den > 0.0 else back
    return x


def _forward(b: list[float], g_c: _Rows, g_s: _Rows) -> None:
    """``b_{k+1} <= g_k(b_k)`` from the start (in place)."""
    x = b[0]
    for k in range(len(g_c)):
        y = b[k + 1]
        for c, s in zip(g_c[k], g_s[k], strict=True):
            v = c + s * x
            if v < y:  # noqa: PLR1730
                y = v
        b[k + 1] = y
        x = y


def _violated(b: FloatArray, p: _Pieces) -> bool:
    """Whether ``b`` breaks a monotone bound by more than round-off."""
    tol = FIXED_POINT_RTOL * max(float(np.max(b)), 1e-300)
    f = np.min(p.f_c + p.f_s * b[1:, None], axis=1)
    g = np.min(p.g_c + p.g_s * b[:-1, None], axis=1)
    return bool(np.any(b[:-1] > f + tol) or np.any(b[1:] > g + tol))


class ReachPass:
    """The speed-and-acceleration problem solved by reachability passes, re-solved as bounds move.

    Parameters
    ----------
    rows : AccelerationRows
        The grid's acceleration rows.
    """

    def __init__(self, rows: AccelerationRows) -> None:
        self.rows = rows
        self.time = 0.0
        self.solves = 0
        self.sweeps = 0

    def solve(self, acc: FloatArray, ub: FloatArray) -> FloatArray | None:
        """The greatest ``b`` with ``0 <= b <= ub`` inside the rows scaled by ``acc`` (n - 1,).

        Returns None when the sweeps do not settle within :data:`MAX_SWEEPS`
        (the caller then solves the LP).
        """
        start = time.perf_counter()
        pieces = _pieces(self.rows, acc, np.maximum(ub, 0.0))
        f_c, f_s, g_c, g_s = pieces.rows()
        values = pieces.ub.tolist()
        settled = False
        for _ in range(MAX_SWEEPS):
            self.sweeps += 1
            _backward(values, f_c, f_s, g_c, g_s)
            _forward(values, g_c, g_s)
            if not _violated(np.asarray(values), pieces):
                settled = True
                break
        self.solves += 1
        self.time += time.perf_counter() - start
        if not settled:
            _log.info("reachability passes did not settle in %d sweeps", MAX_SWEEPS)
            return None
        return np.maximum(np.asarray(values, dtype=np.float64), 0.0)


class ReachGrid:
    """The jerk-free grid problem behind the grid LP's interface (:class:`.rows._GridLP`).

    :meth:`solve` takes the LP's row bounds (the acceleration factors, one
    block per row kind) and column bounds; the passes answer, and the LP,
    built only then, answers what they do not settle.

    Parameters
    ----------
    rows : AccelerationRows
        The grid's acceleration rows.
    lp : callable
        Builds the grid LP (the fallback).
    deadline : Deadline, optional
        Checked before every solve.
    """

    def __init__(
        self, rows: AccelerationRows, lp: Callable[[], _GridLP], deadline: Deadline | None
    ) -> None:
        self.passes = ReachPass(rows)
        self._build_lp = lp
        self._lp: _GridLP | None = None
        self.deadline = deadline

    @property
    def time(self) -> float:
        """Wall time of the passes and any LP solve, s."""
        return self.passes.time + (0.0 if self._lp is None else self._lp.time)

    @property
    def solves(self) -> int:
        """Problems solved (passes and LPs)."""
        return self.passes.solves + (0 if self._lp is None else self._lp.solves)

    @property
    def used_lp(self) -> bool:
        """Whether the LP had to answer."""
        return self._lp is not None

    def solve(self, r: FloatArray, ub: FloatArray, *, rough: bool = False) -> FloatArray:
        """The optimum for row bounds ``r`` (acceleration factors first) and ``b <= ub``
        (``rough`` is not used: the passes are exact)."""
        if self.deadline is not None:
            self.deadline.check(f"speed pass {self.solves + 1}")
        b = self.passes.solve(r[: ub.size - 1], ub)
        if b is not None:
            return b
        if self._lp is None:
            self._lp = self._build_lp()
        return self._lp.solve(r, ub)
