"""Piecewise power-basis polynomials: the one evaluator every polynomial trajectory uses."""

from __future__ import annotations

import math

import numpy as np

from skyquill.validation import FloatArray


def horner(coeffs: FloatArray, tau: FloatArray, order: int = 0) -> FloatArray:
    """Derivative ``order`` of ``sum_j coeffs[:, j] tau^j``, one polynomial per sample.

    Parameters
    ----------
    coeffs
        Shape (N, K, ...): the coefficients of each sample's piece, lowest power first.
    tau
        Shape (N,): local time within each piece.
    order
        Derivative order, >= 0; at or above K the result is 0.

    Returns
    -------
    numpy.ndarray, shape (N, ...)
    """
    n_coef = coeffs.shape[1]
    if order >= n_coef:
        return np.zeros((coeffs.shape[0], *coeffs.shape[2:]))
    # d^n/dtau^n tau^j = j! / (j - n)! tau^(j - n)
    j = np.arange(order, n_coef)
    scale = np.array([math.perm(int(m), order) for m in j], dtype=float)
    c = coeffs[:, order:] * scale.reshape((1, -1) + (1,) * (coeffs.ndim - 2))
    tau_b = tau.reshape((-1,) + (1,) * (coeffs.ndim - 2))
    out = c[:, -1]
    for m in range(c.shape[1] - 2, -1, -1):
        out = out * tau_b + c[:, m]
    return np.asarray(out, dtype=float)
