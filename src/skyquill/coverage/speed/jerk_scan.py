"""The jerk-limited grid problem by forward and backward scans, without a linear program.

The grid problem with a jerk limit (:mod:`.rows`) is the jerk-free one (speed,
chord and rest-end column bounds, acceleration rows between neighbours) plus,
at every interior node ``i`` and limited component ``c``, the jerk row

    sqrt(b_i) |cm b_{i-1} + cc b_i + cp b_{i+1}| <= factor_i

(coefficients already divided by the component's bound). The pseudo-jerk
iteration linearises ``sqrt(b_i)`` and solves a sequence of LPs. The scan
solves the same rows without an LP, by lowering ``b`` only:

1. **Upper envelope.** Every plan that holds the jerk rows holds the jerk-free
   ones, whose feasible set has a greatest element (:mod:`.reach`). So every
   feasible ``b`` lies below the jerk-free optimum ``U``, and the scan starts
   there.
2. **Scans.** A forward scan (nodes ``1 .. n - 2``) and a backward scan (the
   same from the end) visit every jerk row. A row that ``b`` breaks is repaired
   by lowering only the nodes whose coefficient pushes the row past its bound,
   from the highest value down (a water level ``t``: ``min(b_j, t)``). Where
   the acceleration grows too fast (the two outer coefficients positive, the
   centre negative) this lowers the higher neighbour: the node ahead while
   accelerating (forward scan), the node behind while braking (backward scan),
   both at a valley. Where it falls too fast (the centre coefficient
   positive) it lowers the centre node. ``sqrt(b_i)`` is taken at the value
   before the repair (the pseudo-jerk linearisation, updated at every visit):
   lowering ``b_i`` only lowers the true row, so the repair is conservative.
3. **Acceleration.** Lowering a node can break an acceleration row; the
   jerk-free passes, with the scanned ``b`` as column bounds, give the greatest
   plan below it that holds them again.

Steps 2 and 3 repeat until a round lowers no node by more than
:data:`SETTLE_RTOL` (relative to the largest ``b``), at most
:data:`MAX_ROUNDS` times.

**Termination.** Every step only lowers ``b`` and keeps ``b >= 0``, so the
rounds form a non-increasing sequence bounded below: it converges, and the
round cap bounds the work in any case.

**Feasibility.** Every row is homogeneous in ``b`` (the acceleration rows of
degree 1, the jerk rows of degree 3/2, the column bounds hold for any smaller
``b``). After the last round the largest excess ``e`` of any row is measured
and ``b`` is scaled by ``1 / (1 + e)`` (for the acceleration rows) or
``(1 + e)**(-2/3)`` (for the jerk rows), the smaller of both: then every row
holds, whatever the rounds reached. Tests check the result against the LP's
own sparse rows.

**Optimality.** The rows with jerk are not closed under the element-wise
maximum (the jerk-free ones are), so there is no greatest feasible plan and
the scan finds *a* feasible plan, not the LP's optimum. Tests bound its
duration against the LP's (``docs/coverage-speed.md`` gives the measured gap).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from skyquill.coverage.deadline import Deadline
from skyquill.coverage.speed.reach import AccelerationRows, ReachPass
from skyquill.coverage.speed.rows import _GridLP, jerk_coefficients
from skyquill.validation import FloatArray

#: Rounds (a forward scan, a backward scan, the acceleration passes) at most.
MAX_ROUNDS = 200
#: A round that lowers no node by more than this (relative to the largest ``b``) ends the
#: scan.
SETTLE_RTOL = 1e-6


@dataclass(frozen=True)
class JerkRows:
    """The grid's jerk rows ``sqrt(b_i) |cm b_{i-1} + cc b_i + cp b_{i+1}| <= 1``.

    Attributes
    ----------
    cm, cc, cp : ndarray, shape (n - 2, q)
        Coefficients of ``b_{i-1}``, ``b_i``, ``b_{i+1}`` at the interior nodes
        ``i = 1 .. n - 2``, each component divided by its jerk bound (m/s^3).
    """

    cm: FloatArray
    cc: FloatArray
    cp: FloatArray


def jerk_rows(derivs: tuple[FloatArray, FloatArray, FloatArray], limits: FloatArray) -> JerkRows:
    """The exact grid jerk rows of :func:`~.rows._jerk_matrix` (without its linearisation).

    Parameters
    ----------
    derivs : tuple of ndarray, shape (n, q)
        The limited components of ``C'``, ``C''``, ``C'''`` at the grid nodes.
    limits : ndarray, shape (q,)
        Each component's jerk bound.

    Returns
    -------
    JerkRows
        The rows, bound 1 before the refinement's factors.
    """
    cm, cc, cp = jerk_coefficients(derivs)
    return JerkRows(cm=cm / limits, cc=cc / limits, cp=cp / limits)


def jerk_ratio(b: FloatArray, rows: JerkRows) -> FloatArray:
    """``sqrt(b_i) max_c |X_ic(b)|`` at the interior nodes, shape (n - 2,): the true grid jerk
    over its bound (before the refinement's factors)."""
    x = rows.cm * b[:-2, None] + rows.cc * b[1:-1, None] + rows.cp * b[2:, None]
    return np.asarray(np.sqrt(b[1:-1]) * np.max(np.abs(x), axis=1), dtype=np.float64)


def acceleration_ratio(b: FloatArray, alpha: FloatArray, beta: FloatArray) -> FloatArray:
    """``max_j |alpha_j b_k + beta_j b_{k+1}|`` per interval, shape (n - 1,)."""
    return np.asarray(
        np.max(np.abs(alpha * b[:-1, None] + beta * b[1:, None]), axis=1), dtype=np.float64
    )


def _water_level(coef: list[float], vals: list[float], budget: float) -> float:
    """The level ``t`` with ``sum_j coef_j min(vals_j, t) = budget`` (``coef > 0``, ``budget``
    below the sum at ``t = max(vals)``): the highest nodes are lowered first."""
    order = sorted(range(len(vals)), key=lambda j: vals[j])
    below = 0.0  # sum of coef * val of the nodes under the level
    above = sum(coef)  # coefficients of the nodes at the level
    for j in order:
        t = (budget - below) / above
        if t <= vals[j]:
            return max(t, 0.0)
        below += coef[j] * vals[j]
        above -= coef[j]
    return max(vals)


def _repair(b: list[float], i: int, rows: tuple[list[float], list[float], list[float]],
            lim: float) -> bool:  # fmt: skip
    """Lower ``b_{i-1}``, ``b_i``, ``b_{i+1}`` (the highest first) until every component of the
    linear row ``|cm b_{i-1} + cc b_i + cp b_{i+1}| <= lim`` holds; whether any was lowered."""
    vals = [b[i - 1], b[i], b[i + 1]]
    changed = False
    for p, q, r in zip(*rows, strict=True):
        v = p * vals[0] + q * vals[1] + r * vals[2]
        if -lim <= v <= lim:
            continue
        s = 1.0 if v > lim else -1.0
        coefs = (s * p, s * q, s * r)
        pos = [j for j in range(3) if coefs[j] > 0.0]
        neg = sum(coefs[j] * vals[j] for j in range(3) if coefs[j] <= 0.0)
        t = _water_level([coefs[j] for j in pos], [vals[j] for j in pos], lim - neg)
        for j in pos:
            if vals[j] > t:
                vals[j] = t
        changed = True
    if changed:
        b[i - 1], b[i], b[i + 1] = vals
    return changed


def _sweep(b: list[float], rows: _ListRows, lim: list[float], todo: list[bool],
           order: range) -> None:  # fmt: skip
    """Repair the rows of the nodes in ``order`` that ``todo`` marks or that a repair just
    touched (in place)."""
    cm, cc, cp = rows
    step = order.step
    touched = 0
    for i in order:
        if not (todo[i - 1] or touched):
            continue
        touched = max(touched - 1, 0)
        if _repair(b, i, (cm[i - 1], cc[i - 1], cp[i - 1]), lim[i - 1]):
            touched = 2  # the next two rows ahead share a lowered node
    del step


def _lower_hull(v: FloatArray) -> FloatArray:
    """The greatest convex sequence below ``v`` (its lower convex hull on a unit grid)."""
    n = v.size
    hull: list[int] = []
    vals = v.tolist()
    for k in range(n):
        while len(hull) >= 2:
            a, c = hull[-2], hull[-1]
            # c lies on or above the chord from a to k: not a vertex of the lower hull.
            if (vals[c] - vals[a]) * (k - a) >= (vals[k] - vals[a]) * (c - a):
                hull.pop()
            else:
                break
        hull.append(k)
    return np.asarray(np.interp(np.arange(n), hull, v[hull]), dtype=np.float64)


def _concave_bounds(b: FloatArray, rows: JerkRows, lim: FloatArray) -> FloatArray:
    """``rho`` (n - 2,) with ``b_{i-1} - 2 b_i + b_{i+1} >= -rho_i`` the side of the jerk rows that
    limits how fast the acceleration falls, ``b``'s first-order terms taken at ``b``.

    Per component the row is ``A (b_{i-1} - 2 b_i + b_{i+1}) + E (b_{i+1} - b_{i-1}) + F b_i``
    (``A = (cm + cp) / 2``, the tangential term). Only the components whose ``|A|`` is at least
    :data:`DOMINANT` of the node's largest enter; the others are first-order rows, which the
    sweeps repair. ``inf`` where no component enters.
    """
    a = 0.5 * (rows.cm + rows.cp)
    e = 0.5 * (rows.cp - rows.cm)
    f = rows.cc + rows.cm + rows.cp
    mag = np.abs(a)
    s = np.sign(a)
    first = e * (b[2:] - b[:-2])[:, None] + f * b[1:-1, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        rho = (lim[:, None] + s * first) / mag
    dominant = mag >= DOMINANT * np.max(mag, axis=1, keepdims=True)
    dominant &= mag > 0.0
    rho = np.min(np.where(dominant, rho, np.inf), axis=1)
    # Where the first-order terms alone break the row (taken at a b still too high), the
    # bound would ask for strictly convex b: the sweeps repair that row instead.
    return np.asarray(np.maximum(rho, 0.0), dtype=np.float64)


def _round_peaks(b: FloatArray, rho: FloatArray) -> FloatArray:
    """The greatest ``b' <= b`` with ``b'_{i-1} - 2 b'_i + b'_{i+1} >= -rho_i`` where it can bind.

    ``b + Q`` with ``Q``'s second differences ``rho`` must be convex: its lower convex hull,
    minus ``Q``. Nodes where the bound cannot bind (``rho_i >= 2 b_i``: ``b >= 0`` holds it)
    split the grid into runs, each hulled with its own ``Q`` (one ``Q`` over the whole grid
    would grow like ``n**2`` and lose the small ``b`` of the rest ends to round-off).
    """
    out = b.copy()
    binding = np.zeros(b.size, dtype=bool)
    binding[1:-1] = rho < 2.0 * b[1:-1]
    edges = np.flatnonzero(np.diff(binding.astype(np.int8)))
    starts, stops = edges[::2] + 1, edges[1::2] + 1  # runs binding[start:stop]
    for lo, hi in zip(starts.tolist(), stops.tolist(), strict=True):
        seg = slice(lo - 1, hi + 1)
        q = np.zeros(hi - lo + 2)
        q[2:] = np.cumsum(np.cumsum(rho[lo - 1 : hi]))
        v = b[seg] + q
        out[seg] = np.minimum(b[seg], np.maximum(_lower_hull(v) - q, 0.0))
    return out


#: Least share of a node's largest tangential coefficient for a component to enter the
#: convex-hull step (see :func:`_concave_bounds`).
DOMINANT = 0.5
#: The rows as nested lists for the sweeps.
_ListRows = tuple[list[list[float]], list[list[float]], list[list[float]]]


class JerkScan:
    """The grid problem with linear jerk rows ``|X_i(b)| <= lim_i``, solved by scans.

    Parameters
    ----------
    passes : ReachPass
        The jerk-free passes of the same grid.
    rows : JerkRows
        The jerk rows.
    """

    def __init__(self, passes: ReachPass, rows: JerkRows) -> None:
        self.passes = passes
        self.rows = rows
        self._lists: _ListRows = (rows.cm.tolist(), rows.cc.tolist(), rows.cp.tolist())
        self.time = 0.0
        self.solves = 0
        self.rounds = 0

    def solve(self, acc: FloatArray, lim: FloatArray, ub: FloatArray) -> FloatArray | None:
        """A plan inside the acceleration rows scaled by ``acc`` (n - 1,), the jerk rows
        ``|X_i(b)| <= lim_i`` (n - 2,) and ``0 <= b <= ub``; None when the jerk-free passes
        do not settle (the caller then asks the LP)."""
        start = time.perf_counter()
        self.solves += 1
        b = self.passes.solve(acc, ub)
        if b is None:
            return None
        lim_list = lim.tolist()
        n = b.size
        for _ in range(MAX_ROUNDS):
            self.rounds += 1
            before = b
            b = _round_peaks(b, _concave_bounds(b, self.rows, lim))
            todo = (self._excess(b, lim) > 0.0).tolist()
            values = b.tolist()
            _sweep(values, self._lists, lim_list, todo, range(1, n - 1))
            todo = (self._excess(np.asarray(values), lim) > 0.0).tolist()
            _sweep(values, self._lists, lim_list, todo, range(n - 2, 0, -1))
            b = self.passes.solve(acc, np.minimum(np.asarray(values), before))
            if b is None:
                return None
            if float(np.max(before - b)) <= SETTLE_RTOL * max(float(np.max(before)), 1e-300):
                break
        b = self._certify(b, acc, lim)
        self.time += time.perf_counter() - start
        return b

    def _excess(self, b: FloatArray, lim: FloatArray) -> FloatArray:
        """``max_c |X_ic(b)| - lim_i`` at the interior nodes."""
        r = self.rows
        x = r.cm * b[:-2, None] + r.cc * b[1:-1, None] + r.cp * b[2:, None]
        return np.asarray(np.max(np.abs(x), axis=1) - lim, dtype=np.float64)

    def _certify(self, b: FloatArray, acc: FloatArray, lim: FloatArray) -> FloatArray:
        """``b`` scaled down until every row holds (the rows are linear and homogeneous)."""
        alpha, beta = self.passes.rows.alpha, self.passes.rows.beta
        with np.errstate(divide="ignore", invalid="ignore"):
            ea = np.max(acceleration_ratio(b, alpha, beta) / acc, initial=0.0)
            ej = np.max((self._excess(b, lim) + lim) / lim, initial=0.0)
        worst = max(float(ea), float(ej), 1.0)
        return b / worst if worst > 1.0 else b


class ScanGrid:
    """The grid problem behind the LP's interface (:class:`.rows.GridSolver`), by scans.

    A problem whose jerk rows are all free goes to the jerk-free passes, every
    other one to :class:`JerkScan`; the HiGHS LP, built only then, answers what
    the passes do not settle.

    Parameters
    ----------
    acc : AccelerationRows
        The acceleration rows.
    rows : JerkRows
        The jerk rows (coefficients over each component's bound).
    scale : ndarray, shape (n,)
        The speed-like reference of the LP's jerk rows (:func:`~.rows._jerk_matrix`).
    lp : callable
        Builds the HiGHS grid LP (the fallback).
    deadline : Deadline, optional
        Checked before every solve.
    """

    def __init__(self, acc: AccelerationRows, rows: JerkRows, scale: FloatArray,
                 lp: Callable[[], _GridLP], deadline: Deadline | None) -> None:  # fmt: skip
        self.passes = ReachPass(acc)
        self.scan = JerkScan(self.passes, rows)
        self._root = np.sqrt(scale[1:-1])
        self._build_lp = lp
        self._lp: _GridLP | None = None
        self.deadline = deadline

    @property
    def time(self) -> float:
        """Wall time of every solve, s."""
        lp = 0.0 if self._lp is None else self._lp.time
        return self.passes.time + self.scan.time + lp

    @property
    def solves(self) -> int:
        """Problems solved (passes, scans, LP)."""
        return self.passes.solves + (0 if self._lp is None else self._lp.solves)

    @property
    def used_lp(self) -> bool:
        """Whether the HiGHS LP had to answer."""
        return self._lp is not None

    def solve(self, r: FloatArray, ub: FloatArray, *, rough: bool = False) -> FloatArray:
        """A plan inside the LP's row bounds ``r`` and ``0 <= b <= ub`` (``rough`` is not used)."""
        if self.deadline is not None:
            self.deadline.check(f"speed scan {self.solves + 1}")
        n = ub.size
        acc = r[: n - 1]
        jerk = r[self.scan.rows.cm.shape[1] * 2 * (n - 1) :][: n - 2]
        b = (
            self.passes.solve(acc, ub)
            if not np.any(np.isfinite(jerk))
            else self.scan.solve(acc, jerk / self._root, ub)
        )
        if b is not None:
            return b
        if self._lp is None:
            self._lp = self._build_lp()
        return self._lp.solve(r, ub)
