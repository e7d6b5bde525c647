"""Formations: where each drone of a show stands still, at least the safety distance apart.

A formation is a set of points in the world frame (z up, m). Shapes are drawn
on a vertical plane facing ``-y`` (the audience stands at ``-y``, as in front
of a :class:`~skyquill.calligraphy.board.Board` of kind ``"wall"``): a
drawing's ``(u, v)`` goes to ``origin + (u, 0, v)``.

* :func:`shape_formation` -- points evenly along the strokes of a drawing (an
  SVG, a text, a Chinese character: any :class:`~skyquill.strokes.Strokes`);
* :func:`grid_formation`, :func:`circle_formation` -- generated ones;
* :func:`home_grid` -- the take-off and landing pads on the ground.

Every generator refuses (:class:`~skyquill.errors.InputError`) a formation
that cannot hold the drones at the spacing asked for, naming both counts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial.distance import pdist

from skyquill.errors import InputError
from skyquill.strokes import Strokes
from skyquill.validation import FloatArray, as_array, as_float, as_int

#: Dense samples per spacing along the strokes: a greedy pick lands within
#: ``spacing / DENSITY`` of where the ideal one would be.
DENSITY = 8
#: Bisection steps of the spacing that spreads the drones evenly over a shape.
BISECTIONS = 30
#: Relative margin kept above the spacing asked for: the separation proof
#: (:mod:`skyquill.show.separation`) bisects down to where a drone leaving a
#: neighbour at exactly the safety distance is proven apart; 3 um on 3 m is
#: reached in a few bisections, 0 never.
SPACING_MARGIN = 1e-6


@dataclass(frozen=True)
class Formation:
    """Points where the drones hold, at least ``spacing_m`` apart.

    Attributes
    ----------
    points
        One per drone, shape (N, 3), world frame, m.
    spacing_m
        The smallest distance between two of them, m.
    name
        What it shows, for messages and ``summary.json``.
    """

    points: FloatArray
    spacing_m: float
    name: str


def _plane(origin: FloatArray, uv: FloatArray) -> FloatArray:
    """Drawing coordinates (K, 2), m, on the vertical plane through ``origin`` facing -y."""
    return np.asarray(origin + np.column_stack([uv[:, 0], np.zeros(len(uv)), uv[:, 1]]))


def _formation(points: FloatArray, name: str) -> Formation:
    closest = float(pdist(points).min()) if len(points) > 1 else math.inf
    return Formation(points, closest, name)


def _resampled(paths: tuple[FloatArray, ...], step: float) -> list[FloatArray]:
    """Each path resampled every ``step`` of arc length (both ends kept), (K_i, 2)."""
    out = []
    for path in paths:
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))])
        s = np.linspace(0.0, arc[-1], max(2, math.ceil(arc[-1] / step) + 1))
        out.append(np.column_stack([np.interp(s, arc, path[:, k]) for k in range(2)]))
    return out


def _greedy(paths: tuple[FloatArray, ...], spacing: float) -> FloatArray:
    """Points along ``paths`` in drawing order, each kept if ``spacing`` from all kept, (M, 2).

    The kept points are binned in square cells of side ``spacing``: one closer than
    ``spacing`` lies in the sample's cell or one of its eight neighbours, so each
    sample is compared with a few points, not with all of them (a thousand drones'
    shape was 70 s of comparisons).
    """
    kept: list[tuple[float, float]] = []
    cells: dict[tuple[int, int], list[tuple[float, float]]] = {}
    for sample in _resampled(paths, spacing / DENSITY):
        for u, v in sample.tolist():
            i, j = math.floor(u / spacing), math.floor(v / spacing)
            near = (
                q for di in (-1, 0, 1) for dj in (-1, 0, 1) for q in cells.get((i + di, j + dj), ())
            )
            if all(math.hypot(q[0] - u, q[1] - v) >= spacing for q in near):
                kept.append((u, v))
                cells.setdefault((i, j), []).append((u, v))
    return np.asarray(kept, dtype=float).reshape(-1, 2)


def shape_formation(
    strokes: Strokes,
    count: int,
    *,
    origin: FloatArray,
    size_m: float,
    spacing_m: float,
) -> Formation:
    """``count`` points spread evenly along the strokes of a drawing, in the air.

    The drawing is scaled so that its larger side is ``size_m`` and placed with
    its bottom-left corner at ``origin`` on the vertical plane facing ``-y``.
    The points are picked greedily along the strokes, in drawing order, each at
    least a distance ``r`` from all picked before; ``r`` is the largest (found
    by bisection, at least ``spacing_m``) that still gives ``count`` points,
    so the drones spread over the whole drawing.

    Parameters
    ----------
    strokes
        The drawing (:func:`skyquill.strokes.typed_strokes`, :func:`~skyquill.strokes.load_svg`).
    count
        Number of drones, >= 1.
    origin
        World position of the drawing's bottom-left corner (3,), m.
    size_m
        Larger side of the drawing, m.
    spacing_m
        Smallest distance between two drones, m (the show's safety distance).

    Raises
    ------
    InputError
        More drones than fit on the drawing at ``spacing_m`` (naming both counts).
    """
    n = as_int("drones", count, low=1)
    corner = as_array("origin", origin, shape=(3,))
    size = as_float("size_m", size_m, positive=True)
    low = as_float("spacing_m", spacing_m, positive=True) * (1.0 + SPACING_MARGIN)
    paths = strokes.scaled(size).paths
    capacity = len(_greedy(paths, low))
    if capacity < n:
        raise InputError(
            f"drones: got {n}, expected at most {capacity} (the points {spacing_m:g} m apart "
            f"along {strokes.source or 'the drawing'} at {size:g} m)"
        )
    high = float(sum(np.linalg.norm(np.diff(p, axis=0), axis=1).sum() for p in paths)) + low
    for _ in range(BISECTIONS):
        mid = 0.5 * (low + high)
        low, high = (mid, high) if len(_greedy(paths, mid)) >= n else (low, mid)
    picked = _greedy(paths, low)
    # Any subset keeps the spacing; an even one keeps the spread along the strokes.
    chosen = picked[np.round(np.linspace(0, len(picked) - 1, n)).astype(int)]
    return _formation(_plane(corner, chosen), strokes.source or "drawing")


def _padded(spacing: float) -> float:
    """``spacing`` grown by :data:`SPACING_MARGIN` (3 um on 3 m): never exactly the minimum."""
    return spacing * (1.0 + SPACING_MARGIN)


def grid_formation(
    count: int, *, origin: FloatArray, columns: int, spacing_m: float, safety_m: float
) -> Formation:
    """``count`` points in rows of ``columns`` on the vertical plane, bottom row first.

    The spacing is grown by :data:`SPACING_MARGIN`, so that a spacing equal to
    the safety distance can be proven kept.

    Raises
    ------
    InputError
        ``spacing_m`` below the safety distance ``safety_m``.
    """
    n = as_int("drones", count, low=1)
    cols = as_int("columns", columns, low=1)
    spacing = as_float("spacing", spacing_m, positive=True)
    if spacing < as_float("safety_distance", safety_m, positive=True):
        raise InputError(
            f"spacing: got {spacing:g} m, expected at least the safety distance {safety_m:g} m"
        )
    k = np.arange(n)
    uv = _padded(spacing) * np.column_stack([k % cols, k // cols]).astype(float)
    corner = as_array("origin", origin, shape=(3,))
    return _formation(_plane(corner, uv), f"grid of {cols} columns")


def circle_capacity(radius_m: float, spacing_m: float) -> int:
    """Most points on a circle of ``radius_m`` with neighbours ``spacing_m`` apart (chords)."""
    if spacing_m > 2.0 * radius_m:
        return 1
    return max(1, math.floor(math.pi / math.asin(spacing_m / (2.0 * radius_m)) + 1e-9))


def circle_formation(
    count: int, *, center: FloatArray, radius_m: float, spacing_m: float
) -> Formation:
    """``count`` points evenly on a vertical circle, the first at the top.

    Raises
    ------
    InputError
        More drones than the circle holds ``spacing_m`` apart (naming both counts).
    """
    n = as_int("drones", count, low=1)
    radius = as_float("radius", radius_m, positive=True)
    spacing = as_float("spacing_m", spacing_m, positive=True)
    capacity = circle_capacity(radius, spacing * (1.0 + SPACING_MARGIN))
    if n > capacity:
        raise InputError(
            f"drones: got {n}, expected at most {capacity} (the points {spacing:g} m apart on a "
            f"circle of radius {radius:g} m)"
        )
    angle = 2.0 * math.pi * np.arange(n) / n
    uv = radius * np.column_stack([np.sin(angle), np.cos(angle)])
    centre = as_array("center", center, shape=(3,))
    return _formation(_plane(centre, uv), f"circle of radius {radius:g} m")


def home_grid(count: int, *, origin: FloatArray, spacing_m: float, safety_m: float) -> FloatArray:
    """Take-off pads on the ground (z = 0): a square-ish grid from ``origin`` along +x and +y.

    The spacing is grown by :data:`SPACING_MARGIN`, as in :func:`grid_formation`.

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        Row by row (rows along +x, one row after another along +y), m.

    Raises
    ------
    InputError
        ``spacing_m`` below the safety distance ``safety_m``.
    """
    n = as_int("drones", count, low=1)
    spacing = as_float("home_spacing", spacing_m, positive=True)
    if spacing < as_float("safety_distance", safety_m, positive=True):
        raise InputError(
            f"home_spacing: got {spacing:g} m, expected at least the safety distance {safety_m:g} m"
        )
    corner = as_array("home_origin", origin, shape=(2,))
    cols = math.ceil(math.sqrt(n))
    k = np.arange(n)
    xy = corner + _padded(spacing) * np.column_stack([k % cols, k // cols]).astype(float)
    return np.column_stack([xy, np.zeros(n)])
