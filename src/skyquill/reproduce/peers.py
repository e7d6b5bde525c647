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
the layout of :class:`~skyquill.trajectory.PiecewisePolynomial`, so the conversion
is a copy.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.trajectory import PiecewisePolynomial

__all__ = ["PeerFit", "minsnap_interpolate"]

_PEER_INSTALL_HINT = (
    "The minimum-snap peer needs the package 'minsnap-trajectories'; "
    "install it with `pip install minsnap-trajectories`."
)


@dataclass(frozen=True)
class PeerFit:
    """A peer's trajectory and what it took.

    Attributes
    ----------
    trajectory
        The peer's polynomials on their own clock from 0 (``times - times[0]``).
    start_time
        ``times[0]``: add it to the trajectory's time for the caller's clock, s.
    solve_time_s
        Wall time of the peer's own solve (excludes input checks and conversion).
    """

    trajectory: PiecewisePolynomial
    start_time: float
    solve_time_s: float


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
) -> PeerFit:
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
        Strictly increasing arrival times, seconds (``times[0]`` may be non-zero
        or negative; the peer is called with times shifted to start at 0, which
        does not change the local-time coefficients).
    degree : int, optional
        Polynomial degree of every piece, at least 7 (default 7).

    Returns
    -------
    PeerFit
        The trajectory (``breaks`` = ``times - times[0]``, ``coeffs`` shape
        (W - 1, degree + 1, d)), ``times[0]``, and the wall time of
        ``generate_trajectory``.

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
    return PeerFit(PiecewisePolynomial(rel, coeffs), float(ts[0]), solve_time_s)
