"""The speed plan: result types, the interpolated profile and its time-domain samples."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import BSpline, make_interp_spline

from skyquill.coverage.speed.curve import PathCurve, _eval
from skyquill.errors import InfeasibleError, InputError
from skyquill.limits import BoxLimit, CylinderLimit, DerivativeLimit
from skyquill.trajectory import RetimedPath
from skyquill.validation import FloatArray
from skyquill.verify import Verification, verify


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
        jerk-free (with a jerk limit, with the rest-end caps); with a jerk
        limit then the pseudo-jerk iterates and the certification LP; then per
        refinement round its iterates and certification LP (one LP per round
        without jerk limit).
    jerk_changes : tuple of float
        ``max |sqrt(b_k) - sqrt(b_{k-1})| / max sqrt(b_k)`` per iteration
        (refinement rounds appended).
    vmax, amax, jmax :
        The limits (``amax``/``jmax`` per axis; with ``norm_sides`` every
        entry is the one norm limit).
    control_period : float
        Interpolation period ``T`` of §2.2.
    refinements : int
        Rounds of local limit tightening (see ``max_excess`` of :func:`plan_speed`).
    excess_estimate : float
        Largest relative excess of the interpolated plan over a limit, from
        the chain-rule derivatives where :meth:`verify` looks (see
        ``max_excess`` of :func:`plan_speed`), up to the timing law it flies.
    lp_solves : int
        Number of LPs solved.
    grid : str
        ``"uniform"`` or ``"adaptive"`` (see :func:`plan_speed`).
    method : str
        The solver that answered (``method`` of :func:`plan_speed`): ``"reach"`` (the
        reachability passes solved every problem), ``"warm"``, ``"banded"`` or ``"lp"``
        (``"lp"`` also where HiGHS had to answer for the passes or the interior point).
    norm_sides : int or None
        None: ``amax``/``jmax`` hold per axis.  Else they are Euclidean norm
        limits, held in the LP by the inscribed polygon of this many sides
        (see ``norm_sides`` of :func:`plan_speed`) and measured as norms by
        ``excess_estimate`` and :meth:`verify`.
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
    norm_sides: int | None = None
    method: str = "lp"

    def _b_eval(self, u: FloatArray, nu: int) -> FloatArray:
        return np.asarray(self._bspline(u, nu), dtype=np.float64)

    def setpoints(self, period: float | None = None) -> Setpoints:
        """Sample the plan at a fixed period (:meth:`walk`), with the chain-rule rates.

        Without a jerk limit the §2.2 Taylor expansion is exact per grid
        interval (constant ``u_ddot``); with one, the walk samples the C2 timing
        law of :meth:`trajectory` (the paper's recursion at the full period
        showed its truncation error as 8 % jerk excess on a circle).

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
        return self._samples(self.walk(T), T)

    def walk(self, period: float) -> FloatArray:
        """The planning parameter every ``period`` s from 0 (rest) to 1 (rest), shape (m,).

        The last step is shorter than ``period`` (the walk snaps to 1). With a
        jerk limit it samples the timing law of :meth:`trajectory` (vectorised:
        the §2.2 Taylor recursion it replaces was a Python loop of up to
        ``10 duration / period`` steps, 1.3 M on a 100 m field).
        """
        if self.jmax is None:
            return self._exact_walk(period)
        from skyquill.coverage.speed.retime import planning_law

        law = planning_law(self)
        t = period * np.arange(math.ceil(law.duration / period - 1e-9), dtype=np.float64)
        u = np.minimum(np.maximum.accumulate(law.evaluate(t)[:, 0]), 1.0)
        return np.asarray(np.append(u, 1.0), dtype=np.float64)

    def trajectory(self, z: float | None = None) -> RetimedPath:
        """The plan as a trajectory (:func:`~skyquill.coverage.speed.retime.retimed_path`)."""
        from skyquill.coverage.speed.retime import retimed_path

        return retimed_path(self, z)

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
            return rates_of_b(self._b_eval(u, 0), self._b_eval(u, 1))
        return rates_of_w(self._b_eval(u, 0), self._b_eval(u, 1), self._b_eval(u, 2))

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

    def limits(self, dim: int) -> tuple[DerivativeLimit, ...]:
        """The plan's limits as the verifier states them for a ``dim``-axis trajectory.

        The speed is a norm (the LP holds ``|C'|^2 b <= vmax^2``); acceleration
        and jerk are per-axis boxes, or norms with ``norm_sides``. A 3-D
        trajectory of a 2-D plan (lifted to a height) has those norms horizontal.
        """
        out: list[DerivativeLimit] = [_norm_limit(1, self.vmax, dim)]
        for order, bound in ((2, self.amax), (3, self.jmax)):
            if bound is None:
                continue
            if self.norm_sides is not None:
                out.append(_norm_limit(order, float(np.min(bound)), dim))
            else:
                upper = np.resize(np.asarray(bound, dtype=float), dim)
                out.append(BoxLimit(order, -upper, upper))
        return tuple(out)

    def verify(self, z: float | None = None) -> Verification:
        """The one dense check (:func:`skyquill.verify.verify`) of :meth:`trajectory`.

        The limits are held on the LP's grid only: they are reported as not
        guaranteed, with the excess measured.
        """
        traj = self.trajectory(z)
        return verify(traj, self.limits(traj.dim), guaranteed=False)


def _norm_limit(order: int, bound: float, dim: int) -> CylinderLimit:
    """``|horizontal derivative| <= bound`` (and the vertical component within it in 3-D)."""
    if dim == 3:
        return CylinderLimit(order, bound, z_lower=-bound, z_upper=bound)
    return CylinderLimit(order, bound)


def rates_of_b(b: FloatArray, b1: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``u_dot``, ``u_ddot``, ``u_dddot`` (each like ``b``) of a profile linear in ``b``
    (no jerk limit), from ``b`` and ``b' = db/du``: ``sqrt(b)``, ``b' / 2`` and 0."""
    return np.sqrt(np.maximum(b, 0.0)), 0.5 * b1, np.zeros_like(b)


def rates_of_w(
    w: FloatArray, w1: FloatArray, w2: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``u_dot``, ``u_ddot``, ``u_dddot`` (each like ``w``) of a jerk-limited profile, from
    ``w = b**(3/4)`` and its first two derivatives in ``u`` (see :meth:`SpeedPlan._derivs`)."""
    w = np.maximum(w, 0.0)
    ud = w ** (2.0 / 3.0)
    udd = (2.0 / 3.0) * np.cbrt(w) * w1
    uddd = (2.0 / 9.0) * w1**2 + (2.0 / 3.0) * w * w2
    return ud, udd, uddd


def _profile_spline(sig: FloatArray, b: FloatArray, *, jerk: bool) -> BSpline:
    """Grid-profile interpolant: cubic in ``w = b**(3/4)`` (jerk limit), else linear in ``b``."""
    return _w_spline(b) if jerk else make_interp_spline(sig, b, k=1)


def _w_spline(b: FloatArray) -> BSpline:
    """Cubic B-spline *quasi-interpolant* of ``w = b**(3/4)`` on the uniform grid of ``[0, 1]``.

    The ``w_i`` are the coefficients, with odd reflection at the rest ends.
    At the knots ``w''`` and ``w'`` are exactly the discrete second/central
    differences and ``w''`` is linear in between, so there is none of the
    ringing an interpolating spline shows at the kinks of the optimal profile.
    """
    w = b**0.75
    coef = np.concatenate([[-w[1]], w, [-w[-2]]])
    # Knots i / (n - 1), not i * h: the spline does not extrapolate, and
    # h * (n - 1) can round to 1 - 1e-16, which put u = 1 outside the base
    # interval (NaN acceleration and jerk in the last setpoint).
    knots = (np.arange(b.size + 6, dtype=np.float64) - 3.0) / (b.size - 1)
    return BSpline(knots, coef, 3, extrapolate=False)


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
