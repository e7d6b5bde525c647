"""A trajectory that is not a B-spline, refitted as one inside the same limits.

The exact formats (Crazyswarm polynomials, Skybrush Bézier segments) carry
polynomials. A retimed coverage path or a sequence of legs is not one: it is
fitted with the engine (point deviation at dense samples of the trajectory on
its own clock, rest at both ends, the plan's limits through the convex hull),
so the exported trajectory keeps the guarantee, and its distance from the
original is measured and reported.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from skyquill.errors import InputError
from skyquill.limits import DerivativeLimit
from skyquill.optimize import Boundary, PointDeviation, SmoothingProblem, solve
from skyquill.trajectory import SplineTrajectory, Trajectory, dense_times

#: Seconds per knot span of the refit (coverage turns last ~1 s).
KNOT_INTERVAL_S = 0.1
#: Degree of the refit: 7, the highest the Crazyflie firmware evaluates.
DEGREE = 7
#: Samples per knot span the deviation is measured on.
SAMPLES_PER_SPAN = 4
#: Largest number of knot spans a refit may have (QP size).
MAX_SPANS = 20_000
#: Weight of the point deviation against the jerk cost.
WEIGHT = 1e6


@dataclass(frozen=True)
class Refit:
    """A B-spline standing in for a trajectory.

    Attributes
    ----------
    spline
        The B-spline (the trajectory itself when it already is one).
    max_deviation_m
        Largest distance from the original over dense samples, m (0 when exact).
    exact
        Whether no refit was needed.
    """

    spline: SplineTrajectory
    max_deviation_m: float
    exact: bool


def as_spline(traj: Trajectory, limits: Sequence[DerivativeLimit]) -> Refit:
    """``traj`` as a :class:`SplineTrajectory`: itself, or refitted inside ``limits``.

    Raises
    ------
    InputError
        When the refit would need more than :data:`MAX_SPANS` knot spans.
    InfeasibleError
        When no spline on this knot grid keeps the limits (from the engine).
    """
    if isinstance(traj, SplineTrajectory):
        return Refit(traj, 0.0, True)
    spans = max(1, math.ceil(traj.duration / KNOT_INTERVAL_S))
    if spans > MAX_SPANS:
        raise InputError(
            f"trajectory: got {traj.duration:.6g} s ({spans} knot spans at {KNOT_INTERVAL_S} s), "
            f"expected at most {MAX_SPANS} spans for an exact format; use a sampled format"
        )
    t = np.linspace(0.0, traj.duration, spans * SAMPLES_PER_SPAN + 1)
    points = traj.evaluate(t)
    problem = SmoothingProblem(
        dim=traj.dim,
        degree=DEGREE,
        n_ctrl=spans + DEGREE,
        duration=traj.duration,
        deviations=(PointDeviation(t, points, WEIGHT),),
        boundary=Boundary.rest(points[0], points[-1], 3),
        limits=tuple(limits),
    )
    spline = solve(problem).trajectory
    check = dense_times(traj.breakpoints)
    deviation = np.linalg.norm(spline.evaluate(check) - traj.evaluate(check), axis=1)
    return Refit(spline, float(deviation.max()), False)
