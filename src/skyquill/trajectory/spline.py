"""The clamped uniform B-spline the engine returns (paper 003 eq. 4-5)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
from scipy.interpolate import BSpline

from skyquill.limits import DerivativeLimit
from skyquill.spline import ClampedUniformBasis, basis_for, uniform_design
from skyquill.trajectory.base import (
    DENSE_MIN_TOTAL,
    DENSE_PER_SPAN,
    Samples,
    evaluation_times,
    sample,
)
from skyquill.validation import FloatArray, as_array, as_float, as_int

if TYPE_CHECKING:
    from skyquill.verify import Region, Verification


@dataclass(frozen=True)
class SplineTrajectory:
    """Clamped uniform B-spline ``p(t) = sum_i c_i N_i^k(alpha t)``.

    Parameters
    ----------
    control_points
        Shape (M, d), metres.
    degree
        Degree ``k``, 1 to 7.
    duration
        Seconds; ``alpha = (M - k) / duration`` (paper 003 eq. 5).
    """

    control_points: FloatArray
    degree: int
    duration: float

    def __post_init__(self) -> None:
        ctrl = as_array("control_points", self.control_points, ndim=2)
        as_int("degree", self.degree, low=1, high=7)
        as_float("duration", self.duration, positive=True)
        ClampedUniformBasis(self.degree, ctrl.shape[0])  # validates M >= k + 1
        ctrl.setflags(write=False)
        object.__setattr__(self, "control_points", ctrl)

    @property
    def dim(self) -> int:
        """Number of axes ``d``."""
        return int(self.control_points.shape[1])

    def in_3d(self, z: float = 0.0) -> SplineTrajectory:
        """This spline with 3 axes: a 2-D one at height ``z`` (exact: partition of unity)."""
        if self.dim == 3:
            return self
        ctrl = self.control_points
        lifted = np.column_stack([ctrl, np.full((ctrl.shape[0], 3 - self.dim), z)])
        return SplineTrajectory(lifted, self.degree, self.duration)

    @cached_property
    def basis(self) -> ClampedUniformBasis:
        """The basis in the normalised parameter ``s`` (shared cache)."""
        return basis_for(self.degree, int(self.control_points.shape[0]))

    @property
    def alpha(self) -> float:
        """Time scale ``s / t`` in spans per second."""
        return self.basis.n_spans / self.duration

    @property
    def knot_times(self) -> FloatArray:
        """Distinct knot times (breakpoints), shape (L + 1,), s."""
        return np.arange(self.basis.n_spans + 1) / self.alpha

    @property
    def breakpoints(self) -> FloatArray:
        """The knot times: where its polynomial pieces meet, shape (L + 1,), s."""
        return self.knot_times

    @cached_property
    def _splines(self) -> dict[int, BSpline]:
        """The curve (key 0) and the derivatives asked for so far (:meth:`_spline`)."""
        return {0: BSpline(self.basis.knots / self.alpha, self.control_points, self.degree)}

    def _spline(self, order: int) -> BSpline:
        """The ``order``-th derivative as a BSpline, built on first use: the fidelity
        checks of a writing plan ask for positions and accelerations only."""
        if order not in self._splines:
            self._splines[order] = self._splines[0].derivative(order)
        return self._splines[order]

    def evaluate(self, t: FloatArray, order: int = 0) -> FloatArray:
        """The ``order``-th time derivative at times ``t``.

        Parameters
        ----------
        t
            Times, shape (N,), each in ``[0, duration]`` s.
        order
            0 (position) and up; orders above the degree are identically 0.

        Returns
        -------
        numpy.ndarray, shape (N, d)
        """
        times = evaluation_times(t, self.duration)
        as_int("order", order, low=0)
        if order > self.degree:
            return np.zeros((times.size, self.dim))
        return np.asarray(self._spline(order)(times), dtype=float).reshape(times.size, self.dim)

    def sample(self, rate: float) -> Samples:
        """Samples at ``rate`` Hz (position to jerk), including both ends."""
        return sample(self, rate)

    def _n_dense(self) -> int:
        return max(DENSE_MIN_TOTAL, DENSE_PER_SPAN * self.basis.n_spans + 1)

    def dense_times(self) -> FloatArray:
        """Times for the dense check: >= 20 per knot span and >= 10,000 in all."""
        return np.linspace(0.0, self.duration, self._n_dense())

    def dense_derivatives(self, orders: Sequence[int]) -> dict[int, FloatArray]:
        """Derivatives at :meth:`dense_times`, ``{order: (N, d)}``.

        Equal to ``evaluate(dense_times(), order)`` but through a cached sparse
        design matrix: one sparse product per order.
        """
        out = {}
        for order in orders:
            if order > self.degree:
                out[order] = np.zeros((self._n_dense(), self.dim))
                continue
            D = uniform_design(self.degree, self.basis.n_ctrl, order, self._n_dense())
            out[order] = self.alpha**order * np.asarray(D @ self.control_points)
        return out

    def verify(
        self, limits: Sequence[DerivativeLimit] = (), corridors: Sequence[Region] = ()
    ) -> Verification:
        """The dense check (docs/architecture.md) against ``limits`` and ``corridors``."""
        from skyquill.verify import verify  # the verifier imports the trajectory kinds

        return verify(self, limits, corridors)

    def derivative_control_points(self, order: int) -> FloatArray:
        """Control points of the ``order``-th time derivative, shape (M - order, d).

        Paper 003 eq. (37): ``alpha^n Gamma_n C``.
        """
        return np.asarray(
            self.alpha**order * (self.basis.derivative_map(order) @ self.control_points)
        )

    def to_piecewise_polynomial(self) -> tuple[FloatArray, FloatArray]:
        """Exact conversion to one polynomial per knot span.

        Returns
        -------
        breaks : numpy.ndarray, shape (L + 1,)
            Span boundaries, s.
        coeffs : numpy.ndarray, shape (L, k + 1, d)
            Power-basis coefficients in local time ``tau = t - breaks[i]``,
            lowest order first: ``p(t) = sum_j coeffs[i, j] tau^j``.
        """
        # Taylor coefficients at each span's left end: BSpline evaluates a
        # breakpoint with the span to its right, so these are right limits.
        breaks = self.knot_times
        left = breaks[:-1]
        coeffs = np.stack(
            [self._spline(j)(left) / math.factorial(j) for j in range(self.degree + 1)], axis=1
        )
        return breaks, np.asarray(coeffs, dtype=float)
