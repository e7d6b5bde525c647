"""A path curve flown along a timing law: what coverage's speed planning produces.

The trajectory is ``p(t) = C(u(t))``: a B-spline curve ``C`` on ``u in [0, 1]``
and a timing law ``u(t)`` (a 1-D piecewise polynomial, non-decreasing from 0 to
1). Its derivatives come from the chain rule (Faà di Bruno up to order 4)

    v = C' u'
    a = C'' u'^2 + C' u''
    j = C''' u'^3 + 3 C'' u' u'' + C' u'''
    s = C'''' u'^4 + 6 C''' u'^2 u'' + C'' (3 u''^2 + 4 u' u''') + C' u''''

so they are finite wherever ``C`` and ``u`` are: everywhere, the ends included.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.interpolate import BPoly, BSpline, PPoly

from skyquill.errors import InputError
from skyquill.trajectory.base import Samples, sample
from skyquill.trajectory.polynomial import PiecewisePolynomial
from skyquill.validation import FloatArray, as_array, as_int

#: Highest derivative order :meth:`RetimedPath.evaluate` gives (snap: RotorPy asks for it).
MAX_ORDER = 4


@dataclass(frozen=True)
class RetimedPath:
    """``p(t) = C(u(t))``: a path curve and its timing law.

    Parameters
    ----------
    curve
        The path ``C(u)``, ``u in [0, 1]``: a B-spline with ``(n, d)``
        coefficients, metres.
    timing
        ``u(t)``, a :class:`PiecewisePolynomial` with one axis, from ``u(0) = 0``
        to ``u(duration) = 1``.
    """

    curve: BSpline
    timing: PiecewisePolynomial

    def __post_init__(self) -> None:
        if not isinstance(self.curve, BSpline):
            raise InputError(f"curve: got {type(self.curve).__name__}, expected a scipy BSpline")
        coeffs = as_array("curve coefficients", self.curve.c, ndim=2)
        if self.curve.t[self.curve.k] != 0.0 or self.curve.t[-self.curve.k - 1] != 1.0:
            raise InputError(
                f"curve: got a parameter range [{self.curve.t[self.curve.k]:g}, "
                f"{self.curve.t[-self.curve.k - 1]:g}], expected [0, 1]"
            )
        if self.timing.dim != 1:
            raise InputError(f"timing: got {self.timing.dim} axes, expected 1 (u of t)")
        ends = self.timing.evaluate(np.array([0.0, self.timing.duration]))[:, 0]
        if abs(ends[0]) > 1e-9 or abs(ends[1] - 1.0) > 1e-9:
            raise InputError(
                f"timing: got u(0) = {ends[0]:.9g} and u(end) = {ends[1]:.9g}, expected 0 and 1"
            )
        object.__setattr__(self, "curve", BSpline(self.curve.t, coeffs, self.curve.k))

    @classmethod
    def from_samples(
        cls, curve: BSpline, t: FloatArray, u: FloatArray, u_dot: FloatArray, u_ddot: FloatArray
    ) -> RetimedPath:
        """The timing law through samples of ``u``, ``u'`` and ``u''`` at times ``t`` (N,).

        The law is the quintic Hermite interpolant of the samples (C2, exact at
        every sample): a speed planner's walk becomes a trajectory defined at
        every time, not only at its samples.
        """
        values = np.column_stack([u, u_dot, u_ddot])[:, :, None]
        quintic = PPoly.from_bernstein_basis(BPoly.from_derivatives(t, values, orders=5))
        shift = np.asarray(t, dtype=float) - float(t[0])
        coeffs = np.asarray(quintic.c, dtype=float)[::-1].transpose(1, 0, 2)  # (P, 6, 1)
        return cls(curve, PiecewisePolynomial(shift, coeffs))

    @property
    def duration(self) -> float:
        """Length in seconds."""
        return self.timing.duration

    @property
    def dim(self) -> int:
        """Number of axes of the curve."""
        return int(np.asarray(self.curve.c).shape[1])

    @property
    def breakpoints(self) -> FloatArray:
        """The timing law's pieces, shape (P + 1,), s."""
        return self.timing.breakpoints

    def kink_times(self) -> FloatArray:
        """When the path crosses its curve's interior knots, shape (K,), s, increasing.

        There the curve's highest derivative jumps, and the flight's highest one with it
        (a degree-4 curve: the jerk has a kink, its snap a jump): a peak between the
        dense check's evenly spaced samples.
        """
        return self._kink_times

    @cached_property
    def _kink_times(self) -> FloatArray:
        knots = interior_knots(self.curve)
        # Each knot bracketed by the law's breakpoints, then bisected there.
        breaks = self.timing.breakpoints
        at_breaks = self.timing.evaluate(breaks)[:, 0]
        piece = np.clip(np.searchsorted(at_breaks, knots) - 1, 0, breaks.size - 2)
        return increasing_preimage(
            lambda t: self.timing.evaluate(t)[:, 0], knots, breaks[piece], breaks[piece + 1]
        )

    @cached_property
    def _curve_derivatives(self) -> tuple[BSpline, ...]:
        k = self.curve.k
        return (self.curve, *(self.curve.derivative(n) for n in range(1, min(k, MAX_ORDER) + 1)))

    def _curve(self, u: FloatArray, order: int) -> FloatArray:
        if order >= len(self._curve_derivatives):
            return np.zeros((u.size, self.dim))
        return np.asarray(self._curve_derivatives[order](np.clip(u, 0.0, 1.0)), dtype=float)

    def evaluate(self, t: FloatArray, order: int = 0) -> FloatArray:
        """The ``order``-th time derivative at times ``t`` (N,), by the chain rule.

        Returns
        -------
        numpy.ndarray, shape (N, d)

        Raises
        ------
        InputError
            For times outside ``[0, duration]`` or ``order`` above 4.
        """
        return self.evaluate_orders(t, [order])[order]

    def evaluate_orders(self, t: FloatArray, orders: Sequence[int]) -> dict[int, FloatArray]:
        """``{n: self.evaluate(t, n)}`` for each of ``orders``: the timing law and the
        curve evaluated once for all of them (the dense check asks for three).

        Returns
        -------
        dict of numpy.ndarray, shape (N, d) each

        Raises
        ------
        InputError
            For times outside ``[0, duration]`` or an order above 4.
        """
        checked = [as_int("order", n, low=0, high=MAX_ORDER) for n in orders]
        top = max(checked, default=0)
        u = self.timing.evaluate_orders(t, range(top + 1))
        c = [self._curve(u[0][:, 0], n) for n in range(top + 1)]
        return {n: _chain_rule(n, [u[k] for k in range(n + 1)], c) for n in checked}

    def sample(self, rate: float) -> Samples:
        """Samples at ``rate`` Hz (position to jerk), including both ends."""
        return sample(self, rate)


def _chain_rule(order: int, u: list[FloatArray], c: list[FloatArray]) -> FloatArray:
    """``d^order / dt^order C(u(t))`` from ``u``'s derivatives ``u[k]`` (N, 1) and the
    curve's ``c[k]`` (N, d) at ``u(t)``, ``k <= order`` (Faà di Bruno, the module's formulas)."""
    if order == 0:
        return c[0]
    u1 = u[1]
    if order == 1:
        return c[1] * u1
    u2 = u[2]
    if order == 2:
        return c[2] * u1**2 + c[1] * u2
    u3 = u[3]
    if order == 3:
        return c[3] * u1**3 + 3.0 * c[2] * u1 * u2 + c[1] * u3
    u4 = u[4]
    return c[4] * u1**4 + 6.0 * c[3] * u1**2 * u2 + c[2] * (3.0 * u2**2 + 4.0 * u1 * u3) + c[1] * u4


def interior_knots(spline: object) -> FloatArray:
    """The distinct knots strictly inside (0, 1) of a B-spline (none for another curve)."""
    knots = np.unique(np.asarray(getattr(spline, "t", ()), dtype=np.float64))
    inside: FloatArray = knots[(knots > 0.0) & (knots < 1.0)]
    return inside


#: Bisection steps: a bracket of the flight's length (or of [0, 1]) narrowed below a
#: double's resolution.
_BISECTIONS = 60


def increasing_preimage(
    f: Callable[[FloatArray], FloatArray], y: FloatArray, lo: FloatArray, hi: FloatArray
) -> FloatArray:
    """Where the non-decreasing ``f`` first reaches each of ``y`` (K,), bracketed by ``lo``
    and ``hi`` (K,): by bisection, all at once (``f`` evaluates an array)."""
    for _ in range(_BISECTIONS):
        mid = 0.5 * (lo + hi)
        below = np.asarray(f(mid), dtype=np.float64) < y
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    out: FloatArray = 0.5 * (lo + hi)
    return out
