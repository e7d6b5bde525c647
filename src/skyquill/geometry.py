"""Small geometric helpers shared by the engine's users (fidelity checks, studies)."""

from __future__ import annotations

import numpy as np

from skyquill.errors import InputError
from skyquill.validation import FloatArray, as_array


def polyline_distance(points: FloatArray, vertices: FloatArray) -> FloatArray:
    """Distance from each point to the nearest point of a polyline.

    Parameters
    ----------
    points
        Shape (N, d), m.
    vertices
        The polyline's vertices in order, shape (V, d), V >= 2, m. Repeated
        consecutive vertices (zero-length segments) are allowed.

    Returns
    -------
    numpy.ndarray, shape (N,), m
    """
    p = as_array("points", points, ndim=2)
    v = as_array("vertices", vertices, shape=(None, p.shape[1]))
    if v.shape[0] < 2:
        raise InputError(f"vertices: got {v.shape[0]} vertex, expected at least 2")
    a = v[:-1]  # (S, d)
    ab = v[1:] - a
    length2 = np.einsum("sd,sd->s", ab, ab)
    best = np.full(p.shape[0], np.inf)
    for start in range(0, p.shape[0], 4096):  # bounded (chunk, S, d) temporaries
        q = p[start : start + 4096, None, :] - a[None, :, :]
        s = np.einsum("nsd,sd->ns", q, ab) / np.where(length2 > 0.0, length2, 1.0)
        s = np.clip(s, 0.0, 1.0)
        gap = q - s[:, :, None] * ab[None, :, :]
        best[start : start + 4096] = np.sqrt(np.einsum("nsd,nsd->ns", gap, gap).min(axis=1))
    return best
