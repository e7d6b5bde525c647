"""The speed plan as a trajectory: the path and its timing law, defined at every time.

The §2.2 walk gives the path parameter at the control period; with the
chain-rule rates at the same points it fixes a C2 timing law ``u(t)`` (the
quintic Hermite interpolant, as :meth:`RetimedPath.from_samples` builds it), so the
trajectory written, checked, flown and exported is one object rather than a
list of setpoints. With the adaptive grid the walk runs on the planning
parameter ``sigma``; the law is mapped to the curve's own parameter
``u = g(sigma)`` by the chain rule, so the trajectory holds the caller's curve.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from scipy.interpolate import BSpline

from skyquill.coverage.speed.profile import _interval_times
from skyquill.errors import InputError
from skyquill.trajectory import PiecewisePolynomial, RetimedPath
from skyquill.validation import FloatArray

if TYPE_CHECKING:
    from skyquill.coverage.speed.profile import SpeedPlan


def retimed_path(plan: SpeedPlan, z: float | None = None) -> RetimedPath:
    """``plan`` as a :class:`RetimedPath`; a 2-D curve is lifted to height ``z`` if given."""
    curve = plan.curve
    if not isinstance(curve, BSpline):
        raise InputError(f"curve: got {type(curve).__name__}, expected a scipy BSpline")
    coeffs = np.asarray(curve.c, dtype=float)
    if z is not None and coeffs.shape[1] == 2:
        coeffs = np.column_stack([coeffs, np.full(coeffs.shape[0], float(z))])
    lifted = BSpline(curve.t, coeffs, curve.k)
    if plan.jmax is None and plan._umap is None:
        return RetimedPath(lifted, _exact_law(plan))
    t, sig, sd, sdd = _node_rates(plan)
    if plan._umap is None:
        u, ud, udd = sig.copy(), sd, sdd
    else:
        g1, g2 = (np.asarray(plan._umap(sig, k), dtype=float) for k in (1, 2))
        u = np.clip(np.asarray(plan._umap(sig), dtype=float), 0.0, 1.0)
        ud, udd = g1 * sd, g2 * sd**2 + g1 * sdd
    u[0], u[-1] = 0.0, 1.0
    return RetimedPath(lifted, quintic_law(t, u, ud, udd))


def planning_law(plan: SpeedPlan) -> PiecewisePolynomial:
    """The planning parameter ``sigma(t)`` (the LP's, before any grid map), s -> [0, 1].

    The quintic law through the grid nodes and their rates, as
    :func:`retimed_path` builds it: :meth:`SpeedPlan.walk` samples it.
    """
    return quintic_law(*_node_rates(plan))


def _node_rates(plan: SpeedPlan) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Times, planning parameter and its first two rates at the law's nodes."""
    sig, t = _grid_times(plan)
    sd, sdd, _ = plan._derivs(sig)
    sd[0] = sd[-1] = 0.0  # rest at both ends, exactly
    if plan.jmax is not None:  # b ~ s^(4/3) at a jerk-limited rest end: no acceleration there
        sdd[0] = sdd[-1] = 0.0
    sig = sig.copy()
    sig[0], sig[-1] = 0.0, 1.0
    return t, sig, sd, sdd


def quintic_law(
    t: FloatArray, u: FloatArray, u_dot: FloatArray, u_ddot: FloatArray
) -> PiecewisePolynomial:
    """The quintic Hermite interpolant of ``u``, ``u'``, ``u''`` at times ``t`` (N,), s.

    The same C2 law as :meth:`RetimedPath.from_samples` (scipy's
    ``BPoly.from_derivatives``), in closed form for all pieces at once:
    scipy builds it piece by piece in Python, 28 s of a 60 s plan at 370k
    pieces (a 316 m field), where this takes milliseconds.

    Returns
    -------
    PiecewisePolynomial
        One axis, breaks ``t - t[0]`` (s), coefficients (N - 1, 6, 1) in local time.
    """
    h = np.diff(t)
    p0, p1 = u[:-1], u[1:]
    v0, v1 = u_dot[:-1], u_dot[1:]
    a0, a1 = u_ddot[:-1], u_ddot[1:]
    dp = p1 - p0
    c3 = (20.0 * dp - (8.0 * v1 + 12.0 * v0) * h - (3.0 * a0 - a1) * h**2) / (2.0 * h**3)
    c4 = (-30.0 * dp + (14.0 * v1 + 16.0 * v0) * h + (3.0 * a0 - 2.0 * a1) * h**2) / (2.0 * h**4)
    c5 = (12.0 * dp - 6.0 * (v1 + v0) * h - (a0 - a1) * h**2) / (2.0 * h**5)
    coeffs = np.stack([p0, v0, 0.5 * a0, c3, c4, c5], axis=1)[:, :, None]
    return PiecewisePolynomial(np.asarray(t, dtype=float) - float(t[0]), coeffs)


def _exact_law(plan: SpeedPlan) -> PiecewisePolynomial:
    """Without a jerk limit ``b`` is linear per grid interval: ``u(t)`` is exactly quadratic."""
    sig, b = plan._sigma, plan._bsig
    h = float(sig[1] - sig[0])
    steps = _interval_times(b, h, jerk=False)
    start_rate = np.sqrt(np.maximum(b[:-1], 0.0))
    coeffs = np.stack([sig[:-1], start_rate, 0.25 * np.diff(b) / h], axis=1)[:, :, None]
    return PiecewisePolynomial(np.concatenate([[0.0], np.cumsum(steps)]), coeffs)


def _grid_times(plan: SpeedPlan) -> tuple[FloatArray, FloatArray]:
    """Nodes on the LP's grid (subdivided to the control period) and their times.

    The nodes include the profile's own knots: between them the rate is
    smooth, so the quintic law through (parameter, rate, its derivative) at the
    nodes is accurate to high order. (Through the walk's points at the control
    period, which straddle the knots where the profile's third derivative
    jumps, it was not: 9-13 % spurious jerk on the 10 m square's spiral.) A
    grid interval that takes longer than the control period (slow turns,
    adaptive grids) is cut into equal parts that do not, so that no piece of
    the law spans more of the path's own changes than the walk would.
    """
    sig = plan._sigma
    steps = _times(plan, sig)
    parts = np.maximum(1, np.ceil(steps / (_PIECE_PERIODS * plan.control_period))).astype(int)
    if np.any(parts > 1):
        start = np.repeat(sig[:-1], parts)
        width = np.repeat(np.diff(sig) / parts, parts)
        within = np.arange(parts.sum()) - np.repeat(np.cumsum(parts) - parts, parts)
        sig = np.append(start + width * within, sig[-1])
        steps = _times(plan, sig)
    return sig.copy(), np.concatenate([[0.0], np.cumsum(steps)])


def _times(plan: SpeedPlan, nodes: FloatArray) -> FloatArray:
    """Time between consecutive ``nodes``, ``∫ d sigma / sigma_dot`` (Gauss-Legendre).

    On the first and last interval, where the rate vanishes at the rest end
    like a power below 1, the integral is taken in a variable ``x`` with
    ``sigma - end ~ x^3``, which makes the integrand smooth.
    """
    lo, hi = nodes[:-1], nodes[1:]
    x = 0.5 * (_GL_NODES + 1.0)  # on [0, 1]
    w = 0.5 * _GL_WEIGHTS
    shape = np.tile(x, (lo.size, 1))
    slope = np.ones_like(shape)
    shape[0], slope[0] = x**3, 3.0 * x**2
    shape[-1], slope[-1] = 1.0 - (1.0 - x) ** 3, 3.0 * (1.0 - x) ** 2
    points = lo[:, None] + (hi - lo)[:, None] * shape
    rate = plan._derivs(points.ravel())[0].reshape(points.shape)
    return np.asarray((hi - lo) * (w[None, :] * slope / np.maximum(rate, 1e-300)).sum(axis=1))


#: Gauss-Legendre rule of the time quadrature.
_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(8)
#: Longest piece of the timing law, in control periods.
_PIECE_PERIODS = 5
