"""Part of a trajectory, on its own clock: what a vehicle flies between two instants.

A delivered flight's mission is its plan between the end of the take-off and the start of the
landing (:mod:`skyquill.phases`); a Crazyflie uploads only that part, PX4 streams only that
part. Polynomial kinds are cut exactly (each cut piece re-expanded at its new start, so a
Crazyswarm file holds it as it was); others are viewed through :class:`TimeWindow`.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import comb

import numpy as np

from skyquill.errors import InputError
from skyquill.trajectory.base import Samples, Trajectory, evaluation_times, sample
from skyquill.trajectory.polynomial import PiecewisePolynomial
from skyquill.trajectory.sequence import RestToRestSequence
from skyquill.trajectory.spline import SplineTrajectory
from skyquill.validation import FloatArray

#: Pieces shorter than this at a cut are dropped, s (a cut a rounding away from a break).
SLIVER_S = 1e-9


@dataclass(frozen=True)
class TimeWindow:
    """``base`` from ``start`` to ``end`` (s), on a clock from 0."""

    base: Trajectory
    start: float
    end: float

    @property
    def duration(self) -> float:
        """Length, s."""
        return self.end - self.start

    @property
    def dim(self) -> int:
        """Number of axes."""
        return self.base.dim

    @property
    def breakpoints(self) -> FloatArray:
        """The base's breakpoints inside the window, with its ends, shifted to 0, s."""
        inner = np.asarray(self.base.breakpoints, dtype=float)
        inner = inner[(inner > self.start) & (inner < self.end)]
        return np.concatenate([[0.0], inner - self.start, [self.duration]])

    def evaluate(self, t: FloatArray, order: int = 0) -> FloatArray:
        """The base's ``order``-th derivative at ``start + t``."""
        times = evaluation_times(t, self.duration)
        return self.base.evaluate(np.minimum(times + self.start, self.base.duration), order)

    def sample(self, rate: float) -> Samples:
        """Samples at ``rate`` Hz over the window."""
        return sample(self, rate)


def time_window(traj: Trajectory, start: float, end: float) -> Trajectory:
    """``traj`` between ``start`` and ``end`` (s), re-timed from 0.

    The whole trajectory is returned as it is; a spline or piecewise polynomial becomes a
    :class:`PiecewisePolynomial` cut exactly; a rest-to-rest sequence keeps its pieces
    (cut at the ends), so its rests stay where uploads may change; other kinds are viewed
    through :class:`TimeWindow`.

    Raises
    ------
    InputError
        When ``start < 0``, ``end`` beyond the duration, or ``end <= start``.
    """
    duration = traj.duration
    tol = 1e-9 * max(1.0, duration)
    if not (-tol <= start < end <= duration + tol):
        raise InputError(
            f"window: got [{start:g}, {end:g}] s, expected 0 <= start < end <= {duration:g} s"
        )
    start, end = max(0.0, start), min(duration, end)
    if start <= tol and end >= duration - tol:
        return traj
    if isinstance(traj, SplineTrajectory):
        return _polynomial_window(PiecewisePolynomial(*traj.to_piecewise_polynomial()), start, end)
    if isinstance(traj, PiecewisePolynomial):
        return _polynomial_window(traj, start, end)
    if isinstance(traj, RestToRestSequence):
        return _sequence_window(traj, start, end)
    return TimeWindow(traj, start, end)


def _polynomial_window(traj: PiecewisePolynomial, start: float, end: float) -> PiecewisePolynomial:
    """The pieces over ``[start, end]``, the first re-expanded at ``start``."""
    breaks = np.asarray(traj.breaks, dtype=float)
    first = max(0, int(np.searchsorted(breaks, start + SLIVER_S, side="right")) - 1)
    last = min(traj.n_pieces - 1, int(np.searchsorted(breaks, end - SLIVER_S, side="left")) - 1)
    last = max(first, last)
    coeffs = np.array(traj.coeffs[first : last + 1], dtype=float)
    coeffs[0] = _shifted(coeffs[0], start - breaks[first])
    new_breaks = np.concatenate([[start], breaks[first + 1 : last + 1], [end]]) - start
    return PiecewisePolynomial(new_breaks, coeffs)


def _shifted(coeffs: FloatArray, delta: float) -> FloatArray:
    """Power-basis coefficients (K, d) of ``p(tau + delta)``: the Taylor shift."""
    k = coeffs.shape[0]
    out = np.zeros_like(coeffs)
    for j in range(k):
        for i in range(j, k):
            out[j] += comb(i, j) * coeffs[i] * delta ** (i - j)
    return out


def _sequence_window(traj: RestToRestSequence, start: float, end: float) -> Trajectory:
    """The sequence's pieces over ``[start, end]``, the two at its ends cut."""
    starts = traj.starts
    parts = []
    for offset, piece, stop in zip(starts[:-1], traj.pieces, starts[1:], strict=True):
        lo, hi = max(start, float(offset)), min(end, float(stop))
        if hi - lo > SLIVER_S:
            parts.append(time_window(piece, lo - float(offset), hi - float(offset)))
    return parts[0] if len(parts) == 1 else RestToRestSequence(tuple(parts))
