"""Piecewise power-basis polynomials: the one evaluator every polynomial trajectory uses."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from skyquill.validation import FloatArray


def _scaled(coeffs: FloatArray, order: int) -> FloatArray:
    """Coefficients of derivative ``order``: ``coeffs[:, j] * j! / (j - order)!`` for j >= order.

    ``coeffs`` (M, K, ...) with ``order < K``; shape (M, K - order, ...). Order 0 is the
    coefficients themselves (a product by 1.0 changes no float).
    """
    if order == 0:
        return coeffs
    # d^n/dtau^n tau^j = j! / (j - n)! tau^(j - n)
    scale = np.array([math.perm(j, order) for j in range(order, coeffs.shape[1])], dtype=float)
    return np.asarray(coeffs[:, order:] * scale.reshape((1, -1) + (1,) * (coeffs.ndim - 2)))


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


def power_columns(coeffs: FloatArray, order: int) -> FloatArray:
    """The coefficients of derivative ``order`` of every piece, one contiguous block per power.

    ``coeffs`` (P, K, ...) with ``order < K``; shape (K - order, P, ...): what
    :func:`horner_columns` evaluates. Worth keeping for a table evaluated many times.
    """
    return np.ascontiguousarray(np.moveaxis(np.asarray(_scaled(coeffs, order), dtype=float), 1, 0))


def horner_columns(columns: FloatArray, idx: NDArray[np.intp], tau: FloatArray) -> FloatArray:
    """The polynomials ``sum_j columns[j, idx] tau^j`` (:func:`power_columns`), shape (N, ...)."""
    tau_b = tau.reshape((-1,) + (1,) * (columns.ndim - 2))
    out = columns[-1].take(idx, axis=0)
    for m in range(columns.shape[0] - 2, -1, -1):
        out = out * tau_b + columns[m].take(idx, axis=0)
    return np.asarray(out)


def horner_at(
    coeffs: FloatArray, idx: NDArray[np.intp], tau: FloatArray, order: int = 0
) -> FloatArray:
    """:func:`horner` of the pieces ``coeffs[idx]``, without gathering them first.

    The same floats as ``horner(coeffs[idx], tau, order)``, bit for bit (the same products
    and sums in the same order), at a quarter of the time on long samples: the derivative's
    coefficients are scaled once per piece, not once per sample, and each power's column
    is gathered on its own (``take`` of a contiguous (P, ...) block) instead of every
    sample's whole (K, ...) block. With fewer samples than pieces, it is ``horner`` of the
    gathered pieces.

    Parameters
    ----------
    coeffs
        Shape (P, K, ...): each piece's coefficients, lowest power first.
    idx
        Shape (N,): the piece of each sample, in ``[0, P)``.
    tau
        Shape (N,): local time within each sample's piece.
    order
        Derivative order, >= 0; at or above K the result is 0.

    Returns
    -------
    numpy.ndarray, shape (N, ...)
    """
    if order >= coeffs.shape[1]:
        return np.zeros((idx.size, *coeffs.shape[2:]))
    if idx.size < coeffs.shape[0]:
        # fewer samples than pieces: scaling and copying every piece would cost more
        return horner(coeffs[idx], tau, order)
    return horner_columns(power_columns(coeffs, order), idx, tau)
