"""Minimum-snap (and minimum-jerk, minimum-acceleration) interpolation by one banded solve.

The problem is the classical one of Mellinger & Kumar (2011) and Richter, Bry & Roy (2013):
through waypoints ``w_0 .. w_M`` at times ``t_0 < .. < t_M``, find the piecewise polynomial
``p`` minimising ``∫ ||p^(s)(t)||^2 dt`` (``s = 4``: snap), with the derivatives 1 .. s-1
given at both ends (rest by default). Its optimum is known in closed form
(the Euler-Lagrange conditions; Wang et al., "Geometrically Constrained Trajectory
Optimization for Multicopters", T-RO 2022, MINCO): every piece is a polynomial of degree
``2s - 1`` and the derivatives up to ``2s - 2`` are continuous at the interior waypoints.

So the unknowns are the derivatives 1 .. s-1 at the ``M - 1`` interior waypoints. The cost
is a quadratic in them whose Hessian is block-tridiagonal (a waypoint's derivatives touch
only the two pieces beside it) and positive definite: its normal equations -- the same
conditions as the continuity of the derivatives s .. 2s-2 -- are solved by a banded
Cholesky factorisation (LAPACK ``pbsv``), in time and memory linear in the number of
waypoints, for every axis at once.

Each piece is written in Hermite form on its normalised time ``u = tau / T``: its ``2s``
coefficients are a fixed linear map of the scaled end data ``(p, T v, T^2 a, ...)`` at
both ends, so the whole assembly is a handful of array operations.

This differs from paper 003's engine (:func:`skyquill.optimize.solve`), which represents the
same optimum in a clamped uniform B-spline (a few knot spans per waypoint segment): the
engine handles limits, corridors and deviation costs, this module the pure interpolation
problem, exactly and fast. Both are checked against each other and against the peer
``minsnap-trajectories`` in the tests and ``bench/engine.py``.
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
from numpy.typing import NDArray
from scipy.linalg.lapack import dpbsv

from skyquill.errors import InputError, SolverError
from skyquill.trajectory import PiecewisePolynomial
from skyquill.validation import FloatArray

#: Orders of the cost this module solves: 2 (acceleration), 3 (jerk), 4 (snap).
ORDERS = (2, 3, 4)
#: Shortest piece, relative to the mean piece: a piece's cost weight is ``T^(1-2s)``, so
#: shorter ones make the normal equations singular in float64.
MIN_RELATIVE_PIECE = 1e-6


def min_snap(
    waypoints: FloatArray,
    times: FloatArray,
    start: FloatArray | None = None,
    end: FloatArray | None = None,
    order: int = 4,
) -> PiecewisePolynomial:
    """The piecewise polynomial through ``waypoints`` at ``times`` with the least ``∫|p^(s)|^2``.

    Parameters
    ----------
    waypoints
        Positions, shape (M + 1, d), m, ``M >= 1``.
    times
        Arrival times, shape (M + 1,), s, strictly increasing (the result's clock starts at 0:
        ``times - times[0]``).
    start, end
        The derivatives 1 .. s-1 at the first and the last waypoint, shape (s - 1, d)
        (velocity m/s, acceleration m/s^2, jerk m/s^3, ...); rest (zeros) by default.
    order
        ``s``: 4 minimises the snap (pieces of degree 7), 3 the jerk (degree 5), 2 the
        acceleration (cubic).

    Returns
    -------
    PiecewisePolynomial
        ``M`` pieces of degree ``2s - 1``, continuous up to the derivative ``2s - 2``.

    Raises
    ------
    InputError
        Shapes that do not match, non-finite values, times that do not increase, a piece
        shorter than :data:`MIN_RELATIVE_PIECE` of the mean, an unknown ``order``.
    """
    w, t, s = _checked(waypoints, times, order)
    m, d = w.shape[0] - 1, w.shape[1]
    boundary = (_boundary("start", start, s, d), _boundary("end", end, s, d))
    # Work in time units of the mean piece, where every row of the system is O(1).
    unit = (t[-1] - t[0]) / m
    T = np.diff(t) / unit
    # Derivative k of axis a at waypoint i is derivs[k, a, i], in the time unit: the
    # waypoints run along the last axis, so every array operation below is a pass over
    # long rows (numpy's loops over a last axis of length d or s are several times slower).
    derivs = np.empty((s, d, m + 1))
    derivs[0] = w.T
    scale = unit ** np.arange(1, s)[:, None]
    derivs[1:, :, 0], derivs[1:, :, -1] = boundary[0] * scale, boundary[1] * scale
    if m > 1:
        derivs[1:, :, 1:-1] = _interior(derivs, T, s)
    breaks = np.empty(m + 1)
    breaks[0] = 0.0
    np.cumsum(T, out=breaks[1:])
    breaks[1:] *= unit
    coeffs = _power_coefficients(derivs, T, s, unit)
    if not np.isfinite(coeffs).all():  # pragma: no cover - finite input, a definite system
        raise SolverError("min_snap: the solve overflowed (waypoints too far apart?)")
    # Checked here (increasing breaks: every step is positive), so not again.
    return PiecewisePolynomial.trusted(breaks, coeffs)


def _checked(
    waypoints: FloatArray, times: FloatArray, order: int
) -> tuple[FloatArray, FloatArray, int]:
    if isinstance(order, bool) or order not in ORDERS:
        raise InputError(f"order: got {order!r}, expected one of {ORDERS}")
    w = np.asarray(waypoints, dtype=np.float64)
    t = np.asarray(times, dtype=np.float64)
    if w.ndim != 2 or w.shape[0] < 2 or w.shape[1] < 1:
        raise InputError(f"waypoints: got shape {w.shape}, expected (M + 1, d) with M >= 1")
    if t.shape != (w.shape[0],):
        raise InputError(f"times: got shape {t.shape}, expected ({w.shape[0]},), one per waypoint")
    if not (np.all(np.isfinite(w)) and np.all(np.isfinite(t))):
        raise InputError("waypoints, times: got a non-finite value, expected finite numbers")
    steps = np.diff(t)
    if np.any(steps <= MIN_RELATIVE_PIECE * (t[-1] - t[0]) / steps.size):
        raise InputError(
            f"times: got a step of {steps.min():.3g} s, expected strictly increasing times with "
            f"every step at least {MIN_RELATIVE_PIECE:g} of the mean step"
        )
    return w, t, int(order)


def _boundary(name: str, given: FloatArray | None, s: int, d: int) -> FloatArray:
    if given is None:
        return np.zeros((s - 1, d))
    b = np.asarray(given, dtype=np.float64)
    if b.shape != (s - 1, d) or not np.all(np.isfinite(b)):
        raise InputError(
            f"{name}: got shape {b.shape}, expected ({s - 1}, {d}) finite derivatives 1..{s - 1}"
        )
    return b


@cache
def _hermite(s: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A piece's Hermite map and its cost, on the normalised time ``u`` in [0, 1].

    A polynomial ``q`` of degree ``2s - 1`` is fixed by its end data
    ``x = [q(0), q'(0), .., q^(s-1)(0), q(1), .., q^(s-1)(1)]``. Returns ``H`` (2s, 2s), its
    coefficients (lowest power first) from ``x``, and ``Q`` (2s, 2s), the cost
    ``∫_0^1 (q^(s))^2 du = x' Q x``.
    """
    n = 2 * s
    powers = np.arange(n)

    def row(k: int, u: float) -> NDArray[np.float64]:
        falling = np.array([math.perm(j, k) for j in powers], dtype=np.float64)
        return np.where(powers >= k, falling * u ** np.maximum(powers - k, 0), 0.0)

    H = np.linalg.inv(np.array([row(k, 0.0) for k in range(s)] + [row(k, 1.0) for k in range(s)]))
    high = powers[s:]
    gram = np.zeros((n, n))
    gram[s:, s:] = np.outer([math.perm(j, s) for j in high], [math.perm(j, s) for j in high]) / (
        high[:, None] + high[None, :] - 2 * s + 1
    )
    return H, H.T @ gram @ H


def _interior(derivs: FloatArray, T: FloatArray, s: int) -> FloatArray:
    """The derivatives 1 .. s-1 at the interior waypoints that minimise the cost, (s-1, d, M-1).

    Piece ``j`` costs ``T_j^(1-2s) x_j' Q x_j`` with ``x_j`` its end data scaled by
    ``T_j^r``; the cost is a quadratic in the interior derivatives whose Hessian is
    block-tridiagonal (a derivative touches the two pieces beside it) and positive
    definite, so its normal equations are solved by a banded Cholesky factorisation
    (LAPACK ``pbsv``), every axis at once. (Setting that gradient to zero is the same as
    asking the derivatives s .. 2s-2 to be continuous, the Euler-Lagrange form.)

    Every entry of the Hessian is ``Q[a, c] T^(a+c+3-2s)`` of the piece it comes from,
    and every entry of the right-hand side ``Q[r, 0 or s] T^(r+2-2s)`` times a waypoint:
    so the powers ``T^-k`` are computed once and each band row is a pass over them.
    """
    _, Q = _hermite(s)
    q = s - 1
    A, B = slice(1, s), slice(s + 1, 2 * s)  # the derivatives at a piece's start and end
    inv = 1.0 / T
    power = {1: inv}  # power[k] = T^-k, k = 1 .. 2s - 2
    for k in range(2, 2 * s - 1):
        power[k] = power[k - 1] * inv
    band = np.zeros((2 * q, (T.size - 1) * q), order="F")
    for a in range(q):
        for c in range(a + 1):  # diagonal blocks: the piece left and the piece right
            left_right = power[2 * s - 3 - a - c]
            band[a - c, c::q] = Q[B, B][a, c] * left_right[:-1] + Q[A, A][a, c] * left_right[1:]
        for c in range(q):  # block (i + 1, i) couples the two ends of piece i + 1
            band[q + a - c, c::q][:-1] = Q[A, B][c, a] * power[2 * s - 3 - a - c][1:-1]
    p = derivs[0]  # (d, M + 1)
    rhs = np.empty((p.shape[0], T.size - 1, q))  # (d, interior, q): Fortran order for pbsv
    for r in range(q):
        left, right = power[2 * s - 2 - r][:-1], power[2 * s - 2 - r][1:]
        rhs[:, :, r] = -(
            left * (Q[B, 0][r] * p[:, :-2] + Q[B, s][r] * p[:, 1:-1])
            + right * (Q[A, 0][r] * p[:, 1:-1] + Q[A, s][r] * p[:, 2:])
        )
    # Given end derivatives (rest by default) couple with the first and last interior waypoint.
    scale0, scale1 = T[0] ** np.arange(1, s), T[-1] ** np.arange(1, s)
    w0, w1 = T[0] ** (1.0 - 2 * s), T[-1] ** (1.0 - 2 * s)
    rhs[:, 0] -= ((w0 * scale0[:, None] * Q[B, A] * scale0[None, :]) @ derivs[1:, :, 0]).T
    rhs[:, -1] -= ((w1 * scale1[:, None] * Q[A, B] * scale1[None, :]) @ derivs[1:, :, -1]).T
    flat = rhs.reshape(rhs.shape[0], -1).T  # (interior * q, d), Fortran order: no copy
    _, z, info = dpbsv(band, flat, lower=1, overwrite_ab=1, overwrite_b=1)
    if info != 0:  # pragma: no cover - the Hessian is positive definite by construction
        raise SolverError(f"min_snap: the banded Cholesky factorisation failed (info {info})")
    return np.asarray(z).T.reshape(rhs.shape).transpose(2, 0, 1)


def _power_coefficients(derivs: FloatArray, T: FloatArray, s: int, unit: float) -> FloatArray:
    """Every piece's coefficients in its own time in seconds, (M, 2s, d).

    ``derivs`` (s, d, M + 1) and ``T`` (M,) are in the time unit ``unit`` (s).
    """
    H, _ = _hermite(s)
    m, d = T.size, derivs.shape[1]
    powers = np.empty((2 * s, m))  # T^k
    powers[0] = 1.0
    for k in range(1, 2 * s):
        powers[k] = powers[k - 1] * T
    x = np.empty((2 * s, d, m))  # the end data, scaled by T^r, as columns of one product
    x[:s] = derivs[:, :, :-1] * powers[:s, None, :]
    x[s:] = derivs[:, :, 1:] * powers[:s, None, :]
    coeffs = (H @ x.reshape(2 * s, d * m)).reshape(2 * s, d, m)
    coeffs /= (powers * (unit ** np.arange(2 * s))[:, None])[:, None, :]
    return np.ascontiguousarray(coeffs.transpose(2, 0, 1))
