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
and the LP re-solved with HiGHS (``scipy.optimize.linprog``).

Discretisation choices (the grid LP is otherwise optimistic):

* Between grid points ``b`` is taken piecewise linear in ``u`` (constant
  ``u_ddot``); the acceleration constraint is imposed for every interval at
  both ends and the midpoint with that interval's slope.  The duration is the
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
* Remaining inter-grid excess is measured by :meth:`SpeedPlan.verify`; the
  ``safety`` factor scales the acceleration/jerk limits handed to the LP.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt
from scipy import sparse
from scipy.interpolate import BSpline, make_interp_spline
from scipy.optimize import linprog

from skyquill.errors import InfeasibleError, InputError, SolverError

FloatArray = npt.NDArray[np.float64]

# scipy-stubs do not list a sparse A_ub; HiGHS accepts it.
_linprog: Callable[..., Any] = linprog

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
        Uniform parameter grid on ``[0, 1]``.
    b : ndarray, shape (n,)
        ``u_dot**2`` at the grid points (0 at both ends).
    duration : float
        Traversal time of the piecewise-constant-``u_ddot`` model.
    iterations : int
        Pseudo-jerk LPs solved after the jerk-free LP (0 without jerk limit).
    solve_time : float
        Total wall time spent in the LP solver, seconds.
    objectives : tuple of float
        ``sum(b)`` of every LP, in order: jerk-free; with a jerk limit then
        jerk-free with the rest-end caps, the pseudo-jerk iterates and the
        certification LP.
    jerk_changes : tuple of float
        ``max |sqrt(b_k) - sqrt(b_{k-1})| / max sqrt(b_k)`` per iteration.
    vmax, amax, jmax :
        The limits (``amax``/``jmax`` per axis).
    control_period : float
        Interpolation period ``T`` of §2.2.
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

    def _b_eval(self, u: FloatArray, nu: int) -> FloatArray:
        return np.asarray(self._bspline(u, nu), dtype=np.float64)

    def setpoints(self, period: float | None = None) -> Setpoints:
        """Interpolate the plan at a fixed period by the Taylor expansion of §2.2.

        ``u_{k+1} = u_k + u_dot_k T + u_ddot_k T**2 / 2`` with
        ``u_dot = sqrt(b(u))``, ``u_ddot = b'(u)/2``.  At the start, where
        ``u_dot = u_ddot = 0`` can stall the recursion, a tiny parameter step is
        used (the paper's "small initial speed").  The walk ends at ``u = 1`` as
        soon as the step would overshoot or the speed would reverse.

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
        return self._samples(self._taylor_walk(T), T)

    def _exact_walk(self, T: float) -> FloatArray:
        """Sample ``u(t)`` of the piecewise-linear-``b`` model at period ``T``.

        Within a grid interval ``u_ddot = s/2`` is constant, so the Taylor
        expansion of §2.2 taken from the interval's start node is exact; a
        control period that straddles nodes is split there.
        """
        sq = np.sqrt(self.b)
        h = self.u[1] - self.u[0]
        tn = np.concatenate([[0.0], np.cumsum(2.0 * h / (sq[:-1] + sq[1:]))])
        m = int(np.floor(tn[-1] / T))
        t = T * np.arange(m + 1, dtype=np.float64)
        i = np.clip(np.searchsorted(tn, t, side="right") - 1, 0, self.u.size - 2)
        tau = t - tn[i]
        slope = (self.b[i + 1] - self.b[i]) / h
        u = self.u[i] + sq[i] * tau + 0.25 * slope * tau**2
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

    def _taylor_walk(self, T: float) -> FloatArray:
        """Recursion ``u_{k+1} = u_k + u_dot T + u_ddot T**2/2 (+ u_dddot T**3/6)``.

        The second-order expansion of §2.2 stalls at a jerk-limited rest start
        (``u_dot = u_ddot = 0``); the paper injects a small initial speed, here
        the third-order term (bounded in the ``w`` representation) is added.
        The walk snaps to ``u = 1`` once the step would overshoot or the speed
        would reverse within the period.
        """
        max_steps = int(10.0 * self.duration / T) + 1000
        us = [0.0]
        uk = 0.0
        one = np.empty(1)
        for _ in range(max_steps):
            one[0] = uk
            d1, d2, d3 = (float(x[0]) for x in self._derivs(one))
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
        c0, c1, c2, c3 = (_eval(self.curve, uarr, k) for k in range(4))
        v = c1 * ud[:, None]
        a = c2 * (ud**2)[:, None] + c1 * udd[:, None]
        j = c3 * (ud**3)[:, None] + 3.0 * c2 * (ud * udd)[:, None] + c1 * uddd[:, None]
        return Setpoints(t=t, u=uarr, p=c0, v=v, a=a, j=j, period=T)

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


def _limit(name: str, value: float | npt.ArrayLike, d: int) -> FloatArray:
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim == 0:
        arr = np.full(d, float(arr))
    if arr.shape != (d,):
        raise InputError(f"{name} must be a scalar or shape ({d},), got shape {arr.shape}")
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0.0):
        raise InputError(f"{name} must be positive and finite, got {arr.tolist()}")
    return arr


def _solve(cost: FloatArray, a_ub: Any, ub: FloatArray) -> tuple[FloatArray, float]:
    """Maximise ``sum(b)`` s.t. ``a_ub b <= 1``, ``0 <= b <= ub`` with HiGHS."""
    bounds = list(zip(np.zeros_like(ub).tolist(), ub.tolist(), strict=True))
    t0 = time.perf_counter()
    res = _linprog(cost, A_ub=a_ub, b_ub=np.ones(a_ub.shape[0]), bounds=bounds, method="highs")
    dt = time.perf_counter() - t0
    if res.status == 2:
        raise InfeasibleError("speed-planning LP is infeasible", ("speed_lp",))
    if res.status != 0 or res.x is None:
        raise SolverError(f"HiGHS failed on the speed-planning LP: {res.message}")
    return np.maximum(np.asarray(res.x, dtype=np.float64), 0.0), dt


def _acc_matrix(
    curve: PathCurve, u: FloatArray, c1: FloatArray, c2: FloatArray, amax: FloatArray
) -> Any:
    """Rows ``|C'' b + 0.5 C' b'| / amax <= 1`` of the piecewise-linear-``b`` model.

    Every interval is checked at its two ends and its midpoint, each with the
    interval's own slope ``b' = (b_{k+1} - b_k) / h``.
    """
    n, d = c1.shape
    h = u[1] - u[0]
    um = 0.5 * (u[:-1] + u[1:])
    m1, m2 = _eval(curve, um, 1), _eval(curve, um, 2)
    k_idx = np.arange(n - 1)
    ri = np.concatenate([k_idx, k_idx])
    ci = np.concatenate([k_idx, k_idx + 1])
    rows = []
    for p1, p2, wl in ((c1[:-1], c2[:-1], 1.0), (m1, m2, 0.5), (c1[1:], c2[1:], 0.0)):
        left = p2 * wl - 0.5 * p1 / h
        right = p2 * (1.0 - wl) + 0.5 * p1 / h
        for ax in range(d):
            data = np.concatenate([left[:, ax], right[:, ax]]) / amax[ax]
            rows.append(sparse.csr_array((data, (ri, ci)), shape=(n - 1, n)))
    acc = sparse.vstack(rows, format="csr")
    return sparse.vstack([acc, -acc], format="csr")


def _jerk_matrix(
    derivs: tuple[FloatArray, FloatArray, FloatArray], jmax: FloatArray, ref: FloatArray
) -> Any:
    """Pseudo-jerk rows ``sqrt(ref_i) |X_i(b)| / jmax <= 1`` at interior nodes.

    ``X_i = C3 b_i + 1.5 C2 (b_{i+1} - b_{i-1}) / (2h)
    + 0.5 C1 (b_{i+1} - 2 b_i + b_{i-1}) / h**2`` with ``Ck`` the k-th
    derivative of the curve.
    """
    c1, c2, c3 = derivs
    n, d = c1.shape
    h = 1.0 / (n - 1)
    i_idx = np.arange(1, n - 1)
    cm = -1.5 * c2[1:-1] / (2 * h) + 0.5 * c1[1:-1] / h**2
    cc = c3[1:-1] - c1[1:-1] / h**2
    cp = 1.5 * c2[1:-1] / (2 * h) + 0.5 * c1[1:-1] / h**2
    r = np.sqrt(np.maximum(ref[1:-1], 0.0))
    ri = np.tile(np.arange(n - 2), 3)
    ci = np.concatenate([i_idx - 1, i_idx, i_idx + 1])
    blocks = []
    for ax in range(d):
        sc = r / jmax[ax]
        data = np.concatenate([cm[:, ax] * sc, cc[:, ax] * sc, cp[:, ax] * sc])
        blocks.append(sparse.csr_array((data, (ri, ci)), shape=(n - 2, n)))
    jr = sparse.vstack(blocks, format="csr")
    return sparse.vstack([jr, -jr], format="csr")


def _pseudo_jerk(
    cost: FloatArray,
    a_acc: Any,
    ub: FloatArray,
    *,
    derivs: tuple[FloatArray, FloatArray, FloatArray],
    jmax: FloatArray,
    stop: tuple[int, float],
    log: tuple[list[float], list[float]],
) -> tuple[FloatArray, int, float]:
    """Pseudo-jerk fixed-point iteration followed by the certification LP.

    Starting from the jerk-free optimum (an over-estimate), each LP linearises
    ``sqrt(b)`` at the previous iterate; the iterates then alternate around the
    fixed point with shrinking amplitude.  The final LP linearises at
    ``B = max(b_k, b_{k-1})`` and imposes ``b <= B``, which makes the true
    grid jerk ``sqrt(b) |X| <= sqrt(B) |X| <= jmax``.

    Parameters
    ----------
    cost, a_acc, ub
        LP objective, acceleration rows and upper bounds.
    derivs
        ``C', C'', C'''`` on the grid.
    jmax
        Per-axis jerk limit used in the LP.
    stop
        ``(max_iterations, tolerance)`` on the relative change of ``sqrt(b)``.
    log
        Lists that receive the objectives and the relative changes.

    Returns
    -------
    tuple
        Final ``b``, number of iterations, LP time.
    """
    max_iter, tol = stop
    objectives, changes = log
    b, total = _solve(cost, a_acc, ub)
    objectives.append(float(b.sum()))
    prev = prev2 = b
    iterations = 0
    for _ in range(max_iter):
        a_ub = sparse.vstack([a_acc, _jerk_matrix(derivs, jmax, prev)], format="csr")
        bn, dt = _solve(cost, a_ub, ub)
        total += dt
        iterations += 1
        objectives.append(float(bn.sum()))
        sq_new = np.sqrt(bn)
        change = float(np.max(np.abs(sq_new - np.sqrt(prev))) / max(np.max(sq_new), 1e-300))
        changes.append(change)
        prev2, prev = prev, bn
        if change < tol and iterations >= 2:
            break
    big = np.maximum(prev, prev2)
    a_ub = sparse.vstack([a_acc, _jerk_matrix(derivs, jmax, big)], format="csr")
    b, dt = _solve(cost, a_ub, np.minimum(ub, big))
    objectives.append(float(b.sum()))
    return b, iterations, total + dt


def _duration(b: FloatArray, h: float, *, jerk: bool) -> float:
    """Traversal time of the grid model, finite at the rest ends.

    Without jerk limit ``b`` is linear per interval (constant ``u_ddot``) and
    ``dt = 2h / (sqrt(b_i) + sqrt(b_{i+1}))`` is exact.  With a jerk limit
    ``w = b**(3/4)`` is taken linear per interval and ``int w**(-2/3) du``
    is integrated exactly.
    """
    sq = np.sqrt(b)
    if np.any(sq[:-1] + sq[1:] <= 0.0):
        raise InfeasibleError("planned speed vanishes on an interior interval", ("speed_lp",))
    if not jerk:
        return float(np.sum(2.0 * h / (sq[:-1] + sq[1:])))
    w = b**0.75
    cw = np.cbrt(w)
    dw = w[1:] - w[:-1]
    same = np.abs(dw) <= 1e-12 * np.maximum(w[1:], 1e-300)
    safe_dw = np.where(same, 1.0, dw)
    seg = np.where(
        same, h / np.maximum(w[:-1], 1e-300) ** (2.0 / 3.0), 3.0 * h * (cw[1:] - cw[:-1]) / safe_dw
    )
    return float(np.sum(seg))


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
        Maximum number of pseudo-jerk iterations.
    jerk_tol : float, default 1e-3
        Stop when the relative change of ``sqrt(b)`` falls below this.
    safety : float, default 1.0
        Factor in ``(0, 1]`` applied to ``amax`` and ``jmax`` inside the LP, to
        absorb the inter-grid excess reported by :meth:`SpeedPlan.verify`.

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
    n = int(n)
    vmax_f = float(vmax)
    T = float(control_period)
    u = np.linspace(0.0, 1.0, n)
    h = 1.0 / (n - 1)
    c1, c2, c3 = (_eval(curve, u, k) for k in (1, 2, 3))
    d = c1.shape[1]
    amax_a = _limit("amax", amax, d)
    jmax_a = None if jmax is None else _limit("jmax", jmax, d)
    amax_lp = amax_a * safety
    jmax_lp = None if jmax_a is None else jmax_a * safety

    speed2 = np.sum(c1 * c1, axis=1)
    if np.any(speed2 <= 1e-24):
        bad = u[np.argmin(speed2)]
        raise InputError(f"curve has a vanishing derivative |C'(u)| = 0 near u = {bad:.6g}")
    ub = vmax_f**2 / speed2
    if chord_error is not None:
        cross2 = np.maximum(speed2 * np.sum(c2 * c2, axis=1) - np.sum(c1 * c2, axis=1) ** 2, 0.0)
        with np.errstate(divide="ignore"):
            rho = np.where(cross2 > 0.0, speed2**1.5 / np.sqrt(cross2), np.inf)
        ub = np.minimum(ub, 8.0 * rho * float(chord_error) / T**2 / speed2)
    ub[0] = 0.0
    ub[-1] = 0.0

    a_acc = _acc_matrix(curve, u, c1, c2, amax_lp)
    cost = -np.ones(n)
    b, total_time = _solve(cost, a_acc, ub)
    objectives = [float(b.sum())]
    changes: list[float] = []
    iterations = 0
    bspl: BSpline
    if jmax_lp is None:
        bspl = make_interp_spline(u, b, k=1)
    else:
        # Rest ends: the first/last interval is crossed in dt = 2h/sqrt(b_1) with
        # acceleration 0.5 C' b_1 / h that must build up from 0 at <= jmax:
        # 0.5 |C'_k| b_1 / h <= jmax_k * 2 h / sqrt(b_1).
        for node in (1, n - 2):
            with np.errstate(divide="ignore"):
                cap = (4.0 * jmax_lp * h * h / np.abs(c1[node])) ** (2.0 / 3.0)
            ub[node] = min(ub[node], float(np.min(cap)))
        b, iterations, lp_time = _pseudo_jerk(
            cost,
            a_acc,
            ub,
            derivs=(c1, c2, c3),
            jmax=jmax_lp,
            stop=(int(jerk_iterations), jerk_tol),
            log=(objectives, changes),
        )
        total_time += lp_time
        # Cubic B-spline *quasi-interpolant* of w = b**(3/4) with the w_i as
        # coefficients (odd reflection at the rest ends): at the knots w'' and
        # w' are exactly the discrete second/central differences and w'' is
        # linear in between, so there is none of the ringing an interpolating
        # spline shows at the kinks of the optimal profile.
        w = b**0.75
        coef = np.concatenate([[-w[1]], w, [-w[-2]]])
        knots = h * (np.arange(n + 6, dtype=np.float64) - 3.0)
        bspl = BSpline(knots, coef, 3, extrapolate=False)
    duration = _duration(b, h, jerk=jmax_lp is not None)
    return SpeedPlan(
        curve=curve,
        u=u,
        b=b,
        duration=duration,
        iterations=iterations,
        solve_time=total_time,
        objectives=tuple(objectives),
        jerk_changes=tuple(changes),
        vmax=vmax_f,
        amax=amax_a,
        jmax=jmax_a,
        control_period=T,
        _bspline=bspl,
    )
