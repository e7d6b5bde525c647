"""The smoothing-spline problem: costs, constraints, closed form, QP, time allocation."""

from skyquill.optimize.problem import (
    Boundary,
    Corridor,
    Interpolation,
    LineDeviation,
    PlaneDeviation,
    PointDeviation,
    SmoothingProblem,
)
from skyquill.optimize.resegment import (
    ResegmentResult,
    point_fit_factory,
    resegment,
    time_gradient,
)
from skyquill.optimize.solve import FitResult, solve

__all__ = [
    "Boundary",
    "Corridor",
    "FitResult",
    "Interpolation",
    "LineDeviation",
    "PlaneDeviation",
    "PointDeviation",
    "ResegmentResult",
    "SmoothingProblem",
    "point_fit_factory",
    "resegment",
    "solve",
    "time_gradient",
]
