"""The adaptive grid: a map ``u = g(sigma)`` whose uniform ``sigma`` grid suits the path."""

from __future__ import annotations

import numpy as np
from scipy.interpolate import BSpline, make_interp_spline

from skyquill.coverage.speed.curve import PathCurve, _eval
from skyquill.validation import FloatArray

#: Share of the adaptive grid spread uniformly in arc length (the rest: uniformly in
#: the estimated time, which crowds the points at the rest ends and tight curls).
_ARC_SHARE = 0.5
#: The time estimate floors the speed at this fraction of ``vmax`` (bounds the crowding).
_V_FLOOR = 0.05
#: Table points per grid point for building the adaptive grid.
_TABLE = 8
#: Width (in grid cells) of the smoothing of the adaptive grid's density.
_SMOOTH_CELLS = 10


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
