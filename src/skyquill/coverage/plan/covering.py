"""The covering path: a pattern's waypoints, its flown path densely sampled, and what it covers."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray
from shapely.geometry import LineString, Polygon

from skyquill.coverage.missed import Missed, missed_area
from skyquill.coverage.paths import (
    contours,
    merge_close,
    spiral_control_points,
    spiral_curve,
    with_corner_points,
    zigzag,
)
from skyquill.coverage.plan.options import CoverageOptions
from skyquill.coverage.regions import swept

FloatArray = NDArray[np.float64]


#: Spacing of the speed LP's grid along the path, m (the grid needs several
#: points per corner feature; see :func:`grid_points`).
GRID_SPACING_M = 0.05


#: Waypoints closer than this fraction of ``delta`` are one (see :func:`covering_waypoints`).
MERGE_FRACTION = 0.01


#: Bounds on the LP's grid size (LP time grows faster than linearly).
GRID_POINTS = (300, 2000)


#: Spacing of the dense samples that coverage is measured on, m.
COVERAGE_SPACING_M = 0.02


#: Degree of the covering splines (paper 001: 4, so that jerk is differentiable).
SPLINE_DEGREE = 4


def grid_points(length: float) -> int:
    """Speed-LP grid size for a path of ``length`` metres (spacing ~5 cm, bounded)."""
    lo, hi = GRID_POINTS
    return int(min(max(math.ceil(length / GRID_SPACING_M), lo), hi))


def is_convex(region: Polygon) -> bool:
    """Whether ``region`` equals its convex hull (to round-off)."""
    return bool(region.convex_hull.area - region.area <= 1e-9 * region.area)


def covering_waypoints(region: Polygon, options: CoverageOptions) -> FloatArray:
    """The pattern's waypoints: a spline's control polygon, or the stop points.

    Concave regions are decomposed into convex parts, covered one after the
    other along one continuous path. Waypoints closer than
    :data:`MERGE_FRACTION` of ``delta`` to the previous one are merged
    (:func:`~skyquill.coverage.paths.merge_close`).
    """
    return merge_close(_waypoints(region, options), MERGE_FRACTION * options.delta)


def _waypoints(region: Polygon, options: CoverageOptions) -> FloatArray:
    w, d, eps = options.width, options.delta, options.epsilon
    if options.pattern == "spiral":
        if is_convex(region):
            rings = contours(region, w, options.contours, epsilon=eps)
            return spiral_control_points(rings, d, drift=options.drift)
        from skyquill.coverage.joined import multi_spiral_control_points

        return multi_spiral_control_points(region, eps * w, mode=options.contours, delta=d)
    # The sweep lines' spacing is the swath; epsilon < 1 packs them closer.
    if is_convex(region):
        stops = zigzag(region, eps * w, perimeter=options.perimeter)
    else:
        from skyquill.coverage.joined import multi_zigzag

        stops = multi_zigzag(region, eps * w, perimeter=options.perimeter)
    if options.pattern == "zigzag-stop":
        return stops
    return with_corner_points(merge_close(stops, MERGE_FRACTION * d), d)


def covering_path(region: Polygon, options: CoverageOptions) -> tuple[FloatArray, FloatArray]:
    """The pattern's waypoints ``(K, 2)`` and its flown path densely sampled ``(M, 2)``, m."""
    waypoints = covering_waypoints(region, options)
    if options.pattern == "zigzag-stop":
        return waypoints, densified(waypoints)
    return waypoints, dense_path(spiral_curve(waypoints))


def dense_path(curve: Any) -> FloatArray:
    """``curve`` sampled every ~``COVERAGE_SPACING_M`` (by its control polygon's length)."""
    rough = np.asarray(curve(np.linspace(0.0, 1.0, 2001)), dtype=np.float64)
    length = float(np.linalg.norm(np.diff(rough, axis=0), axis=1).sum())
    m = max(2001, math.ceil(length / COVERAGE_SPACING_M))
    return np.asarray(curve(np.linspace(0.0, 1.0, m)), dtype=np.float64)


def densified(waypoints: FloatArray) -> FloatArray:
    """A polyline resampled every ~``COVERAGE_SPACING_M`` (its corners kept)."""
    line = LineString(waypoints)
    m = max(2, math.ceil(line.length / COVERAGE_SPACING_M))
    along = np.unique(np.concatenate([np.linspace(0.0, line.length, m), _vertex_distances(line)]))
    return np.array([line.interpolate(s).coords[0] for s in along], dtype=np.float64)


def _vertex_distances(line: LineString) -> FloatArray:
    xy = np.asarray(line.coords, dtype=np.float64)
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xy, axis=0), axis=1))])


def path_length(path: FloatArray) -> float:
    return float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())


def measured(region: Polygon, path: FloatArray, width: float) -> tuple[float, Missed]:
    """Covered fraction of ``region`` by ``path``'s swath and what it misses (one buffer)."""
    area = swept(path, width)
    return float(region.intersection(area).area / region.area), missed_area(region, area)
