"""Peer trajectory generators that skyquill compares itself with.

The peer wrapped here is the PyPI package ``minsnap-trajectories`` (import name
``minsnap_trajectories``): minimum-snap piecewise-polynomial interpolation of
waypoints at given times (Mellinger & Kumar 2011; Richter, Bry & Roy 2013,
closed-form unconstrained reformulation).

The package is imported lazily inside :func:`minsnap_interpolate`, so this module
imports without it; calling the function without it raises :class:`ImportError`.

Peer conventions (checked against its source, version 0.3)
----------------------------------------------------------
``generate_trajectory`` returns a ``PiecewisePolynomialTrajectory`` named tuple
``(time_reference, durations, coefficients)``. ``coefficients[i, j, k]`` is the
coefficient of ``tau**j`` (lowest power first) of piece ``i`` along axis ``k``,
where ``tau = t - time_reference[i]`` is *local, un-normalised* time in seconds:
the solver works in normalised time ``tau / durations[i]`` internally but rescales
the coefficients by ``durations[i] ** -j`` before returning them. This is exactly
the layout of :class:`PolynomialTrajectory`, so the conversion is a copy.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import numpy.polynomial.polynomial as npoly
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.polynomial import horner

__all__ = ["PolynomialTrajectory", "minsnap_interpolate"]

_PEER_INSTALL_HINT = (
    "The minimum-snap peer needs the package 'minsnap-trajectories'; "
    "install it with `pip install minsnap-trajectories`."
)


@dataclass(frozen=True)
class PolynomialTrajectory:
    """Piecewise polynomial trajectory in the power basis.

    Piece ``i`` covers ``[breaks[i], breaks[i + 1]]`` and is
    ``p_i(t) = sum_j coeffs[i, j, :] * tau**j`` with local time
    ``tau = t - breaks[i]`` in seconds (lowest power first).

    Parameters
    ----------
    breaks : ndarray, shape (P + 1,)
        Strictly increasing break times, seconds. Absolute times: ``breaks[0]``
        need not be zero.
    coeffs : ndarray, shape (P, degree + 1, d)
        Power-basis coefficients; ``coeffs[i, j, k]`` has unit m / s**j.
    solve_time_s : float
        Wall-clock time of the peer's own solve, seconds (excludes the wrapper's
        input checks and conversion).

    Notes
    -----
    Both arrays are stored as read-only float64 copies.
    """

    breaks: NDArray[np.float64]
    coeffs: NDArray[np.float64]
    solve_time_s: float

    def __post_init__(self) -> None:
        breaks = np.array(self.breaks, dtype=np.float64)
        coeffs = np.array(self.coeffs, dtype=np.float64)
        if breaks.ndim != 1 or breaks.size < 2:
            raise InputError(f"breaks: expected shape (P+1,) with P >= 1, got {breaks.shape}")
        if not np.all(np.isfinite(breaks)) or np.any(np.diff(breaks) <= 0.0):
            raise InputError("breaks: expected finite, strictly increasing times")
        if coeffs.ndim != 3 or coeffs.shape[0] != breaks.size - 1 or coeffs.shape[1] < 1:
            raise InputError(
                f"coeffs: expected shape (P, degree+1, d) = ({breaks.size - 1}, n, d), "
                f"got {coeffs.shape}"
            )
        if not np.all(np.isfinite(coeffs)):
            raise InputError("coeffs: expected finite values")
        breaks.setflags(write=False)
        coeffs.setflags(write=False)
        object.__setattr__(self, "breaks", breaks)
        object.__setattr__(self, "coeffs", coeffs)
        object.__setattr__(self, "solve_time_s", float(self.solve_time_s))

    @property
    def duration(self) -> float:
        """Total duration ``breaks[-1] - breaks[0]``, seconds."""
        return float(self.breaks[-1] - self.breaks[0])

    @property
    def degree(self) -> int:
        """Polynomial degree of every piece (``coeffs.shape[1] - 1``)."""
        return int(self.coeffs.shape[1] - 1)

    @property
    def dim(self) -> int:
        """Spatial dimension ``d``."""
        return int(self.coeffs.shape[2])

    def _derivative_coeffs(self, order: int) -> NDArray[np.float64]:
        """Coefficients of the ``order``-th derivative, shape (P, max(degree+1-order, 1), d)."""
        if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or order < 0:
            raise InputError(f"order: expected a non-negative integer, got {order!r}")
        if order == 0:
            return self.coeffs
        if order > self.degree:
            return np.zeros((self.coeffs.shape[0], 1, self.coeffs.shape[2]))
        return np.asarray(npoly.polyder(self.coeffs, m=int(order), axis=1), dtype=np.float64)

    def evaluate(self, t: NDArray[np.float64], order: int = 0) -> NDArray[np.float64]:
        """Evaluate the trajectory or one of its time derivatives.

        Parameters
        ----------
        t : ndarray, shape (N,)
            Query times, seconds, within ``[breaks[0], breaks[-1]]`` (i.e.
            ``[0, duration]`` when the trajectory starts at zero). A scalar is
            treated as shape (1,). At an interior break the later piece is used
            (both agree up to the enforced continuity).
        order : int, optional
            Derivative order (0 position in m, 1 velocity in m/s, 2 acceleration
            in m/s^2, 3 jerk, 4 snap, ...). Any non-negative order is accepted;
            orders above ``degree`` give zeros.

        Returns
        -------
        ndarray, shape (N, d)
            Values in m / s**order.

        Raises
        ------
        ValueError
            (:class:`skyquill.errors.InputError`) if ``t`` is not 1-D, not finite,
            or lies outside ``[breaks[0], breaks[-1]]``, or ``order`` is invalid.
        """
        ts = np.atleast_1d(np.asarray(t, dtype=np.float64))
        if ts.ndim != 1:
            raise InputError(f"t: expected shape (N,), got {ts.shape}")
        if not np.all(np.isfinite(ts)):
            raise InputError("t: expected finite times")
        lo, hi = float(self.breaks[0]), float(self.breaks[-1])
        if ts.size and (ts.min() < lo or ts.max() > hi):
            raise InputError(
                f"t: expected times within [{lo}, {hi}] s, got range "
                f"[{float(ts.min())}, {float(ts.max())}]"
            )
        self._derivative_coeffs(order)  # validates the order
        n_pieces = self.coeffs.shape[0]
        idx = np.clip(np.searchsorted(self.breaks, ts, side="right") - 1, 0, n_pieces - 1)
        return horner(self.coeffs[idx], ts - self.breaks[idx], int(order))

    def squared_derivative_integral(self, order: int) -> float:
        """Exact integral of the squared norm of a derivative over the trajectory.

        Computes ``∫ ||d^order p / dt^order||^2 dt`` over ``[breaks[0], breaks[-1]]``
        by polynomial algebra on the coefficients (derivative, square, antiderivative;
        :mod:`numpy.polynomial`), not by sampling.

        Parameters
        ----------
        order : int
            Derivative order (4 for snap).

        Returns
        -------
        float
            The integral, in m^2 / s^(2 * order - 1).
        """
        c = self._derivative_coeffs(order)
        durations = np.diff(self.breaks)
        total = 0.0
        for i in range(c.shape[0]):
            for k in range(c.shape[2]):
                sq = npoly.polymul(c[i, :, k], c[i, :, k])
                anti = npoly.polyint(sq)
                total += float(npoly.polyval(durations[i], anti))
        return total


def _check_inputs(
    waypoints: NDArray[np.float64], times: NDArray[np.float64], degree: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    wp = np.asarray(waypoints, dtype=np.float64)
    ts = np.asarray(times, dtype=np.float64)
    if wp.ndim != 2 or wp.shape[0] < 2 or wp.shape[1] not in (1, 2, 3):
        raise InputError(
            f"waypoints: expected shape (W, d) with W >= 2, d in {{1,2,3}}, got {wp.shape}"
        )
    if ts.shape != (wp.shape[0],):
        raise InputError(f"times: expected shape ({wp.shape[0]},), got {ts.shape}")
    if not np.all(np.isfinite(wp)):
        raise InputError("waypoints: expected finite values")
    if not np.all(np.isfinite(ts)) or np.any(np.diff(ts) <= 0.0):
        raise InputError("times: expected finite, strictly increasing times")
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)) or degree < 7:
        raise InputError(
            f"degree: expected an integer >= 7 (minimum snap with pos/vel/acc/jerk "
            f"continuity needs 8 coefficients per piece), got {degree!r}"
        )
    return wp, ts


def minsnap_interpolate(
    waypoints: NDArray[np.float64], times: NDArray[np.float64], degree: int = 7
) -> PolynomialTrajectory:
    """Minimum-snap interpolation of waypoints at given times, by the peer package.

    Minimises ``∫ ||p''''(t)||^2 dt`` over piecewise polynomials of ``degree``
    that pass through every waypoint at its time, with position, velocity,
    acceleration and jerk continuous at interior waypoints and velocity,
    acceleration and jerk zero at the first and last waypoint (rest to rest).
    Solved by ``minsnap_trajectories.generate_trajectory`` (closed-form
    algorithm, ``idx_minimized_orders=4``, ``num_continuous_orders=4``).

    Parameters
    ----------
    waypoints : ndarray, shape (W, d)
        Positions, metres; ``W >= 2``, ``d`` in {1, 2, 3}.
    times : ndarray, shape (W,)
        Strictly increasing arrival times, seconds. Kept absolute: the result's
        ``breaks`` equal ``times`` (``times[0]`` may be non-zero or negative; the
        peer is called with times shifted to start at 0, which does not change
        the local-time coefficients).
    degree : int, optional
        Polynomial degree of every piece, at least 7 (default 7).

    Returns
    -------
    PolynomialTrajectory
        ``breaks`` shape (W,), ``coeffs`` shape (W - 1, degree + 1, d);
        ``solve_time_s`` is the wall time of ``generate_trajectory``.

    Raises
    ------
    ImportError
        If ``minsnap-trajectories`` is not installed.
    ValueError
        (:class:`skyquill.errors.InputError`) on malformed input.
    """
    wp, ts = _check_inputs(waypoints, times, degree)
    try:
        from minsnap_trajectories import Waypoint, generate_trajectory
    except ImportError as exc:
        raise ImportError(_PEER_INSTALL_HINT) from exc

    rel = ts - ts[0]
    zero = np.zeros(wp.shape[1])
    last = wp.shape[0] - 1
    refs = [
        Waypoint(time=float(rel[i]), position=wp[i], velocity=zero, acceleration=zero, jerk=zero)
        if i in (0, last)
        else Waypoint(time=float(rel[i]), position=wp[i])
        for i in range(wp.shape[0])
    ]
    start = time.perf_counter()
    peer = generate_trajectory(
        refs,
        int(degree),
        idx_minimized_orders=4,
        num_continuous_orders=4,
        algorithm="closed-form",
    )
    solve_time_s = time.perf_counter() - start
    coeffs = np.asarray(peer.coefficients, dtype=np.float64)
    expected = (wp.shape[0] - 1, int(degree) + 1, wp.shape[1])
    if coeffs.shape != expected:  # pragma: no cover - guards against a peer API change
        raise RuntimeError(
            f"minsnap_trajectories returned coefficients of shape "
            f"{coeffs.shape}, expected {expected}"
        )
    return PolynomialTrajectory(breaks=ts.copy(), coeffs=coeffs, solve_time_s=solve_time_s)
