"""Time allocation for nominal plans (paper 003 §3.5).

* :func:`rest_to_rest_time` -- minimum time of a double integrator moving a
  distance from rest to rest with ``|v| <= vmax``, ``|a| <= amax``
  (trapezoidal or triangular speed profile, closed form; the algorithm the
  paper cites as [14]).
* :func:`allocate_segment_times` -- that time for every segment of a
  waypoint chain: the paper's allocation for sparse waypoints.
* :func:`allocate_path_times` -- for densely sampled paths (handwriting,
  sketches) stopping at every sample would be absurd, so the same double
  integrator runs along the whole arc length, slowing at corners so that the
  centripetal acceleration ``v^2 kappa`` stays within ``amax``, with forward
  and backward passes for the tangential acceleration. It starts and ends at
  rest; on a straight two-point path it reduces to :func:`rest_to_rest_time`.
* :func:`segment_chain_terms` -- the §3.5 deviation terms for a chain of line
  segments: the waypoints, the intermediate points ``S_i^+``, ``S_{i+1}^-``
  at ``kappa`` and ``1 - kappa`` of each segment's time, and the segment's
  line on the window between them.
"""

from __future__ import annotations

import numpy as np

from skyquill.errors import InputError
from skyquill.optimize.problem import Deviation, LineDeviation, PointDeviation
from skyquill.validation import FloatArray, as_array, as_float


def rest_to_rest_time(distance: float, vmax: float, amax: float) -> float:
    """Minimum rest-to-rest time over ``distance`` m with speed and acceleration limits (s)."""
    dist = as_float("distance", distance, nonneg=True)
    v = as_float("vmax", vmax, positive=True)
    a = as_float("amax", amax, positive=True)
    if dist >= v * v / a:  # reaches vmax: accelerate, cruise, decelerate
        return dist / v + v / a
    return 2.0 * float(np.sqrt(dist / a))


def rest_to_rest_distance(t: FloatArray, distance: float, vmax: float, amax: float) -> FloatArray:
    """Distance covered at times ``t`` (s) by the profile of :func:`rest_to_rest_time`."""
    total = rest_to_rest_time(distance, vmax, amax)
    v_peak = min(vmax, float(np.sqrt(distance * amax)))
    t_acc = v_peak / amax
    t = np.clip(np.asarray(t, dtype=float), 0.0, total)
    s_acc = 0.5 * amax * np.minimum(t, t_acc) ** 2
    s_cruise = v_peak * np.clip(t - t_acc, 0.0, max(total - 2 * t_acc, 0.0))
    t_dec = np.clip(t - (total - t_acc), 0.0, t_acc)
    s_dec = v_peak * t_dec - 0.5 * amax * t_dec**2
    return np.asarray(s_acc + s_cruise + s_dec)


#: Coordinates beyond this (m) are refused: a drawing is not 1000 km wide.
MAX_COORDINATE_M = 1e6


def _waypoints(name: str, points: object) -> FloatArray:
    pts = as_array(name, points, ndim=2, max_abs=MAX_COORDINATE_M)
    if pts.shape[0] < 2:
        raise InputError(f"{name}: got {pts.shape[0]} point(s), expected at least 2")
    return pts


def allocate_segment_times(waypoints: FloatArray, vmax: float, amax: float) -> FloatArray:
    """Times at the waypoints, rest to rest on every segment (paper 003 §3.5).

    Parameters
    ----------
    waypoints
        Shape (W, d), m; consecutive waypoints must differ.
    vmax, amax
        m/s, m/s^2.

    Returns
    -------
    numpy.ndarray, shape (W,), s, starting at 0.
    """
    pts = _waypoints("waypoints", waypoints)
    lengths = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    if np.any(lengths == 0.0):
        i = int(np.argmin(lengths))
        raise InputError(
            f"waypoints: got waypoints {i} and {i + 1} equal, expected distinct consecutive points"
        )
    steps = [rest_to_rest_time(float(length), vmax, amax) for length in lengths]
    return np.concatenate([[0.0], np.cumsum(steps)])


def allocate_path_times(
    points: FloatArray, vmax: float, amax: float, resolution: float = 0.02
) -> FloatArray:
    """Times along a densely sampled path, at rest at both ends.

    Parameters
    ----------
    points
        Shape (N, d), m, N >= 2, not all equal. Repeated consecutive samples
        get the same time.
    vmax, amax
        m/s, m/s^2.
    resolution
        Arc length (m) over which curvature is measured: the three points of
        each curvature estimate are at least this far apart along the path,
        so millimetre jitter of hand-drawn samples does not read as tight
        corners.

    Returns
    -------
    numpy.ndarray, shape (N,), non-decreasing, s, starting at 0.
    """
    pts = _waypoints("points", points)
    resolution = as_float("resolution", resolution, positive=True)
    vmax = as_float("vmax", vmax, positive=True)
    amax = as_float("amax", amax, positive=True)
    ds = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    if ds.sum() == 0.0:
        raise InputError("points: got all points equal, expected a path of non-zero length")
    v_cap = np.full(pts.shape[0], vmax)
    v_cap[1:-1] = np.minimum(
        vmax, np.sqrt(amax / np.maximum(_curvature(pts, ds, resolution), 1e-12))
    )
    v_cap[0] = v_cap[-1] = 0.0
    v = np.sqrt(_reachable(_reachable(v_cap**2, 2.0 * amax * ds)[::-1], 2.0 * amax * ds[::-1]))
    v = v[::-1]
    return np.concatenate([[0.0], np.cumsum(_interval_times(ds, v[:-1], v[1:], vmax, amax))])


def _reachable(cap: FloatArray, gain: FloatArray) -> FloatArray:
    """The forward pass ``w_i = min(cap_i, w_{i-1} + gain_{i-1})``, ``w_0 = cap_0``, at once.

    With ``S_i = sum_{k<i} gain_k``, ``w_i - S_i = min(cap_i - S_i, w_{i-1} - S_{i-1})``: a
    running minimum. In squared speeds (``w = v^2``, ``gain = 2 a ds``) this is the
    profile's pass ``v_i^2 <= v_{i-1}^2 + 2 a ds``, without a Python loop over the samples.
    """
    S = np.concatenate([[0.0], np.cumsum(gain)])
    return np.asarray(np.maximum(np.minimum.accumulate(cap - S) + S, 0.0))


def _interval_times(
    ds: FloatArray, v0: FloatArray, v1: FloatArray, vmax: float, amax: float
) -> FloatArray:
    """Minimum time over each interval from speed ``v0`` to ``v1`` (reachable by construction).

    Accelerate to the peak speed ``vp``, cruise, decelerate; with ``v0 = v1 = 0``
    this is :func:`rest_to_rest_time`.
    """
    vp = np.minimum(vmax, np.sqrt(np.maximum(amax * ds + 0.5 * (v0**2 + v1**2), 0.0)))
    ramp = (2 * vp**2 - v0**2 - v1**2) / (2 * amax)  # distance spent accelerating/decelerating
    cruise = np.maximum(ds - ramp, 0.0) / np.maximum(vp, 1e-300)
    return np.where(ds > 0, (2 * vp - v0 - v1) / amax + cruise, 0.0)


def _curvature(pts: FloatArray, ds: FloatArray, resolution: float) -> FloatArray:
    """Menger curvature at interior samples over a stencil of ``resolution`` m; (N-2,), 1/m."""
    arc = np.concatenate([[0.0], np.cumsum(ds)])
    inner = np.arange(1, pts.shape[0] - 1)
    back = np.searchsorted(arc, arc[inner] - resolution, side="right") - 1
    ahead = np.searchsorted(arc, arc[inner] + resolution, side="left")
    back = np.clip(np.minimum(back, inner - 1), 0, None)
    ahead = np.clip(np.maximum(ahead, inner + 1), None, pts.shape[0] - 1)
    a = pts[inner] - pts[back]
    b = pts[ahead] - pts[inner]
    c = pts[ahead] - pts[back]
    la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, c))
    if pts.shape[1] == 2:
        cross = np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    else:
        cross = np.linalg.norm(np.cross(a, b), axis=1)
    denom = la * lb * lc
    return np.where(denom > 0, 2.0 * cross / np.maximum(denom, 1e-300), 0.0)


def segment_chain_terms(
    waypoints: FloatArray,
    times: FloatArray,
    vmax: float,
    amax: float,
    *,
    kappa: float = 0.25,
    point_weight: float = 1.0,
    line_weight: float = 1.0,
) -> tuple[Deviation, ...]:
    """Deviation terms for a chain of line segments (paper 003 §3.5, Fig. 2).

    Parameters
    ----------
    waypoints
        Shape (W, d), m.
    times
        Shape (W,), s, from :func:`allocate_segment_times`.
    vmax, amax
        The limits used for the allocation (they place ``S_i^+``, ``S_{i+1}^-``
        on each segment's time-optimal profile).
    kappa
        Fraction of each segment's time in ``(0, 0.5)``.
    point_weight, line_weight
        Weights of the point terms and of the line terms.

    Returns
    -------
    tuple
        One :class:`PointDeviation` (waypoints and intermediate points) and one
        :class:`LineDeviation` per segment on ``[t_i + kappa dt_i, t_i + (1 - kappa) dt_i)``.
    """
    pts = _waypoints("waypoints", waypoints)
    t = as_array("times", times, shape=(pts.shape[0],))
    k = as_float("kappa", kappa)
    if not 0.0 < k < 0.5:
        raise InputError(f"kappa: got {k:g}, expected a fraction in (0, 0.5)")
    point_t, point_p = [t[0]], [pts[0]]
    lines: list[Deviation] = []
    for i in range(pts.shape[0] - 1):
        dt = t[i + 1] - t[i]
        seg = pts[i + 1] - pts[i]
        length = float(np.linalg.norm(seg))
        t_plus, t_minus = t[i] + k * dt, t[i] + (1 - k) * dt
        s_plus, s_minus = rest_to_rest_distance(
            np.array([k * dt, (1 - k) * dt]), length, vmax, amax
        )
        point_t += [t_plus, t_minus, t[i + 1]]
        point_p += [pts[i] + seg * s_plus / length, pts[i] + seg * s_minus / length, pts[i + 1]]
        lines.append(LineDeviation(pts[i], pts[i + 1], t_plus, t_minus, line_weight))
    return (PointDeviation(np.array(point_t), np.array(point_p), point_weight), *lines)
