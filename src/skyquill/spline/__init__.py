"""Clamped uniform B-splines: knots, basis, exact Gram matrices, derivative maps, hulls."""

from skyquill.spline.basis import (
    ClampedUniformBasis,
    HullKind,
    basis_for,
    clamped_uniform_knots,
    uniform_design,
)

__all__ = [
    "ClampedUniformBasis",
    "HullKind",
    "basis_for",
    "clamped_uniform_knots",
    "uniform_design",
]
