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
from skyquill.optimize.solve import FitResult, solve

__all__ = [
    "Boundary",
    "Corridor",
    "FitResult",
    "Interpolation",
    "LineDeviation",
    "PlaneDeviation",
    "PointDeviation",
    "SmoothingProblem",
    "solve",
]
