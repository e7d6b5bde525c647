"""Regions with holes, step 1: hole-free pieces to plan one by one.

A field with keep-out zones (holes) cannot be spiralled or swept as one
polygon: the covering planners (:mod:`skyquill.coverage.partition` and on)
take simple polygons. :func:`hole_free_pieces` cuts each field around its
holes, as a boustrophedon cell decomposition does: from each hole, a cut
runs straight up and one straight down (through a point inside the hole) to
the next boundary, which opens the hole into the pieces on its two sides.

Each hole is first replaced by a *planning obstacle* that contains it: its
convex hull (a round hole of 64 vertices would otherwise give the
convex-part split dozens of reflex vertices), circumscribed by an octagon
when the hull has many vertices, grown by :data:`GUARD_FRACTION` of the
swath so that a planner's outer lap, which runs half a swath inside its
piece, keeps its footprint clear of the hole and not just touching it. What
the obstacle adds to the hole is counted as missed, never as covered.
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from shapely.geometry import LinearRing, LineString, Polygon
from shapely.geometry.base import BaseGeometry

from skyquill.coverage.regions import Region, fields
from skyquill.errors import SolverError

#: Planning obstacles are the hole's hull grown by this fraction of the swath, m/m.
GUARD_FRACTION = 0.02
#: Hulls with more vertices than this are circumscribed by an octagon.
MAX_OBSTACLE_VERTICES = 12
#: Pieces below this fraction of the field's area are round-off slivers.
_SLIVER = 1e-9


def planning_obstacle(hole: Polygon, width: float) -> Polygon:
    """A polygon of few vertices that contains ``hole`` with a guard band (m).

    Parameters
    ----------
    hole
        A keep-out zone (m).
    width
        Coverage diameter (m); the guard is ``GUARD_FRACTION * width``.

    Returns
    -------
    shapely.geometry.Polygon
        Convex, at most ``max(MAX_OBSTACLE_VERTICES, 8)`` vertices, containing
        ``hole.buffer(GUARD_FRACTION * width)``'s polygonal core.
    """
    hull = hole.convex_hull
    if len(hull.exterior.coords) - 1 > MAX_OBSTACLE_VERTICES:
        hull = _octagon(np.asarray(hull.exterior.coords, dtype=np.float64))
    # A mitre join keeps the vertex count; the mitre limit's bevel of very sharp
    # corners still contains the guard band's disc at that corner.
    grown = hull.buffer(GUARD_FRACTION * width, join_style="mitre", mitre_limit=2.0)
    assert isinstance(grown, Polygon)  # a buffered convex polygon
    return grown


def _octagon(points: np.ndarray) -> Polygon:
    """The octagon circumscribing ``points`` (K, 2) with sides in 8 fixed directions (m)."""
    angles = np.arange(8) * (math.pi / 4.0)
    normals = np.column_stack([np.cos(angles), np.sin(angles)])
    support = (points @ normals.T).max(axis=0)
    # Vertex k: where side k meets side k + 1 (two lines n . x = h).
    corners = []
    for k in range(8):
        a = np.vstack([normals[k], normals[(k + 1) % 8]])
        corners.append(np.linalg.solve(a, [support[k], support[(k + 1) % 8]]))
    return Polygon(corners)


def hole_free_pieces(region: Region, width: float) -> list[Polygon]:
    """Cut every field of ``region`` around its holes into polygons without holes.

    Parameters
    ----------
    region
        A checked region (:func:`~skyquill.coverage.regions.load_region`), m.
    width
        Coverage diameter (m), for the obstacles' guard band.

    Returns
    -------
    list of shapely.geometry.Polygon
        Simple polygons (m) whose union is the region minus the planning
        obstacles (:func:`planning_obstacle`), field by field.

    Raises
    ------
    SolverError
        If a piece still has a hole after the cuts (round-off at
        near-degenerate input).
    """
    pieces: list[Polygon] = []
    for field in fields(region):
        obstacles = [planning_obstacle(Polygon(ring), width) for ring in field.interiors]
        free = field.difference(shapely.union_all(obstacles)) if obstacles else field
        pieces += _cut_open(free, field.area)
    return pieces


def _cut_open(free: BaseGeometry, area: float) -> list[Polygon]:
    """The faces of ``free`` (m) once every remaining hole has its two vertical cuts."""
    parts = [p for p in shapely.get_parts(free) if isinstance(p, Polygon)]
    cuts = [cut for part in parts for ring in part.interiors for cut in _cuts(part, ring)]
    if not cuts:
        return [p for p in parts if p.area > _SLIVER * area]
    faces = shapely.get_parts(shapely.polygonize([shapely.union_all([free.boundary, *cuts])]))
    inside = [
        f for f in faces if isinstance(f, Polygon) and free.contains(f.representative_point())
    ]
    out = [shapely.normalize(f) for f in inside if f.area > _SLIVER * area]
    if any(p.interiors for p in out):
        raise SolverError(
            "region: got a hole that the vertical cuts did not open (round-off?), expected "
            "hole-free pieces"
        )
    return out


def _cuts(part: Polygon, ring: LinearRing) -> list[LineString]:
    """The vertical segments of ``part`` from the hole ``ring`` up and down to the boundary."""
    hole = Polygon(ring)
    x = hole.representative_point().x
    _, low, _, high = part.bounds
    line = LineString([(x, low - 1.0), (x, high + 1.0)])
    spans = shapely.get_parts(part.intersection(line))
    scale = 1.0 + math.sqrt(part.area)
    touching = [s for s in spans if isinstance(s, LineString) and s.distance(hole) <= 1e-9 * scale]
    # Computed ends lie on the boundary only up to round-off: a cut that stops
    # short of it is not noded and opens nothing, so it is made to cross.
    return [_extended(s, 1e-7 * scale) for s in touching]


def _extended(segment: LineString, by: float) -> LineString:
    """``segment`` lengthened by ``by`` (m) at both ends."""
    a, b = np.asarray(segment.coords, dtype=np.float64)[[0, -1]]
    u = (b - a) / float(np.linalg.norm(b - a))
    return LineString([a - by * u, b + by * u])
