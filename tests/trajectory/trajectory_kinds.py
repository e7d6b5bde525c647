"""Small trajectories of every kind, with closed forms to check them against."""

from __future__ import annotations

import numpy as np
from scipy.interpolate import BSpline, make_interp_spline

from skyquill.trajectory import PiecewisePolynomial, RetimedPath
from skyquill.validation import FloatArray

#: Coefficients of the rest-to-rest septic smoothstep s(x) = 35x^4 - 84x^5 + 70x^6 - 20x^7.
SMOOTHSTEP7 = np.array([0.0, 0.0, 0.0, 0.0, 35.0, -84.0, 70.0, -20.0])


def rest_to_rest_leg(start: FloatArray, end: FloatArray, duration: float) -> PiecewisePolynomial:
    """A straight leg from rest to rest: one septic piece (velocity to jerk 0 at both ends)."""
    scale = SMOOTHSTEP7 / duration ** np.arange(8)
    coeffs = scale[:, None] * (np.asarray(end) - np.asarray(start))[None, :]
    coeffs[0] += start
    return PiecewisePolynomial(np.array([0.0, duration]), coeffs[None])


def arc_curve() -> BSpline:
    """A quintic B-spline through a quarter circle of radius 2 m on u in [0, 1]."""
    u = np.linspace(0.0, 1.0, 12)
    pts = np.column_stack([2.0 * np.cos(0.5 * np.pi * u), 2.0 * np.sin(0.5 * np.pi * u)])
    return make_interp_spline(u, pts, k=5)


def smoothstep_timing(duration: float, n: int = 40) -> tuple[FloatArray, ...]:
    """Samples t, u, u', u'' of the quintic rest-to-rest law u = 10x^3 - 15x^4 + 6x^5."""
    t = np.linspace(0.0, duration, n)
    x = t / duration
    u = 10 * x**3 - 15 * x**4 + 6 * x**5
    u1 = (30 * x**2 - 60 * x**3 + 30 * x**4) / duration
    u2 = (60 * x - 180 * x**2 + 120 * x**3) / duration**2
    return t, u, u1, u2


def retimed_arc(duration: float = 4.0) -> RetimedPath:
    """The arc flown rest to rest along the quintic law."""
    return RetimedPath.from_samples(arc_curve(), *smoothstep_timing(duration))
