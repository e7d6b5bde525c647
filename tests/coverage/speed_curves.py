"""Paths the speed planner's tests share: the 10 m square's spiral and hand-made wiggles."""

from __future__ import annotations

import numpy as np
from scipy.interpolate import BSpline, make_interp_spline

from skyquill.coverage.paths import contours, spiral_control_points, spiral_curve
from skyquill.coverage.regions import region_from_vertices


def square_spiral(delta: float = 1.0) -> BSpline:
    """The spiral covering a 10 m square at a 2 m swath (``delta``: its drift, m)."""
    square = region_from_vertices([[0, 0], [10, 0], [10, 10], [0, 10]])
    curve: BSpline = spiral_curve(spiral_control_points(contours(square, 2.0, "offset"), delta))
    return curve


def wiggle(points: list[tuple[float, float]]) -> BSpline:
    """A degree-4 interpolating spline through the running sums of ``points`` (steps, m)."""
    xy = np.cumsum(np.asarray(points, dtype=float), axis=0)
    return make_interp_spline(np.linspace(0.0, 1.0, len(xy)), xy, k=4)
