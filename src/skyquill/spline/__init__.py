"""Clamped uniform B-splines: knots, basis, exact Gram matrices, derivative maps, hulls."""

from skyquill.spline.basis import (
    ClampedUniformBasis,
    HullKind,
    basis_for,
    clamped_uniform_knots,
)

__all__ = ["ClampedUniformBasis", "HullKind", "basis_for", "clamped_uniform_knots"]
