"""A drone's position on the show clock as exact polynomial pieces, with bounds on its motion.

The separation check (:mod:`skyquill.show.separation`) needs two things of a
drone: its position at any time, and a *guaranteed* bound on how fast it can
move on an interval. Both are exact on a piecewise polynomial, so every
trajectory kind is turned into one (:func:`motion_of`):

* :class:`~skyquill.trajectory.PiecewisePolynomial` (a ``.skyc`` as played)
  as it is;
* :class:`~skyquill.trajectory.SplineTrajectory` by its exact conversion;
* :class:`~skyquill.trajectory.SampledTrajectory` (``trajectory.csv``) as
  skyquill flies it: the cubic Hermite through the positions and velocities;
* :class:`~skyquill.trajectory.RetimedPath` (coverage) by composing its curve's
  polynomial spans with its timing law's pieces;
* :class:`~skyquill.trajectory.RestToRestSequence` piece after piece.

A drone that has finished holds its last position until the show ends.

On an interval ``[a, b]`` inside one piece the Taylor expansion at the midpoint
``m`` is exact (the piece is a polynomial), so with ``r = (b - a) / 2``

    |v(t)| <= sum_q |p^(q+1)(m)| r^q / q!     for every t in [a, b],

and the same sum over the *difference* of two drones' derivatives bounds their
relative speed: drones flying in formation move together and their bound is ~0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from itertools import pairwise

import numpy as np
from numpy.polynomial import Polynomial
from numpy.typing import NDArray
from scipy.interpolate import BSpline, CubicHermiteSpline

from skyquill.errors import InputError
from skyquill.trajectory import (
    PiecewisePolynomial,
    RestToRestSequence,
    RetimedPath,
    SampledTrajectory,
    SplineTrajectory,
    Trajectory,
)
from skyquill.trajectory.horner import horner, horner_at
from skyquill.validation import FloatArray

#: Largest position jump accepted where pieces meet, m. Exported files are not exactly
#: continuous: Skybrush stores millimetres and its firmware evaluates in float32, so a
#: skyquill ``.skyc`` played back jumps by a few micrometres. Jumps up to this are
#: accounted for in the separation bound (:attr:`Motion.jump_m`); a larger one is not
#: round-off but a broken trajectory.
JUMP_TOLERANCE_M = 1e-3


@dataclass(frozen=True)
class LocalMotion:
    """What a drone does on a batch of intervals ``[a, b]``.

    Attributes
    ----------
    derivatives
        Derivatives of position of orders 1 to ``K - 1`` at each midpoint,
        shape (N, K - 1, 3) (m/s, m/s^2, ...); valid where ``inside``.
    inside
        Whether the interval lies within one polynomial piece, shape (N,).
    speed
        A guaranteed bound of the speed on each interval, shape (N,), m/s.
    jump
        A bound of how far the position jumps inside each interval (where pieces
        meet; 0 where ``inside``), shape (N,), m.
    """

    derivatives: FloatArray
    inside: NDArray[np.bool_]
    speed: FloatArray
    jump: FloatArray


def taylor_bound(derivatives: FloatArray, half_width: FloatArray) -> FloatArray:
    """``sum_q |D_q| r^q / q!``: a bound of ``|v|`` on ``[m - r, m + r]`` (N,), m/s.

    ``derivatives`` (N, Q, 3) are orders 1.. of a polynomial's position at ``m``;
    ``half_width`` is ``r`` (N,), s.
    """
    norms = np.linalg.norm(derivatives, axis=2)
    q = np.arange(derivatives.shape[1])
    weights = half_width[:, None] ** q[None, :] / np.array([math.factorial(int(k)) for k in q])
    return np.asarray((norms * weights).sum(axis=1))


@dataclass(frozen=True)
class Motion:
    """A drone's position on ``[0, horizon]``: polynomial pieces, held after its end.

    Parameters
    ----------
    breaks
        Piece boundaries, shape (P + 1,), s, from 0 to the horizon.
    coeffs
        Power-basis coefficients in local time, shape (P, K, 3), lowest first (m / s^j).
    jump_m
        The largest position jump where two pieces meet, m (round-off of a file).
    """

    breaks: FloatArray
    coeffs: FloatArray
    jump_m: float = 0.0

    @property
    def horizon(self) -> float:
        """End of the show clock, s."""
        return float(self.breaks[-1])

    @property
    def order(self) -> int:
        """Number of coefficients per piece ``K``."""
        return int(self.coeffs.shape[1])

    def _piece(self, t: FloatArray, side: str) -> NDArray[np.intp]:
        found = np.searchsorted(self.breaks, t, side="right" if side == "right" else "left") - 1
        return np.clip(found, 0, self.breaks.size - 2)

    def position(self, t: FloatArray) -> FloatArray:
        """Positions at times ``t`` (N,) in ``[0, horizon]``, shape (N, 3), m."""
        idx = self._piece(t, "right")
        return horner_at(self.coeffs, idx, t - self.breaks[idx], 0).reshape(t.size, 3)

    def derivatives_at(self, t: FloatArray, idx: NDArray[np.intp]) -> FloatArray:
        """Orders 1 to ``K - 1`` of piece ``idx`` (N,) at ``t`` (N,), shape (N, K - 1, 3)."""
        tau = t - self.breaks[idx]
        orders = [
            horner_at(self.coeffs, idx, tau, q).reshape(t.size, 3) for q in range(1, self.order)
        ]
        if not orders:
            return np.zeros((t.size, 0, 3))
        return np.stack(orders, axis=1)

    def local(self, a: FloatArray, b: FloatArray) -> LocalMotion:
        """Derivatives at the midpoints and speed bounds on the intervals ``[a, b]`` (N,)."""
        first = self._piece(a, "right")
        last = np.maximum(self._piece(b, "left"), first)
        inside = first == last
        mid = 0.5 * (a + b)
        derivatives = self.derivatives_at(mid, first)
        speed = taylor_bound(derivatives, 0.5 * (b - a))
        if not inside.all():
            speed[~inside] = self._straddling(a[~inside], b[~inside], first[~inside], last[~inside])
        derivatives[~inside] = 0.0
        return LocalMotion(derivatives, inside, speed, (last - first).astype(float) * self.jump_m)

    def _straddling(
        self, a: FloatArray, b: FloatArray, first: NDArray[np.intp], last: NDArray[np.intp]
    ) -> FloatArray:
        """Speed bounds on intervals across piece boundaries: the max over the parts."""
        head_end = self.breaks[first + 1]
        tail_start = self.breaks[last]
        head = self._within(a, head_end, first)
        tail = self._within(tail_start, b, last)
        bound = np.maximum(head, tail)
        between = last - first >= 2
        if between.any():
            # max over the pieces strictly between: reduceat on [first + 1, last) ranges
            edges = np.column_stack([first[between] + 1, last[between]]).ravel()
            inner = np.maximum.reduceat(self._whole_pieces, edges)[::2]
            bound[between] = np.maximum(bound[between], inner)
        return bound

    @cached_property
    def _whole_pieces(self) -> FloatArray:
        """Speed bound over each whole piece, shape (P + 1,) (a 0 appended for reduceat)."""
        pieces = np.arange(self.breaks.size - 1)
        return np.append(self._within(self.breaks[:-1], self.breaks[1:], pieces), 0.0)

    def _within(self, a: FloatArray, b: FloatArray, idx: NDArray[np.intp]) -> FloatArray:
        derivatives = self.derivatives_at(0.5 * (a + b), idx)
        return taylor_bound(derivatives, 0.5 * (b - a))


def motion_of(name: str, trajectory: Trajectory, horizon: float, start_s: float = 0.0) -> Motion:
    """``trajectory`` as exact polynomial pieces on ``[0, horizon]``, held before and after.

    Parameters
    ----------
    name
        The drone's name, for the error.
    trajectory
        Any of the kinds in the module docstring, 3 axes, z up, m.
    horizon
        End of the show, s, at least ``start_s`` plus the trajectory's duration.
    start_s
        Show time of the trajectory's 0, s; before it the drone waits at its start.

    Raises
    ------
    InputError
        For another kind (a coverage ``retimed`` path) or not 3 axes.
    """
    if trajectory.dim != 3:
        raise InputError(f"{name}: got {trajectory.dim} axes, expected 3 (x, y, z)")
    breaks, coeffs = _pieces(name, trajectory)
    ends = horner(coeffs, np.diff(breaks), 0).reshape(-1, 3)
    jump = _largest_jump(name, breaks, coeffs[1:, 0], ends[:-1])
    breaks = breaks + start_s
    if start_s > 0.0:
        breaks = np.concatenate([[0.0], breaks])
        coeffs = np.concatenate([_hold(coeffs[0, 0], coeffs.shape[1]), coeffs])
    if horizon > breaks[-1]:
        breaks = np.append(breaks, horizon)
        coeffs = np.concatenate([coeffs, _hold(ends[-1], coeffs.shape[1])])
    return Motion(np.asarray(breaks, dtype=float), np.asarray(coeffs, dtype=float), jump)


def _hold(point: FloatArray, order: int) -> FloatArray:
    """One piece standing at ``point`` (3,): shape (1, order, 3)."""
    hold = np.zeros((1, order, 3))
    hold[0, 0] = point
    return hold


def _largest_jump(name: str, breaks: FloatArray, starts: FloatArray, ends: FloatArray) -> float:
    """The largest jump where pieces meet, m; refused above :data:`JUMP_TOLERANCE_M`."""
    jumps = np.linalg.norm(starts - ends, axis=1)
    if not jumps.size:
        return 0.0
    k = int(np.argmax(jumps))
    if jumps[k] > JUMP_TOLERANCE_M:
        raise InputError(
            f"{name}: got a jump of {jumps[k]:.3g} m at t = {breaks[k + 1]:.6g} s, expected a "
            f"continuous trajectory (at most {JUMP_TOLERANCE_M:g} m where pieces meet)"
        )
    return float(jumps[k])


def _pieces(name: str, traj: Trajectory) -> tuple[FloatArray, FloatArray]:
    """``(breaks (P + 1,), coeffs (P, K, 3))`` of a trajectory, exactly."""
    if isinstance(traj, PiecewisePolynomial):
        return np.asarray(traj.breaks), np.asarray(traj.coeffs)
    if isinstance(traj, SplineTrajectory):
        return traj.to_piecewise_polynomial()
    if isinstance(traj, SampledTrajectory):
        hermite = CubicHermiteSpline(traj.breakpoints, traj.p, traj.v)
        return np.asarray(hermite.x), np.asarray(hermite.c)[::-1].transpose(1, 0, 2)
    if isinstance(traj, RestToRestSequence):
        return _joined(name, traj)
    if isinstance(traj, RetimedPath):
        return _retimed(traj)
    raise InputError(
        f"{name}: got a {type(traj).__name__} trajectory, expected a polynomial, B-spline, "
        "sampled, retimed or sequence trajectory (the guaranteed check needs polynomial pieces)"
    )


def _retimed(traj: RetimedPath) -> tuple[FloatArray, FloatArray]:
    """``C(u(t))`` exactly: cut where ``u`` crosses a knot of ``C``, compose the polynomials.

    Between two cuts ``C`` is one polynomial of degree ``k`` in ``u`` and ``u`` one of
    degree ``q`` in ``t``, so ``C(u(t))`` is one polynomial of degree ``k q``
    (:mod:`numpy.polynomial` composes them).
    """
    knots, taylor = _curve_spans(traj.curve)
    breaks = [0.0]
    pieces: list[FloatArray] = []
    timing = traj.timing
    kinks = traj.kink_times()  # the knot crossings, increasing
    first = np.searchsorted(kinks, timing.breaks, side="right")
    for i in range(timing.n_pieces):
        start, width = float(timing.breaks[i]), float(timing.breaks[i + 1] - timing.breaks[i])
        u = Polynomial(timing.coeffs[i, :, 0])
        inner = (kinks[first[i] : first[i + 1]] - start).tolist()
        for a, b in pairwise(sorted({0.0, *(c for c in inner if 0.0 < c < width), width})):
            local = u(Polynomial([a, 1.0]))  # u on [a, b], in time from a
            pieces.append(_composed(local, 0.5 * (b - a), knots, taylor))
            breaks.append(start + b)
    width = max(p.shape[0] for p in pieces)
    coeffs = np.stack([np.pad(p, ((0, width - p.shape[0]), (0, 0))) for p in pieces])
    return np.array(breaks), coeffs


def _composed(u: Polynomial, middle: float, knots: FloatArray, taylor: FloatArray) -> FloatArray:
    """``C(u(tau))`` on a stretch where ``u`` stays in one span: coefficients (K, 3), lowest first.

    ``middle`` is a time inside the stretch, which picks the span.
    """
    span = int(np.clip(np.searchsorted(knots, u(middle), "right") - 1, 0, knots.size - 2))
    shifted = u - knots[span]
    axes = [np.asarray(Polynomial(taylor[span, :, a])(shifted).coef, float) for a in range(3)]
    size = max(c.size for c in axes)  # numpy trims the zeros of a constant axis
    return np.stack([np.pad(c, (0, size - c.size)) for c in axes], axis=1)


def _curve_spans(curve: BSpline) -> tuple[FloatArray, FloatArray]:
    """Distinct knots of ``curve`` (S + 1,) and its Taylor coefficients at each span's start.

    Returns the knots and coefficients (S, k + 1, 3) in ``u - knots[s]``, lowest first.
    """
    k = curve.k
    knots = np.unique(curve.t[k : curve.t.size - k])
    orders = [curve, *(curve.derivative(m) for m in range(1, k + 1))]
    taylor = [
        np.asarray(d(knots[:-1]), dtype=float) / math.factorial(m) for m, d in enumerate(orders)
    ]
    return knots, np.stack(taylor, axis=1)


def _joined(name: str, seq: RestToRestSequence) -> tuple[FloatArray, FloatArray]:
    parts = [_pieces(f"{name} piece {i}", p) for i, p in enumerate(seq.pieces)]
    width = max(c.shape[1] for _, c in parts)
    breaks = [np.zeros(1)]
    coeffs = []
    for start, (b, c) in zip(seq.starts, parts, strict=False):
        breaks.append(start + b[1:])
        coeffs.append(np.pad(c, ((0, 0), (0, width - c.shape[1]), (0, 0))))
    return np.concatenate(breaks), np.concatenate(coeffs)
