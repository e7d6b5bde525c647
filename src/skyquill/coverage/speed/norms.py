"""How the acceleration and jerk limits are held: per-axis boxes or norms.

Per axis (``norm_sides=None``), ``|x_k| <= lim_k`` for every axis ``k``.  A
Euclidean norm ``|x| <= lim`` is not linear; it is held through the inscribed
regular polygon of ``m`` sides, ``n_j . x <= lim cos(pi / m)`` for its edge
normals ``n_j`` -- still linear in ``b`` when ``x`` is the chain-rule
acceleration or pseudo-jerk.  The LP's rows are two-sided (``|row| <= r``), so
the ``m / 2`` normals of one half-plane give all ``m`` edges (``m`` even).  On
a 3-D path the horizontal norm is held by the polygon and the vertical
component by ``|x_z| <= lim``.

The LP sees the limits as *components*: the axes, or the projections on the
polygon's normals (:func:`components`), each with its own bound
(:func:`component_limits`).  What the plan measures afterwards
(:func:`limit_ratio`) is the limit itself, not its polygon.
"""

from __future__ import annotations

import numpy as np

from skyquill.validation import FloatArray


def directions(norm_sides: int, d: int) -> FloatArray:
    """Unit normals of the polygon's edges (one per opposite pair), shape (q, d).

    ``q = m / 2`` on a 2-D path; on a 3-D path the normals lie in the
    horizontal plane and ``e_z`` is appended (``q = m / 2 + 1``).
    """
    angles = 2.0 * np.pi * np.arange(norm_sides // 2) / norm_sides
    planar = np.column_stack([np.cos(angles), np.sin(angles)])
    if d == 2:
        return planar
    horizontal = np.column_stack([planar, np.zeros(planar.shape[0])])
    return np.vstack([horizontal, [0.0, 0.0, 1.0]])


def components(x: FloatArray, norm_sides: int | None) -> FloatArray:
    """The limited components of ``x`` (N, d): ``x`` itself per axis, else its projections."""
    if norm_sides is None:
        return x
    return np.asarray(x @ directions(norm_sides, x.shape[1]).T, dtype=np.float64)


def component_limits(lim: FloatArray, norm_sides: int | None) -> FloatArray:
    """Bound of every component: ``lim`` per axis; ``lim cos(pi/m)`` on the polygon's normals."""
    if norm_sides is None:
        return lim
    q = norm_sides // 2
    held = np.full(q, float(lim[0]) * np.cos(np.pi / norm_sides))
    # The vertical component of a 3-D path is bounded by the limit itself.
    return held if lim.size == 2 else np.append(held, float(lim[0]))


def limit_ratio(x: FloatArray, lim: FloatArray, norm_sides: int | None) -> FloatArray:
    """Per sample, ``x`` (N, d) over its limit: ``max_k |x_k| / lim_k``, or ``|x| / lim``.

    With norms on a 3-D path, the larger of the horizontal norm and ``|x_z|``
    over ``lim``.
    """
    if norm_sides is None:
        return np.asarray(np.max(np.abs(x) / lim, axis=1), dtype=np.float64)
    ratio = np.linalg.norm(x[:, :2], axis=1)
    if x.shape[1] == 3:
        ratio = np.maximum(ratio, np.abs(x[:, 2]))
    return np.asarray(ratio / float(lim[0]), dtype=np.float64)
