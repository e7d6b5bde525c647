"""One polynomial per piece in the power basis: Crazyswarm files, min-snap peers, Ruckig legs."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.polynomial.polynomial as npoly
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.trajectory.base import Samples, check_breakpoints, evaluation_times, sample
from skyquill.trajectory.horner import horner_at
from skyquill.validation import FloatArray, as_array, as_int


@dataclass(frozen=True)
class PiecewisePolynomial:
    """``p(t) = sum_j coeffs[i, j] (t - breaks[i])^j`` on piece ``i``.

    Parameters
    ----------
    breaks
        Piece boundaries, shape (P + 1,), s; starts at 0, strictly increasing.
    coeffs
        Power-basis coefficients, shape (P, K, d), lowest order first, in
        local time ``tau = t - breaks[i]`` (m / s^j).
    yaw_coeffs
        Optional heading in the same layout, shape (P, K_yaw), rad / s^j
        (Crazyswarm files carry one; :meth:`evaluate_yaw`).

    Notes
    -----
    At an interior break the piece on its right is used; the end belongs to
    the last piece. Arrays are stored as read-only copies.
    """

    breaks: FloatArray
    coeffs: FloatArray
    yaw_coeffs: FloatArray | None = None

    def __post_init__(self) -> None:
        breaks = check_breakpoints("breaks", self.breaks)
        n = breaks.size - 1
        coeffs = as_array("coeffs", self.coeffs, shape=(n, None, None))
        if coeffs.shape[1] < 1 or coeffs.shape[2] < 1:
            raise InputError(
                f"coeffs: got shape {coeffs.shape}, expected at least 1 coefficient and 1 axis"
            )
        coeffs.setflags(write=False)
        object.__setattr__(self, "breaks", breaks)
        object.__setattr__(self, "coeffs", coeffs)
        if self.yaw_coeffs is not None:
            yaw = as_array("yaw_coeffs", self.yaw_coeffs, shape=(n, None))
            yaw.setflags(write=False)
            object.__setattr__(self, "yaw_coeffs", yaw)

    @classmethod
    def trusted(cls, breaks: FloatArray, coeffs: FloatArray) -> PiecewisePolynomial:
        """The polynomial of arrays its caller has just computed, not checked again.

        For planners that build many small trajectories (a stop-and-go chain of ten legs
        costs less than checking it): ``breaks`` must already be float64, start at 0 and
        increase strictly, ``coeffs`` be finite float64 of shape (P, K, d). Both are taken
        as they are (no copy) and made read-only, so the caller must not keep writing them.
        """
        poly = object.__new__(cls)
        breaks.setflags(write=False)
        coeffs.setflags(write=False)
        # (The fields written into the instance's dict, as the frozen dataclass's own
        # __init__ would leave them: a third cheaper than three object.__setattr__ calls.)
        fields = poly.__dict__
        fields["breaks"] = breaks
        fields["coeffs"] = coeffs
        fields["yaw_coeffs"] = None
        return poly

    @property
    def duration(self) -> float:
        """Total length, s."""
        return float(self.breaks[-1])

    @property
    def dim(self) -> int:
        """Number of axes ``d``."""
        return int(self.coeffs.shape[2])

    @property
    def degree(self) -> int:
        """Polynomial degree of every piece (``K - 1``)."""
        return int(self.coeffs.shape[1] - 1)

    @property
    def n_pieces(self) -> int:
        """Number of pieces ``P``."""
        return int(self.breaks.size - 1)

    @property
    def breakpoints(self) -> FloatArray:
        """The piece boundaries, shape (P + 1,), s."""
        return self.breaks

    def _locate(self, t: FloatArray) -> tuple[FloatArray, NDArray[np.intp]]:
        times = evaluation_times(t, self.duration)
        idx = np.clip(np.searchsorted(self.breaks, times, side="right") - 1, 0, self.n_pieces - 1)
        return times - self.breaks[idx], idx

    def evaluate(self, t: FloatArray, order: int = 0) -> FloatArray:
        """The ``order``-th time derivative at times ``t``.

        Parameters
        ----------
        t
            Times, shape (N,), each in ``[0, duration]`` s.
        order
            0 (position, m) and up (m/s^order); exact polynomial derivatives,
            0 above the degree.

        Returns
        -------
        numpy.ndarray, shape (N, d)
        """
        order = as_int("order", order, low=0)
        tau, idx = self._locate(t)
        return horner_at(self.coeffs, idx, tau, order).reshape(tau.size, self.dim)

    def evaluate_orders(self, t: FloatArray, orders: Sequence[int]) -> dict[int, FloatArray]:
        """``{n: self.evaluate(t, n)}`` for each of ``orders``, the pieces looked up once.

        The same arrays as :meth:`evaluate` order by order, bit for bit; shape (N, d) each.
        """
        checked = [as_int("order", n, low=0) for n in orders]
        tau, idx = self._locate(t)
        return {n: horner_at(self.coeffs, idx, tau, n).reshape(tau.size, self.dim) for n in checked}

    def evaluate_yaw(self, t: FloatArray, order: int = 0) -> FloatArray:
        """The ``order``-th time derivative of yaw, shape (N,), rad / s^order (0 without yaw)."""
        order = as_int("order", order, low=0)
        tau, idx = self._locate(t)
        if self.yaw_coeffs is None:
            return np.zeros(tau.size)
        return horner_at(self.yaw_coeffs, idx, tau, order).reshape(tau.size)

    def sample(self, rate: float) -> Samples:
        """Samples at ``rate`` Hz (position to jerk), including both ends."""
        return sample(self, rate)

    def squared_derivative_integral(self, order: int) -> float:
        """Exact ``∫ ||d^order p / dt^order||^2 dt`` over the trajectory.

        By polynomial algebra on the coefficients (derivative, square,
        antiderivative; :mod:`numpy.polynomial`), not by sampling; in
        m^2 / s^(2 order - 1).
        """
        order = as_int("order", order, low=0)
        if order > self.degree:
            return 0.0
        c = npoly.polyder(self.coeffs, m=order, axis=1) if order else self.coeffs
        durations = np.diff(self.breaks)
        total = 0.0
        for i in range(c.shape[0]):
            for k in range(c.shape[2]):
                anti = npoly.polyint(npoly.polymul(c[i, :, k], c[i, :, k]))
                total += float(npoly.polyval(durations[i], anti))
        return total
