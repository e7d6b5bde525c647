"""The speed plan as a trajectory: the path and its timing law, defined at every time.

The §2.2 walk gives the path parameter at the control period; with the
chain-rule rates at the same points it fixes a C2 timing law ``u(t)`` (the
quintic Hermite interpolant, :meth:`RetimedPath.from_samples`), so the
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
    sig, t = _grid_times(plan)
    sd, sdd, _ = plan._derivs(sig)
    sd[0] = sd[-1] = 0.0  # rest at both ends, exactly
    if plan._umap is None:
        u, ud, udd = sig.copy(), sd, sdd
    else:
        g1, g2 = (np.asarray(plan._umap(sig, k), dtype=float) for k in (1, 2))
        u = np.clip(np.asarray(plan._umap(sig), dtype=float), 0.0, 1.0)
        ud, udd = g1 * sd, g2 * sd**2 + g1 * sdd
    u[0], u[-1] = 0.0, 1.0
    return RetimedPath.from_samples(lifted, t, u, ud, udd)


def _exact_law(plan: SpeedPlan) -> PiecewisePolynomial:
    """Without a jerk limit ``b`` is linear per grid interval: ``u(t)`` is exactly quadratic."""
    sig, b = plan._sigma, plan._bsig
    h = float(sig[1] - sig[0])
    steps = _interval_times(b, h, jerk=False)
    start_rate = np.sqrt(np.maximum(b[:-1], 0.0))
    coeffs = np.stack([sig[:-1], start_rate, 0.25 * np.diff(b) / h], axis=1)[:, :, None]
    return PiecewisePolynomial(np.concatenate([[0.0], np.cumsum(steps)]), coeffs)


def _grid_times(plan: SpeedPlan) -> tuple[FloatArray, FloatArray]:
    """The LP's grid and the time at each node, ``t = ∫ d sigma / sigma_dot``.

    The nodes are the profile's own knots: between them the rate is smooth, so
    the quintic law through (parameter, rate, its derivative) at the nodes is
    accurate to high order. (Through the walk's points at the control period,
    which straddle the knots where the profile's third derivative jumps, it
    was not: 9-13 % spurious jerk on the 10 m square's spiral.) Each
    interval's time is Gauss-Legendre quadrature of ``1 / sigma_dot``; on the
    first and last interval, where the rate vanishes at the rest end like a
    power below 1, in a variable ``x`` with ``sigma - end ~ x^3``, which makes
    the integrand smooth.
    """
    sig = plan._sigma
    lo, hi = sig[:-1], sig[1:]
    x = 0.5 * (_GL_NODES + 1.0)  # on [0, 1]
    w = 0.5 * _GL_WEIGHTS
    # sigma = lo + (hi - lo) * s(x), s(x) = x on interior intervals; x^3 from the rest start;
    # 1 - (1 - x)^3 into the rest end.
    shape = np.tile(x, (lo.size, 1))
    slope = np.ones_like(shape)
    shape[0], slope[0] = x**3, 3.0 * x**2
    shape[-1], slope[-1] = 1.0 - (1.0 - x) ** 3, 3.0 * (1.0 - x) ** 2
    points = lo[:, None] + (hi - lo)[:, None] * shape
    rate = plan._derivs(points.ravel())[0].reshape(points.shape)
    steps = (hi - lo) * (w[None, :] * slope / np.maximum(rate, 1e-300)).sum(axis=1)
    return sig.copy(), np.concatenate([[0.0], np.cumsum(steps)])


#: Gauss-Legendre rule of the time quadrature.
_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(8)
