"""Time-optimal speed planning along a parametric path by linear programming.

Implements the speed planner of §2.1 and the second-order Taylor interpolator
of §2.2 of the coverage-path paper (``001_61beb0e01a19013a``): the path
``C(u)``, ``u in [0, 1]``, is sampled at ``n`` grid points and the decision
variable at each point is ``b_i = u_dot_i**2``.  The problem

    maximise   sum_i b_i
    subject to |C'(u_i)|**2 b_i <= vmax**2                    (speed)
               |C'|**2 b_i <= 8 rho eps / T**2                 (chord error)
               |C''_k b + 0.5 C'_k b'| <= amax_k               (acceleration)
               sqrt(b) |C'''_k b + 1.5 C''_k b' + 0.5 C'_k b''| <= jmax_k
               b_0 = b_{n-1} = 0

is linear in ``b`` except for the ``sqrt(b)`` factor of the jerk (the paper's
expression drops it); it is linearised at the previous iterate ("pseudo-jerk")
and the LP re-solved with HiGHS.  With highspy installed one HiGHS model is
built once: the linearisation point only changes row bounds
(``|X_i| <= jmax / sqrt(b_ref_i)``), so every re-solve is a dual-simplex hot
start from the previous basis (tens of pivots instead of a cold solve);
without it each LP goes to ``scipy.optimize.linprog``.

Discretisation choices (the grid LP is otherwise optimistic):

* Optionally (``grid="adaptive"``) the grid is not uniform in ``u``: the LP
  runs on ``C(g(sigma))`` with a uniform ``sigma`` grid, ``g`` chosen so that
  half of the points are uniform in arc length and half uniform in an
  estimated traversal time (crowding the rest ends and tight curls, where a
  spiral winding into its centre has features short relative to a uniform
  ``u`` grid).  ``SpeedPlan.u``/``b`` and ``Setpoints.u`` stay in ``u``.
* Between grid points ``b`` is taken piecewise linear in ``u`` (constant
  ``u_ddot``); the acceleration constraint is imposed for every interval at
  both ends with that interval's slope.  The duration is the
  exact time of this model, ``dt = 2 du / (sqrt(b_i) + sqrt(b_{i+1}))``, which
  stays finite at the rest-to-rest ends where a trapezoid of ``1/sqrt(b)``
  diverges/under-estimates.
* With a jerk limit the rest ends behave like ``b ~ s**(4/3)``; the first and
  last interior ``b`` are capped so that the acceleration builds up from zero
  at <= jmax, ``w = b**(3/4)`` (regular there) is represented by a cubic
  B-spline *quasi-interpolant* (no ringing at the kinks of the optimum, unlike
  an interpolating spline), and the §2.2 Taylor recursion gets a third-order
  term so that it leaves the rest start (the paper injects a small speed).
  The pseudo-jerk iteration alternates between over- and under-estimates with
  shrinking amplitude; the last LP is a *certification* LP with ``sqrt(B)`` as
  linearisation point and ``b <= B`` (``B`` the element-wise max of the last
  two iterates), so that ``sqrt(b) |X| <= sqrt(B) |X| <= jmax`` holds exactly
  at the grid points.
* The grid constraints do not bound the interpolated profile between the
  nodes.  A *local refinement* evaluates the chain-rule speed/acceleration/jerk
  of the interpolant at the resolution of :meth:`SpeedPlan.verify`, divides
  the limits of the nodes around every excess by ``(1 + excess)**r`` (``r``
  the round, 1, 2, ...) and re-solves from the previous basis, until the
  excess is below ``max_excess`` (2 % by default).  Unlike the global
  ``safety`` factor (still available) this keeps the speed elsewhere.
"""

from __future__ import annotations

import bisect
import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt
from scipy import sparse
from scipy.interpolate import BSpline, PPoly, make_interp_spline
from scipy.optimize import linprog

from skyquill.errors import InfeasibleError, InputError, SolverError
from skyquill.validation import per_axis

try:  # optional fast path: one HiGHS model, hot-started between re-solves
    import highspy as _highspy
except ImportError:  # pragma: no cover - exercised only without highspy
    _highspy = None  # type: ignore[assignment]

FloatArray = npt.NDArray[np.float64]

# scipy-stubs do not list a sparse A_ub; HiGHS accepts it.
_linprog: Callable[..., Any] = linprog

#: Largest step of the Taylor walk, as a fraction of the control period.
_WALK_FRACTION = 0.25
#: Fewest / most points per grid interval at which the refinement checks the plan.
_SAMPLES = 8
_MAX_SAMPLES = 256
#: Share of the adaptive grid spread uniformly in arc length (the rest: uniformly in
#: the estimated time, which crowds the points at the rest ends and tight curls).
_ARC_SHARE = 0.5
#: The time estimate floors the speed at this fraction of ``vmax`` (bounds the crowding).
_V_FLOOR = 0.05
#: Table points per grid point for building the adaptive grid.
_TABLE = 8
#: Width (in grid cells) of the smoothing of the adaptive grid's density.
_SMOOTH_CELLS = 10

logger = logging.getLogger(__name__)

__all__ = ["PathCurve", "Setpoints", "SpeedPlan", "Verification", "plan_speed"]


class PathCurve(Protocol):
    """A parametric path ``C(u)``, ``u in [0, 1]``, with derivatives ``nu``."""

    def __call__(self, x: Any, nu: int = ...) -> Any:
        """Evaluate the ``nu``-th derivative at ``x``."""
        ...


@dataclass(frozen=True, eq=False)
class Setpoints:
    """Time-domain samples of a planned path.

    Attributes
    ----------
    t : ndarray, shape (m,)
        Sample times (uniform, spacing ``period``).
    u : ndarray, shape (m,)
        Path parameter at each sample.
    p, v, a, j : ndarray, shape (m, d)
        Position, and velocity, acceleration and jerk from the chain rule
        with ``u_dot = sqrt(b)``, ``u_ddot = b'/2``, ``u_dddot = b'' u_dot/2``.
    period : float
        Sampling period.
    """

    t: FloatArray
    u: FloatArray
    p: FloatArray
    v: FloatArray
    a: FloatArray
    j: FloatArray
    period: float


@dataclass(frozen=True, eq=False)
class Verification:
    """Limits measured on finite differences of the setpoints.

    Attributes
    ----------
    max_speed : float
        Largest speed (first differences).
    max_acc : ndarray, shape (d,)
        Per-axis largest ``|a|`` (second central differences).
    max_jerk : ndarray, shape (d,) or None
        Per-axis largest ``|j|`` (third differences); None without jerk limit.
    speed_excess, acc_excess, jerk_excess : float
        Relative excess over the respective limit (0 when respected).
    max_excess : float
        Largest of the three relative excesses.
    period : float
        Sampling period used for the differences.
    """

    max_speed: float
    max_acc: FloatArray
    max_jerk: FloatArray | None
    speed_excess: float
    acc_excess: float
    jerk_excess: float
    max_excess: float
    period: float


@dataclass(frozen=True, eq=False)
class SpeedPlan:
    """Result of :func:`plan_speed`.

    Attributes
    ----------
    u : ndarray, shape (n,)
        Parameter grid on ``[0, 1]``: uniform with ``grid="uniform"``, else
        the image of a uniform grid of the planning parameter (see ``grid``
        of :func:`plan_speed`).
    b : ndarray, shape (n,)
        ``u_dot**2`` at the grid points (0 at both ends).
    duration : float
        Traversal time of the piecewise-constant-``u_ddot`` model.
    iterations : int
        Pseudo-jerk LPs solved after the jerk-free LP, refinement rounds
        included (0 without jerk limit).
    solve_time : float
        Total wall time spent in the LP solver, seconds.
    objectives : tuple of float
        ``sum(b)`` (in the planning parameter) of every LP, in order:
        jerk-free; with a jerk limit then jerk-free with the rest-end caps,
        the pseudo-jerk iterates and the certification LP; then per
        refinement round its iterates and certification LP (one LP per round
        without jerk limit).
    jerk_changes : tuple of float
        ``max |sqrt(b_k) - sqrt(b_{k-1})| / max sqrt(b_k)`` per iteration
        (refinement rounds appended).
    vmax, amax, jmax :
        The limits (``amax``/``jmax`` per axis).
    control_period : float
        Interpolation period ``T`` of §2.2.
    refinements : int
        Rounds of local limit tightening (see ``max_excess`` of :func:`plan_speed`).
    excess_estimate : float
        Largest relative excess of the interpolated plan over a limit, from
        the chain-rule derivatives at >= 8 points per grid interval and at
        least every ``control_period / 10`` (what :meth:`verify` measures by
        finite differences, up to sampling).
    lp_solves : int
        Number of LPs solved.
    grid : str
        ``"uniform"`` or ``"adaptive"`` (see :func:`plan_speed`).
    """

    curve: PathCurve
    u: FloatArray
    b: FloatArray
    duration: float
    iterations: int
    solve_time: float
    objectives: tuple[float, ...]
    jerk_changes: tuple[float, ...]
    vmax: float
    amax: FloatArray
    jmax: FloatArray | None
    control_period: float
    _bspline: BSpline = field(repr=False)
    _path: PathCurve = field(repr=False)
    _sigma: FloatArray = field(repr=False)
    _bsig: FloatArray = field(repr=False)
    _umap: BSpline | None = field(repr=False)
    refinements: int = 0
    excess_estimate: float = 0.0
    lp_solves: int = 0
    grid: str = "uniform"

    def _b_eval(self, u: FloatArray, nu: int) -> FloatArray:
        return np.asarray(self._bspline(u, nu), dtype=np.float64)

    def setpoints(self, period: float | None = None) -> Setpoints:
        """Interpolate the plan at a fixed period by the Taylor expansion of §2.2.

        ``u_{k+1} = u_k + u_dot_k T + u_ddot_k T**2 / 2`` with
        ``u_dot = sqrt(b(u))``, ``u_ddot = b'(u)/2``.  At the start, where
        ``u_dot = u_ddot = 0`` can stall the recursion, a tiny parameter step is
        used (the paper's "small initial speed").  The walk ends at ``u = 1`` as
        soon as the step would overshoot or the speed would reverse.  With a
        jerk limit the recursion runs at a step of at most ``control_period / 4``
        and every k-th point is output: at the full period its truncation error
        shows up in the third differences of the positions (8 % jerk excess on
        a circle at 1,000 grid points; none at ``T / 2``).

        Parameters
        ----------
        period : float, optional
            Sampling period; defaults to ``control_period``.

        Returns
        -------
        Setpoints
            Samples ``t, u, p, v, a, j``.
        """
        T = self.control_period if period is None else float(period)
        if not np.isfinite(T) or T <= 0.0:
            raise InputError(f"period must be a positive finite number, got {period!r}")
        if self.jmax is None:
            return self._samples(self._exact_walk(T), T)
        sub = max(1, math.ceil(T / (_WALK_FRACTION * self.control_period) - 1e-9))
        u = self._taylor_walk(T / sub)[::sub]
        if u[-1] < 1.0:
            u = np.append(u, 1.0)
        return self._samples(u, T)

    def _exact_walk(self, T: float) -> FloatArray:
        """Sample ``u(t)`` of the piecewise-linear-``b`` model at period ``T``.

        Within a grid interval ``u_ddot = s/2`` is constant, so the Taylor
        expansion of §2.2 taken from the interval's start node is exact; a
        control period that straddles nodes is split there.
        """
        sig, bs = self._sigma, self._bsig
        sq = np.sqrt(bs)
        h = sig[1] - sig[0]
        tn = np.concatenate([[0.0], np.cumsum(2.0 * h / (sq[:-1] + sq[1:]))])
        m = int(np.floor(tn[-1] / T))
        t = T * np.arange(m + 1, dtype=np.float64)
        i = np.clip(np.searchsorted(tn, t, side="right") - 1, 0, sig.size - 2)
        tau = t - tn[i]
        slope = (bs[i + 1] - bs[i]) / h
        u = sig[i] + sq[i] * tau + 0.25 * slope * tau**2
        u = np.minimum(np.maximum.accumulate(u), 1.0)
        if u[-1] < 1.0:
            u = np.append(u, 1.0)
        return np.asarray(u, dtype=np.float64)

    def _derivs(self, u: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``u_dot``, ``u_ddot``, ``u_dddot`` as functions of ``u``.

        Without jerk limit ``b`` is piecewise linear (``u_dddot = 0``).  With a
        jerk limit the spline interpolates ``w = b**(3/4)``, which is regular
        (linear) at a jerk-limited rest end where ``b ~ s**(4/3)``; then
        ``u_dot = w**(2/3)``, ``u_ddot = (2/3) w**(1/3) w'`` and
        ``u_dddot = (2/9) w'**2 + (2/3) w w''`` are all bounded.
        """
        if self.jmax is None:
            b = np.maximum(self._b_eval(u, 0), 0.0)
            return np.sqrt(b), 0.5 * self._b_eval(u, 1), np.zeros_like(u)
        w = np.maximum(self._b_eval(u, 0), 0.0)
        w1 = self._b_eval(u, 1)
        w2 = self._b_eval(u, 2)
        ud = w ** (2.0 / 3.0)
        udd = (2.0 / 3.0) * np.cbrt(w) * w1
        uddd = (2.0 / 9.0) * w1**2 + (2.0 / 3.0) * w * w2
        return ud, udd, uddd

    def _scalar_derivs(self) -> Callable[[float], tuple[float, float, float]]:
        """:meth:`_derivs` (jerk-limited case) at one ``u``, in plain floats.

        The walk is sequential, one ``u`` at a time; calling the B-spline on
        one-element arrays costs ~25 us a call, so the cubic ``w`` is turned
        into its piecewise polynomial once and evaluated by Horner's rule.
        """
        pp = PPoly.from_spline((self._bspline.t, self._bspline.c, self._bspline.k))
        breaks = pp.x.tolist()
        coef = pp.c.T.tolist()  # per interval: (c3, c2, c1, c0) of (u - x_i)
        last = len(coef) - 1

        def at(u: float) -> tuple[float, float, float]:
            i = min(max(bisect.bisect_right(breaks, u) - 1, 0), last)
            a3, a2, a1, a0 = coef[i]
            x = u - breaks[i]
            w = max(((a3 * x + a2) * x + a1) * x + a0, 0.0)
            w1 = (3.0 * a3 * x + 2.0 * a2) * x + a1
            w2 = 6.0 * a3 * x + 2.0 * a2
            cw = w ** (1.0 / 3.0)
            return cw * cw, (2.0 / 3.0) * cw * w1, (2.0 / 9.0) * w1 * w1 + (2.0 / 3.0) * w * w2

        return at

    def _taylor_walk(self, T: float) -> FloatArray:
        """Recursion ``u_{k+1} = u_k + u_dot T + u_ddot T**2/2 (+ u_dddot T**3/6)``.

        The second-order expansion of §2.2 stalls at a jerk-limited rest start
        (``u_dot = u_ddot = 0``); the paper injects a small initial speed, here
        the third-order term (bounded in the ``w`` representation) is added.
        The walk snaps to ``u = 1`` once the step would overshoot or the speed
        would reverse within the period.
        """
        max_steps = int(10.0 * self.duration / T) + 1000
        derivs = self._scalar_derivs()
        us = [0.0]
        uk = 0.0
        for _ in range(max_steps):
            d1, d2, d3 = derivs(uk)
            if uk > 0.5 and d1 + d2 * T + 0.5 * d3 * T * T <= 0.0:
                break
            step = d1 * T + 0.5 * d2 * T * T + d3 * T**3 / 6.0
            if step <= 0.0:
                if uk > 0.5:
                    break
                step = 1e-12
            unext = uk + step
            if unext >= 1.0:
                break
            us.append(unext)
            uk = unext
        us.append(1.0)
        return np.asarray(us, dtype=np.float64)

    def _samples(self, uarr: FloatArray, T: float) -> Setpoints:
        t = T * np.arange(uarr.size, dtype=np.float64)
        ud, udd, uddd = self._derivs(uarr)
        ud[0] = ud[-1] = 0.0
        c0, c1, c2, c3 = (_eval(self._path, uarr, k) for k in range(4))
        v = c1 * ud[:, None]
        a = c2 * (ud**2)[:, None] + c1 * udd[:, None]
        j = c3 * (ud**3)[:, None] + 3.0 * c2 * (ud * udd)[:, None] + c1 * uddd[:, None]
        u_out = uarr if self._umap is None else np.clip(self._umap(uarr), 0.0, 1.0)
        return Setpoints(t=t, u=u_out, p=c0, v=v, a=a, j=j, period=T)

    def verify(self, period: float | None = None) -> Verification:
        """Measure speed, acceleration and jerk of the setpoints by finite differences.

        Parameters
        ----------
        period : float, optional
            Sampling period of the setpoints that are differenced; defaults to
            ``control_period / 10`` (a fine grid).

        Returns
        -------
        Verification
            Per-axis maxima and relative excesses over the limits.
        """
        T = self.control_period / 10.0 if period is None else float(period)
        sp = self.setpoints(T)
        # Rest before and after: pad with the end points so that a start or
        # stop with non-zero acceleration shows up as jerk.
        p = np.concatenate([np.repeat(sp.p[:1], 3, axis=0), sp.p, np.repeat(sp.p[-1:], 3, axis=0)])
        vel = np.diff(p, axis=0) / T
        acc = np.diff(p, n=2, axis=0) / T**2
        max_speed = float(np.max(np.linalg.norm(vel, axis=1)))
        max_acc = np.max(np.abs(acc), axis=0)
        speed_ex = max(max_speed / self.vmax - 1.0, 0.0)
        acc_ex = max(float(np.max(max_acc / self.amax)) - 1.0, 0.0)
        max_jerk: FloatArray | None = None
        jerk_ex = 0.0
        if self.jmax is not None:
            jerk = np.diff(p, n=3, axis=0) / T**3
            max_jerk = np.max(np.abs(jerk), axis=0)
            jerk_ex = max(float(np.max(max_jerk / self.jmax)) - 1.0, 0.0)
        return Verification(
            max_speed=max_speed,
            max_acc=max_acc,
            max_jerk=max_jerk,
            speed_excess=speed_ex,
            acc_excess=acc_ex,
            jerk_excess=jerk_ex,
            max_excess=max(speed_ex, acc_ex, jerk_ex),
            period=T,
        )


def _eval(curve: PathCurve, u: FloatArray, nu: int) -> FloatArray:
    """Evaluate ``curve(u, nu=nu)`` as an ``(len(u), d)`` float array."""
    try:
        out = np.asarray(curve(u, nu=nu), dtype=np.float64)
    except Exception as exc:
        raise InputError(f"curve(u, nu={nu}) failed: {exc}") from exc
    if out.ndim == 1 and out.shape[0] == u.shape[0]:
        out = out[:, None]
    if out.ndim != 2 or out.shape[0] != u.shape[0]:
        raise InputError(
            f"curve(u, nu={nu}) must return shape (len(u), d), got {out.shape} for len(u)={u.size}"
        )
    if not np.all(np.isfinite(out)):
        raise InputError(f"curve(u, nu={nu}) returned non-finite values")
    return out


class _GridLP:
    """``max sum(b)`` s.t. ``|A b| <= r`` row-wise, ``0 <= b <= ub``; re-solved as bounds change.

    With ``backend="highspy"`` the model is passed to HiGHS once and every
    later solve only changes bounds, so the dual simplex restarts from the
    previous optimal basis: a pseudo-jerk iteration or a refinement round
    costs a few dozen pivots instead of a cold solve.  ``"linprog"`` rebuilds
    the two-sided rows for :func:`scipy.optimize.linprog` every time (the
    reference path, and the fallback when highspy is missing).
    """

    def __init__(self, a: Any, *, backend: str) -> None:
        self.a = sparse.csr_array(a)
        self.backend = backend
        self.time = 0.0
        self.solves = 0
        m, n = self.a.shape
        self._r = np.full(m, np.inf)
        self._ub = np.full(n, np.inf)
        self._highs: Any = _highs_model(self.a) if backend == "highspy" else None

    def solve(self, r: FloatArray, ub: FloatArray) -> FloatArray:
        """Solve with row bounds ``r`` (``inf`` = free row) and column bounds ``ub``."""
        if self._highs is not None:
            try:
                return self._solve_highspy(r, ub)
            except _HighsStalledError as exc:
                logger.info("highspy stalled (%s); linprog for the remaining solves", exc)
                self._highs = None
        keep = np.isfinite(r)
        # Rows normalised to right-hand side 1 (as linprog's presolve/scaling prefer).
        a_keep = sparse.diags_array(1.0 / r[keep]) @ self.a[keep]
        a_ub = sparse.vstack([a_keep, -a_keep], format="csr")
        x, dt = _solve(-np.ones(self.a.shape[1]), a_ub, ub, np.ones(a_ub.shape[0]))
        return self._count(x, dt)

    def _solve_highspy(self, r: FloatArray, ub: FloatArray) -> FloatArray:
        # Only the changed bounds are passed (most rows keep theirs between iterations).
        rows = np.flatnonzero(r != self._r).astype(np.int32)
        cols = np.flatnonzero(ub != self._ub).astype(np.int32)
        self._r, self._ub = r.copy(), ub.copy()
        x, dt = _highs_solve(self._highs, (rows, r[rows]), (cols, ub[cols]))
        return self._count(np.clip(x, 0.0, ub), dt)

    def _count(self, x: FloatArray, dt: float) -> FloatArray:
        self.time += dt
        self.solves += 1
        return x


def _highs_model(a: Any) -> Any:
    """A silent HiGHS instance holding ``max sum(b)`` with the rows ``a`` (bounds set per solve).

    Presolve is off: it would discard the basis of the hot starts, and the
    cold first solve is no faster with it (72 vs 81 ms at n = 2000).
    """
    if _highspy is None:  # pragma: no cover - guarded by _validate_refine
        raise SolverError("highspy is not installed")
    csc = sparse.csc_array(a)
    m, n = csc.shape
    lp = _highspy.HighsLp()
    lp.num_col_ = n
    lp.num_row_ = m
    lp.col_cost_ = -np.ones(n)
    lp.col_lower_ = np.zeros(n)
    lp.col_upper_ = np.full(n, _highspy.kHighsInf)
    lp.row_lower_ = np.full(m, -_highspy.kHighsInf)
    lp.row_upper_ = np.full(m, _highspy.kHighsInf)
    lp.a_matrix_.format_ = _highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_ = csc.indptr
    lp.a_matrix_.index_ = csc.indices
    lp.a_matrix_.value_ = csc.data
    highs = _highspy.Highs()  # type: ignore[no-untyped-call]
    highs.setOptionValue("output_flag", False)
    highs.setOptionValue("presolve", "off")
    highs.passModel(lp)
    return highs


#: Wall-time limit of one hot-started highspy solve, s (the slowest seen takes 0.1 s).
HOT_SOLVE_LIMIT_S = 0.5


class _HighsStalledError(Exception):
    """A hot-started highspy solve ended neither optimal nor infeasible."""


def _run_highs(highs: Any, limit_s: float) -> Any:
    """Run HiGHS for at most ``limit_s`` more seconds; its model status.

    HiGHS's ``time_limit`` counts the instance's run time over all solves, so
    the limit is set relative to the time already spent.
    """
    highs.setOptionValue("time_limit", float(highs.getRunTime()) + limit_s)
    highs.run()
    return highs.getModelStatus()


def _highs_solve(
    highs: Any, rows: tuple[Any, FloatArray], cols: tuple[Any, FloatArray]
) -> tuple[FloatArray, float]:
    """Change the ``(indices, values)`` row (symmetric) and column bounds, then re-solve."""
    inf = _highspy.kHighsInf
    idx, r = rows
    if idx.size:
        rr = np.where(np.isfinite(r), r, inf)
        highs.changeRowsBounds(idx.size, idx, -rr, rr)
    idx, ub = cols
    if idx.size:
        highs.changeColsBounds(idx.size, idx, np.zeros(idx.size), ub)
    t0 = time.perf_counter()
    status = _run_highs(highs, HOT_SOLVE_LIMIT_S)
    if status not in (_highspy.HighsModelStatus.kOptimal, _highspy.HighsModelStatus.kInfeasible):
        # A hot start can stall, or end "Unknown", on some smoothed zigzags;
        # a cold highspy solve stalled too, scipy's HiGHS (presolve on) does not.
        raise _HighsStalledError(highs.modelStatusToString(status))
    dt = time.perf_counter() - t0
    if status == _highspy.HighsModelStatus.kInfeasible:
        raise InfeasibleError("speed-planning LP is infeasible", ("speed_lp",))
    if status != _highspy.HighsModelStatus.kOptimal:
        why = highs.modelStatusToString(status)
        raise SolverError(f"HiGHS failed on the speed-planning LP: {why}")
    return np.asarray(highs.getSolution().col_value, dtype=np.float64), dt


def _solve(
    cost: FloatArray, a_ub: Any, ub: FloatArray, b_ub: FloatArray
) -> tuple[FloatArray, float]:
    """Maximise ``sum(b)`` s.t. ``a_ub b <= b_ub``, ``0 <= b <= ub`` with scipy's ``linprog``."""
    bounds = list(zip(np.zeros_like(ub).tolist(), ub.tolist(), strict=True))
    t0 = time.perf_counter()
    res = _linprog(cost, A_ub=a_ub, b_ub=b_ub, bounds=bounds, method="highs")
    dt = time.perf_counter() - t0
    if res.status == 2:
        raise InfeasibleError("speed-planning LP is infeasible", ("speed_lp",))
    if res.status != 0 or res.x is None:
        raise SolverError(f"HiGHS failed on the speed-planning LP: {res.message}")
    return np.maximum(np.asarray(res.x, dtype=np.float64), 0.0), dt


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
    c1, c2, c3 = derivs
    n, d = c1.shape
    h = 1.0 / (n - 1)
    i_idx = np.arange(1, n - 1)
    cm = -1.5 * c2[1:-1] / (2 * h) + 0.5 * c1[1:-1] / h**2
    cc = c3[1:-1] - c1[1:-1] / h**2
    cp = 1.5 * c2[1:-1] / (2 * h) + 0.5 * c1[1:-1] / h**2
    r = np.sqrt(scale[1:-1])
    ri = np.tile(np.arange(n - 2), 3)
    ci = np.concatenate([i_idx - 1, i_idx, i_idx + 1])
    blocks = []
    for ax in range(d):
        sc = r / jmax[ax]
        data = np.concatenate([cm[:, ax] * sc, cc[:, ax] * sc, cp[:, ax] * sc])
        blocks.append(sparse.csr_array((data, (ri, ci)), shape=(n - 2, n)))
    return sparse.vstack(blocks, format="csr")


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


def _pseudo_jerk(
    lp: _GridLP,
    bounds: _Bounds,
    start: FloatArray,
    *,
    stop: tuple[int, float],
    log: tuple[list[float], list[float]],
) -> tuple[FloatArray, int]:
    """Pseudo-jerk fixed-point iteration from ``start``, then the certification LP.

    Starting from an over-estimate (the jerk-free optimum, or the previous
    plan before a refinement), each LP linearises ``sqrt(b)`` at the previous
    iterate; the iterates then alternate around the fixed point with
    shrinking amplitude.  The final LP linearises at
    ``B = max(b_k, b_{k-1})`` and imposes ``b <= B``, which makes the true
    grid jerk ``sqrt(b) |X| <= sqrt(B) |X| <= jmax``.

    Parameters
    ----------
    lp
        The grid LP (hot-started between solves).
    bounds
        Row/column bounds with the refinement factors.
    start
        First linearisation point.
    stop
        ``(max_iterations, tolerance)`` on the relative change of ``sqrt(b)``.
    log
        Lists that receive the objectives and the relative changes.

    Returns
    -------
    tuple
        Final ``b`` and the number of iterations.
    """
    max_iter, tol = stop
    objectives, changes = log
    ub = bounds.cols()
    prev = prev2 = start
    iterations = 0
    for _ in range(max_iter):
        bn = lp.solve(bounds.rows(prev), ub)
        iterations += 1
        objectives.append(float(bn.sum()))
        sq_new = np.sqrt(bn)
        change = float(np.max(np.abs(sq_new - np.sqrt(prev))) / max(np.max(sq_new), 1e-300))
        changes.append(change)
        prev2, prev = prev, bn
        if change < tol and iterations >= 2:
            break
    big = np.maximum(prev, prev2)
    b = lp.solve(bounds.rows(big), np.minimum(ub, big))
    objectives.append(float(b.sum()))
    return b, iterations


def _w_spline(b: FloatArray, h: float) -> BSpline:
    """Cubic B-spline *quasi-interpolant* of ``w = b**(3/4)`` with the ``w_i`` as coefficients.

    Odd reflection at the rest ends.  At the knots ``w''`` and ``w'`` are
    exactly the discrete second/central differences and ``w''`` is linear in
    between, so there is none of the ringing an interpolating spline shows at
    the kinks of the optimal profile.
    """
    w = b**0.75
    coef = np.concatenate([[-w[1]], w, [-w[-2]]])
    knots = h * (np.arange(b.size + 6, dtype=np.float64) - 3.0)
    return BSpline(knots, coef, 3, extrapolate=False)


def _interval_excess(plan: SpeedPlan) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Relative speed, acceleration and jerk excess of each grid interval.

    The chain-rule derivatives of the interpolated plan (what
    :meth:`SpeedPlan.setpoints` outputs and :meth:`SpeedPlan.verify`
    differences) are evaluated on each interval at ``_SAMPLES`` points, or at
    least every ``control_period / 10`` of its traversal time (the default
    resolution of :meth:`SpeedPlan.verify`): the peaks at the kinks of the
    jerk are narrow.

    Returns
    -------
    tuple of ndarray, shape (n - 1,)
        ``max(ratio - 1, 0)`` per interval for speed, acceleration, jerk.
    """
    sig = plan._sigma
    h = sig[1] - sig[0]
    dt = _interval_times(plan._bsig, h, jerk=plan.jmax is not None)
    m = np.clip(np.ceil(dt / (0.1 * plan.control_period)), _SAMPLES, _MAX_SAMPLES).astype(int)
    start = np.concatenate([[0], np.cumsum(m)[:-1]])
    frac = (np.arange(int(m.sum())) - np.repeat(start, m)) / np.repeat(m, m)
    us = np.minimum(np.repeat(sig[:-1], m) + h * frac, 1.0)
    ud, udd, uddd = plan._derivs(us)
    c1, c2, c3 = _derivs3(plan._path, us)
    speed = np.linalg.norm(c1, axis=1) * ud / plan.vmax
    acc = np.max(np.abs(c2 * (ud**2)[:, None] + c1 * udd[:, None]) / plan.amax, axis=1)
    out = [speed, acc]
    if plan.jmax is not None:
        jerk = c3 * (ud**3)[:, None] + 3.0 * c2 * (ud * udd)[:, None] + c1 * uddd[:, None]
        out.append(np.max(np.abs(jerk) / plan.jmax, axis=1))
    else:
        out.append(np.zeros_like(speed))
    ex = [np.maximum(np.maximum.reduceat(x, start) - 1.0, 0.0) for x in out]
    return ex[0], ex[1], ex[2]


def _spread(x: FloatArray, lo: int, hi: int, size: int) -> FloatArray:
    """``out[i] = max(x[i - hi .. i - lo])`` (clipped), for mapping intervals to nodes."""
    out = np.zeros(size)
    for s in range(lo, hi + 1):
        dst = slice(max(s, 0), min(size, x.size + s))
        src = slice(max(-s, 0), max(-s, 0) + dst.stop - dst.start)
        out[dst] = np.maximum(out[dst], x[src])
    return out


def _tighten(
    bounds: _Bounds, excess: tuple[FloatArray, FloatArray, FloatArray], *, power: float
) -> None:
    """Lower the limits near every interval with an excess by ``(1 + excess)**power``.

    Interval ``k`` of the cubic ``w`` interpolant depends on nodes ``k - 1 .. k + 2``;
    all of them are tightened (speed, jerk), and the acceleration rows of the
    interval and its neighbours.  The caller raises ``power`` round by round:
    where the interpolant's jerk is not proportional to the grid's (short
    features, rest ends) a plain ``1 / (1 + excess)`` converges only
    geometrically.  The rest-end caps on ``b_1``, ``b_{n-2}`` are jerk limits
    too (``b_1**1.5`` scales like the jerk) and follow the end intervals.
    """
    ev, ea, ej = excess
    n = bounds.ub.size
    bounds.speed = bounds.speed / (1.0 + _spread(ev, -1, 2, n)) ** power
    bounds.jerk = bounds.jerk / (1.0 + _spread(ej, -1, 2, n)) ** power
    bounds.acc = bounds.acc / (1.0 + _spread(ea, -1, 1, n - 1)) ** power
    # speed**2 multiplies the column bound, so b scales like (1 + e)**(-2/3).
    bounds.speed[[1, n - 2]] /= (1.0 + ej[[0, n - 2]]) ** (power / 3.0)


def _duration(b: FloatArray, h: float, *, jerk: bool) -> float:
    """Traversal time of the grid model (sum of :func:`_interval_times`)."""
    return float(np.sum(_interval_times(b, h, jerk=jerk)))


def _interval_times(b: FloatArray, h: float, *, jerk: bool) -> FloatArray:
    """Traversal time of every grid interval, finite at the rest ends.

    Without jerk limit ``b`` is linear per interval (constant ``u_ddot``) and
    ``dt = 2h / (sqrt(b_i) + sqrt(b_{i+1}))`` is exact.  With a jerk limit
    ``w = b**(3/4)`` is taken linear per interval and ``int w**(-2/3) du``
    is integrated exactly.
    """
    sq = np.sqrt(b)
    if np.any(sq[:-1] + sq[1:] <= 0.0):
        raise InfeasibleError("planned speed vanishes on an interior interval", ("speed_lp",))
    if not jerk:
        return np.asarray(2.0 * h / (sq[:-1] + sq[1:]), dtype=np.float64)
    w = b**0.75
    cw = np.cbrt(w)
    dw = w[1:] - w[:-1]
    same = np.abs(dw) <= 1e-12 * np.maximum(w[1:], 1e-300)
    safe_dw = np.where(same, 1.0, dw)
    seg = np.where(
        same, h / np.maximum(w[:-1], 1e-300) ** (2.0 / 3.0), 3.0 * h * (cw[1:] - cw[:-1]) / safe_dw
    )
    return np.asarray(seg, dtype=np.float64)


def _validate(
    curve: object,
    n: object,
    vmax: float,
    *,
    control_period: float,
    chord_error: float | None,
    jerk_iterations: int,
    safety: float,
) -> None:
    if not callable(curve):
        raise InputError(f"curve must be callable as curve(u, nu=k), got {type(curve).__name__}")
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 3:
        raise InputError(f"n must be an integer >= 3, got {n!r}")
    if not np.isfinite(vmax) or vmax <= 0.0:
        raise InputError(f"vmax must be positive and finite, got {vmax!r}")
    if not np.isfinite(control_period) or control_period <= 0.0:
        raise InputError(f"control_period must be positive and finite, got {control_period!r}")
    if chord_error is not None and (not np.isfinite(chord_error) or chord_error <= 0.0):
        raise InputError(f"chord_error must be positive and finite or None, got {chord_error!r}")
    if isinstance(jerk_iterations, bool) or int(jerk_iterations) < 0:
        raise InputError(f"jerk_iterations must be an integer >= 0, got {jerk_iterations!r}")
    if not 0.0 < safety <= 1.0:
        raise InputError(f"safety must lie in (0, 1], got {safety!r}")


def _validate_refine(
    max_excess: float | None, refine_rounds: int, lp_backend: str, grid: str
) -> str:
    """Check the refinement/back-end/grid options; returns the back-end actually used."""
    if grid not in ("adaptive", "uniform"):
        raise InputError(f"grid must be 'uniform' or 'adaptive', got {grid!r}")
    if max_excess is not None and (not np.isfinite(max_excess) or max_excess < 0.0):
        raise InputError(f"max_excess must be a finite number >= 0 or None, got {max_excess!r}")
    if isinstance(refine_rounds, bool) or int(refine_rounds) < 0:
        raise InputError(f"refine_rounds must be an integer >= 0, got {refine_rounds!r}")
    if lp_backend not in ("auto", "highspy", "linprog"):
        raise InputError(f"lp_backend must be 'auto', 'highspy' or 'linprog', got {lp_backend!r}")
    if lp_backend == "highspy" and _highspy is None:
        raise InputError("lp_backend='highspy' requested but highspy is not installed")
    if lp_backend == "auto":
        return "linprog" if _highspy is None else "highspy"
    return lp_backend


@dataclass(frozen=True, eq=False)
class _Reparam:
    """``C(g(sigma))``: the path on the planning parameter ``sigma``, by the chain rule."""

    curve: PathCurve
    g: BSpline

    def __call__(self, x: Any, nu: int = 0) -> FloatArray:
        """Evaluate the ``nu``-th derivative (``nu <= 3``) with respect to ``sigma``."""
        s = np.atleast_1d(np.asarray(x, dtype=np.float64))
        u = np.clip(np.asarray(self.g(s), dtype=np.float64), 0.0, 1.0)
        c = [_eval(self.curve, u, k) for k in range(nu + 1)]
        if nu == 0:
            return c[0]
        g1, g2, g3 = (np.asarray(self.g(s, k), dtype=np.float64)[:, None] for k in (1, 2, 3))
        if nu == 1:
            return c[1] * g1
        if nu == 2:
            return c[2] * g1**2 + c[1] * g2
        if nu == 3:
            return c[3] * g1**3 + 3.0 * c[2] * g1 * g2 + c[1] * g3
        raise InputError(f"derivative order {nu} > 3 of a reparametrised path")

    def derivs(self, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """First three derivatives at once (one evaluation of ``C`` and ``g`` per order)."""
        u = np.clip(np.asarray(self.g(x), dtype=np.float64), 0.0, 1.0)
        c1, c2, c3 = (_eval(self.curve, u, k) for k in (1, 2, 3))
        g1, g2, g3 = (np.asarray(self.g(x, k), dtype=np.float64)[:, None] for k in (1, 2, 3))
        return (
            c1 * g1,
            c2 * g1**2 + c1 * g2,
            c3 * g1**3 + 3.0 * c2 * g1 * g2 + c1 * g3,
        )


def _derivs3(path: PathCurve, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """First, second and third derivative of ``path`` at ``x``."""
    if isinstance(path, _Reparam):
        return path.derivs(x)
    c1, c2, c3 = (_eval(path, x, k) for k in (1, 2, 3))
    return c1, c2, c3


def _speed_estimate(
    c1: FloatArray, c2: FloatArray, s: FloatArray, *, vmax: float, amax: float, jmax: float | None
) -> FloatArray:
    """A cheap upper estimate of the speed along the path, for placing grid points.

    Smooth minimum of ``vmax``, the curvature limits ``sqrt(amax / kappa)`` and
    ``(jmax / kappa**2)**(1/3)`` and the rest-end ramps (``s = jmax t**3 / 6``,
    or ``v**2 = 2 amax s`` without jerk limit), smoothly floored at
    ``_V_FLOOR vmax``; smooth so that the grid map (and the path on it) stays smooth.
    """
    sp2 = np.sum(c1 * c1, axis=1)
    cross = np.sqrt(np.maximum(sp2 * np.sum(c2 * c2, axis=1) - np.sum(c1 * c2, axis=1) ** 2, 0.0))
    kappa = cross / sp2**1.5
    dist = np.minimum(s, s[-1] - s)
    inv4 = vmax**-4.0 + (kappa / amax) ** 2
    with np.errstate(divide="ignore", over="ignore"):
        if jmax is None:
            inv4 = inv4 + (2.0 * amax * dist) ** -2.0
        else:
            inv4 = inv4 + (kappa**2 / jmax) ** (4.0 / 3.0)
            inv4 = inv4 + (0.5 * jmax * (6.0 * dist / jmax) ** (2.0 / 3.0)) ** -4.0
        v4 = 1.0 / inv4
    return np.asarray((v4 + (_V_FLOOR * vmax) ** 4) ** 0.25, dtype=np.float64)


def _grid_map(
    curve: PathCurve, n: int, *, vmax: float, amax: FloatArray, jmax: FloatArray | None
) -> BSpline:
    """Monotone map ``u = g(sigma)`` whose uniform ``sigma`` grid suits the path.

    The density of grid points per metre mixes a uniform share (``_ARC_SHARE``)
    with one proportional to ``1 / v`` of :func:`_speed_estimate`, i.e. equal
    time steps: a uniform ``u`` grid leaves the short, slow features (the
    tight curls where a spiral winds into its centre, the rest ends) with too
    few points, while a grid in ``u`` alone follows the parametric speed
    ``|C'|``, which varies by an order of magnitude along a spiral.
    """
    ut = np.linspace(0.0, 1.0, max(_TABLE * n, 2001))
    c1, c2 = _eval(curve, ut, 1), _eval(curve, ut, 2)
    sp = np.linalg.norm(c1, axis=1)
    s = _cumtrapz(sp, ut)
    jm = None if jmax is None else float(np.min(jmax))
    v = _speed_estimate(c1, c2, s, vmax=vmax, amax=float(np.min(amax)), jmax=jm)
    tau = _cumtrapz(sp / v, ut)
    rho = _ARC_SHARE * sp / s[-1] + (1.0 - _ARC_SHARE) * sp / v / tau[-1]
    # Smoothed over ~_SMOOTH_CELLS grid cells: g varies slowly at the grid
    # scale (else the reparametrised path gets short features of its own,
    # and the fourth derivative of C, which jumps at its knots, would make
    # g''' and so the jerk of the new path jump).
    width = min(_SMOOTH_CELLS * (ut.size // n), ut.size // 2) | 1
    rho = _smooth(rho, width=width, passes=3)
    # sigma(u) as a smooth spline; invert it on a uniform sigma table by Newton
    # steps, so that g is interpolated on evenly spaced (well-conditioned) data.
    drho = make_interp_spline(ut, rho, k=3)
    sig_of_u = drho.antiderivative()
    total = float(sig_of_u(1.0))
    sk = np.linspace(0.0, 1.0, ut.size)
    uk = np.interp(sk * total, np.asarray(sig_of_u(ut), dtype=np.float64), ut)
    for _ in range(4):
        uk = np.clip(uk - (sig_of_u(uk) - sk * total) / drho(uk), 0.0, 1.0)
    uk[0], uk[-1] = 0.0, 1.0
    return make_interp_spline(sk, uk, k=5)


def _smooth(x: FloatArray, *, width: int, passes: int) -> FloatArray:
    """Repeated centred moving average (odd ``width``), even reflection at the ends."""
    kernel = np.full(width, 1.0 / width)
    half = width // 2
    for _ in range(passes):
        padded = np.concatenate([x[half:0:-1], x, x[-2 : -half - 2 : -1]])
        x = np.convolve(padded, kernel, mode="valid")
    return x


def _cumtrapz(y: FloatArray, x: FloatArray) -> FloatArray:
    """Cumulative trapezoid integral starting at 0."""
    return np.concatenate([[0.0], np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(x))])


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


def plan_speed(
    curve: PathCurve | Callable[..., Any],
    vmax: float,
    amax: float | npt.ArrayLike,
    jmax: float | npt.ArrayLike | None = None,
    *,
    n: int = 500,
    chord_error: float | None = None,
    control_period: float = 0.02,
    jerk_iterations: int = 20,
    jerk_tol: float = 1e-3,
    safety: float = 1.0,
    max_excess: float | None = 0.02,
    refine_rounds: int = 8,
    lp_backend: str = "auto",
    grid: str = "uniform",
) -> SpeedPlan:
    """Plan the time-optimal rest-to-rest speed profile along ``curve``.

    Parameters
    ----------
    curve : callable
        ``curve(u, nu=k)`` returns the ``k``-th derivative at the array ``u``
        (shape ``(len(u), d)``), ``u in [0, 1]``; e.g. a
        :class:`scipy.interpolate.BSpline` of degree >= 3.
    vmax : float
        Speed limit (> 0).
    amax : float or array_like, shape (d,)
        Per-axis acceleration limit (> 0).
    jmax : float or array_like, shape (d,), optional
        Per-axis jerk limit; None disables jerk constraints.
    n : int, default 500
        Number of grid points (>= 3).
    chord_error : float, optional
        Maximum chord (sagitta) error ``eps``; adds ``v**2 <= 8 rho eps / T**2``.
    control_period : float, default 0.02
        Interpolation period ``T``.
    jerk_iterations : int, default 20
        Maximum number of pseudo-jerk iterations (per refinement round).
    jerk_tol : float, default 1e-3
        Stop when the relative change of ``sqrt(b)`` falls below this.
    safety : float, default 1.0
        Factor in ``(0, 1]`` applied to ``amax`` and ``jmax`` inside the LP
        (uniformly; the refinement below tightens only where needed).
    max_excess : float or None, default 0.02
        Target of the local refinement: while the interpolated plan exceeds a
        limit by more than this (relative, measured on the chain-rule
        derivatives at >= 8 points per grid interval and at least every
        ``control_period / 10``), the limits of the grid nodes around the
        excess are divided by ``(1 + excess)**r`` in round ``r = 1, 2, ...``
        and the LP is re-solved from the previous basis.  None disables the
        refinement.  The result is in ``SpeedPlan.excess_estimate``; it may
        stay above the target after ``refine_rounds`` rounds.
    refine_rounds : int, default 8
        Maximum number of refinement rounds.
    lp_backend : {"auto", "highspy", "linprog"}, default "auto"
        ``"highspy"`` keeps one HiGHS model and hot-starts every re-solve;
        ``"linprog"`` solves each LP from scratch with
        :func:`scipy.optimize.linprog`; ``"auto"`` takes highspy if installed.
    grid : {"uniform", "adaptive"}, default "uniform"
        ``"uniform"``: the ``n`` points are uniform in ``u``.  ``"adaptive"``
        (experimental): the LP runs on a parameter ``sigma`` with
        ``u = g(sigma)`` chosen so that a uniform ``sigma`` grid is half
        uniform in arc length and half uniform in an estimated time (denser at
        the rest ends and in tight curls); ``u`` and ``b`` of the plan are
        reported in ``u``.  On the 10 m square spiral it gives 0.5-2 % shorter
        plans than ``"uniform"`` at the same ``n`` and excess, but on paths
        whose end hooks are shorter than a grid cell its pseudo-jerk
        iteration can cycle and stop the vehicle at the last interior node
        (``InfeasibleError``) or plan twice as slowly.

    Returns
    -------
    SpeedPlan
        The plan; ``setpoints()`` and ``verify()`` give the time domain.

    Raises
    ------
    InputError
        Malformed argument.
    InfeasibleError
        The LP has no solution.
    SolverError
        HiGHS failed otherwise.
    """
    _validate(
        curve,
        n,
        float(vmax),
        control_period=float(control_period),
        chord_error=chord_error,
        jerk_iterations=jerk_iterations,
        safety=safety,
    )
    backend = _validate_refine(max_excess, refine_rounds, lp_backend, grid)
    n = int(n)
    d = _eval(curve, np.array([0.0, 1.0]), 1).shape[1]
    amax_a = per_axis("amax", amax, d)
    jmax_a = None if jmax is None else per_axis("jmax", jmax, d)
    umap = None
    path: PathCurve = curve
    if grid == "adaptive":
        umap = _grid_map(curve, n, vmax=float(vmax), amax=amax_a, jmax=jmax_a)
        path = _Reparam(curve, umap)
    sig = np.linspace(0.0, 1.0, n)
    c1, c2, c3 = _derivs3(path, sig)
    speed2 = np.sum(c1 * c1, axis=1)
    if np.any(speed2 <= 1e-24):
        bad = sig[np.argmin(speed2)]
        raise InputError(f"curve has a vanishing derivative |C'(u)| = 0 near u = {bad:.6g}")
    ub, vb = _speed_bounds(c1, c2, float(vmax), chord_error=chord_error, period=control_period)
    a = _acc_matrix(sig, (c1, c2), amax_a * safety)
    if jmax_a is not None:
        a = sparse.vstack([a, _jerk_matrix((c1, c2, c3), jmax_a * safety, vb)], format="csr")
    lp = _GridLP(a, backend=backend)
    bounds = _Bounds(ub, None if jmax_a is None else vb, d, *_ones(n))
    log: tuple[list[float], list[float]] = ([], [])
    stop = (int(jerk_iterations), float(jerk_tol))
    b, iterations = _initial_solve(lp, bounds, c1=c1, jmax=jmax_a, stop=stop, log=log)
    plan = SpeedPlan(
        curve=curve,
        u=sig,
        b=b,
        duration=0.0,
        iterations=0,
        solve_time=0.0,
        objectives=(),
        jerk_changes=(),
        vmax=float(vmax),
        amax=amax_a,
        jmax=jmax_a,
        control_period=float(control_period),
        _bspline=_profile_spline(sig, b, jerk=jmax_a is not None),
        _path=path,
        _sigma=sig,
        _bsig=b,
        _umap=umap,
        grid=grid,
    )
    plan, rounds, est, extra = _refine(
        plan, lp, bounds, target=max_excess, rounds=refine_rounds, stop=stop, log=log
    )
    return replace(
        _in_caller_parameter(plan),
        duration=_duration(plan._bsig, sig[1], jerk=jmax_a is not None),
        iterations=iterations + extra,
        solve_time=lp.time,
        objectives=tuple(log[0]),
        jerk_changes=tuple(log[1]),
        refinements=rounds,
        excess_estimate=est,
        lp_solves=lp.solves,
    )


def _profile_spline(sig: FloatArray, b: FloatArray, *, jerk: bool) -> BSpline:
    """Grid-profile interpolant: cubic in ``w = b**(3/4)`` (jerk limit), else linear in ``b``."""
    return _w_spline(b, sig[1]) if jerk else make_interp_spline(sig, b, k=1)


def _in_caller_parameter(plan: SpeedPlan) -> SpeedPlan:
    """``u``, ``b`` in the caller's parameter: ``u = g(sigma)``, ``b = b_sigma g'**2``."""
    if plan._umap is None:
        return replace(plan, u=plan._sigma, b=plan._bsig)
    u = np.clip(np.asarray(plan._umap(plan._sigma), dtype=np.float64), 0.0, 1.0)
    g1 = np.asarray(plan._umap(plan._sigma, 1), dtype=np.float64)
    return replace(plan, u=u, b=plan._bsig * g1**2)


def _initial_solve(
    lp: _GridLP,
    bounds: _Bounds,
    *,
    c1: FloatArray,
    jmax: FloatArray | None,
    stop: tuple[int, float],
    log: tuple[list[float], list[float]],
) -> tuple[FloatArray, int]:
    """Jerk-free LP; with a jerk limit then the end caps and the pseudo-jerk iteration."""
    b = lp.solve(bounds.rows(None), bounds.cols())
    log[0].append(float(b.sum()))
    if jmax is None:
        return b, 0
    _end_caps(bounds.ub, c1, jmax)
    start = lp.solve(bounds.rows(None), bounds.cols())
    log[0].append(float(start.sum()))
    return _pseudo_jerk(lp, bounds, start, stop=stop, log=log)


def _refine(
    plan: SpeedPlan,
    lp: _GridLP,
    bounds: _Bounds,
    *,
    target: float | None,
    rounds: int,
    stop: tuple[int, float],
    log: tuple[list[float], list[float]],
) -> tuple[SpeedPlan, int, float, int]:
    """Tighten the limits locally and re-solve until the estimated excess meets ``target``.

    Returns
    -------
    tuple
        Final plan, refinement rounds done, its estimated max excess, extra
        pseudo-jerk iterations.
    """
    done = extra = 0
    while True:
        excess = _interval_excess(plan)
        est = float(max(np.max(x) for x in excess))
        if target is None or est <= target or done >= rounds:
            return plan, done, est, extra
        _tighten(bounds, excess, power=1.0 + done)
        if plan.jmax is None:
            b = lp.solve(bounds.rows(None), bounds.cols())
            log[0].append(float(b.sum()))
        else:
            b, its = _pseudo_jerk(lp, bounds, plan._bsig, stop=stop, log=log)
            extra += its
        spline = _profile_spline(plan._sigma, b, jerk=plan.jmax is not None)
        plan = replace(plan, _bsig=b, _bspline=spline)
        done += 1
