"""A trajectory moved by a rigid motion of the horizontal plane (rotation or mirror, then shift).

Every kind that stores its positions as coefficients of a basis (B-spline
control points, power-basis polynomials) moves exactly: the basis is linear,
so ``x -> R x + s`` applied to the coefficients moves every point, and ``R``
alone every derivative. The timing is untouched: the moved trajectory has the
same duration and breakpoints, and under norm limits the same speed,
acceleration and jerk norms at every instant (``R`` is orthogonal).
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import BSpline

from skyquill.errors import InputError
from skyquill.trajectory.base import Trajectory
from skyquill.trajectory.polynomial import PiecewisePolynomial
from skyquill.trajectory.retimed import RetimedPath
from skyquill.trajectory.sequence import RestToRestSequence
from skyquill.trajectory.spline import SplineTrajectory
from skyquill.validation import FloatArray, as_array

#: Largest deviation of ``R.T R`` from the identity accepted as orthogonal.
_ORTHOGONAL_TOL = 1e-9


def moved(traj: Trajectory, rotation: FloatArray, shift: FloatArray) -> Trajectory:
    """``traj`` with its x and y moved to ``rotation @ (x, y) + shift``; z unchanged.

    Parameters
    ----------
    traj
        A :class:`RetimedPath`, :class:`PiecewisePolynomial` (without yaw),
        :class:`SplineTrajectory` or :class:`RestToRestSequence` of them, with
        at least 2 axes (m).
    rotation
        Orthogonal matrix, shape (2, 2): a rotation, or a mirror (determinant -1).
    shift
        Translation, shape (2,), m.

    Returns
    -------
    Trajectory
        Of the same kind, duration and breakpoints.

    Raises
    ------
    InputError
        ``rotation`` not orthogonal, fewer than 2 axes, a heading (it would
        need turning too), or another kind of trajectory.
    """
    r = as_array("rotation", rotation, shape=(2, 2))
    s = as_array("shift", shift, shape=(2,))
    if not np.allclose(r.T @ r, np.eye(2), rtol=0.0, atol=_ORTHOGONAL_TOL):
        raise InputError(f"rotation: got {r.tolist()}, expected an orthogonal 2 x 2 matrix")
    if traj.dim < 2:
        raise InputError(f"traj: got {traj.dim} axis, expected at least x and y")
    return _moved(traj, r, s)


def _moved(traj: Trajectory, r: FloatArray, s: FloatArray) -> Trajectory:
    if isinstance(traj, RestToRestSequence):
        return RestToRestSequence(tuple(_moved(p, r, s) for p in traj.pieces), traj.tolerance)
    if isinstance(traj, RetimedPath):
        curve = BSpline(traj.curve.t, _points(traj.curve.c, r, s), traj.curve.k)
        return RetimedPath(curve, traj.timing)
    if isinstance(traj, SplineTrajectory):
        return SplineTrajectory(_points(traj.control_points, r, s), traj.degree, traj.duration)
    if isinstance(traj, PiecewisePolynomial) and traj.yaw_coeffs is None:
        coeffs = np.array(traj.coeffs, dtype=np.float64)
        coeffs[:, :, :2] = coeffs[:, :, :2] @ r.T  # every power of tau turns
        coeffs[:, 0, :2] += s  # only the positions shift
        return PiecewisePolynomial(traj.breaks, coeffs)
    raise InputError(
        f"traj: got a {type(traj).__name__}, expected a RetimedPath, PiecewisePolynomial "
        "without heading, SplineTrajectory or a RestToRestSequence of them"
    )


def _points(points: FloatArray, r: FloatArray, s: FloatArray) -> FloatArray:
    """Control points ``(n, d)`` with their first two columns moved."""
    out = np.array(points, dtype=np.float64)
    out[:, :2] = out[:, :2] @ r.T + s
    return out
