"""Transit legs between covered pieces: the shortest polyline that goes around the holes.

A transit is flown with the spray off, but the vehicle must still not fly
over a keep-out zone. :func:`transit_route` finds the shortest path on the
visibility graph of the holes' hulls grown by a clearance (the classic exact
method for polygonal obstacles: a shortest path bends only at obstacle
vertices), solved by scipy's Dijkstra.
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Sequence

import numpy as np
import shapely
from scipy.sparse import csr_array
from scipy.sparse.csgraph import dijkstra
from shapely.geometry import Point, Polygon

from skyquill.coverage.holes import planning_obstacle
from skyquill.validation import FloatArray

#: The route keeps this fraction of its clearance at least from the holes' hulls.
_BLOCK_FRACTION = 0.5


def transit_route(
    begin: FloatArray, end: FloatArray, holes: Sequence[Polygon], clearance: float
) -> FloatArray:
    """The shortest route ``(M, 2)`` from ``begin`` to ``end`` (m) that avoids ``holes``.

    Parameters
    ----------
    begin, end
        Points ``(2,)``, m.
    holes
        Keep-out zones (m).
    clearance
        Distance the route's corners keep from the holes' hulls (m), > 0; its
        legs keep at least half of it.

    Returns
    -------
    ndarray
        Polyline from ``begin`` to ``end`` (m); straight when nothing is in
        the way. An end point within half the clearance of a hole (where a
        piece's path ended close to it) may leave and reach it straight.
    """
    corners, blocks = _graph_geometry(tuple(holes), clearance)
    straight = np.vstack([begin, end])
    # Nothing in the way: the shortest route, as the search would find (a mission of n
    # pieces routes n (n - 1) pairs to order them, most in the open).
    if _visible_lengths(straight, blocks)[0, 1] > 0.0:
        return straight
    return _searched_route(np.vstack([straight, *corners]) if corners else straight, blocks)


def _searched_route(nodes: FloatArray, blocks: Sequence[tuple[Polygon, Polygon]]) -> FloatArray:
    """The shortest route from ``nodes[0]`` to ``nodes[1]`` through the others (K, 2), m,
    on the legs that cross no block (the two ends alone when none reaches)."""
    weights = _visible_lengths(nodes, blocks)
    _, parents = dijkstra(csr_array(weights), indices=np.array([0]), return_predecessors=True)
    parent = parents[0]
    route = [1]
    while route[-1] != 0:
        route.append(int(parent[route[-1]]))
        if route[-1] < 0:  # unreachable: only when the ends are walled in by holes
            return nodes[:2]
    out: FloatArray = nodes[route[::-1]]
    return out


@functools.lru_cache(maxsize=16)
def _graph_geometry(
    holes: tuple[Polygon, ...], clearance: float
) -> tuple[list[FloatArray], list[tuple[Polygon, Polygon]]]:
    """The graph's corner points (each grown hull's vertices) and, per hole, the polygon
    that blocks legs and the hull itself.

    Kept for the last holes seen: a mission routes every pair of its pieces round the
    same holes (82 pieces of the 100 ha field: 6,642 routes, 2.6 s of it rebuilding this).
    """
    corners: list[FloatArray] = []
    blocks: list[tuple[Polygon, Polygon]] = []
    for hole in holes:
        grown = planning_obstacle(hole, 0.0).buffer(clearance, join_style="mitre")
        corners.append(np.asarray(grown.exterior.coords, dtype=np.float64)[:-1])
        hull = hole.convex_hull
        blocks.append((hull.buffer(_BLOCK_FRACTION * clearance), hull))
    if corners:
        points = shapely.points(np.vstack(corners))
        # A corner inside another hole's block is no way round.
        inside = np.any([shapely.intersects(points, b) for b, _ in blocks], axis=0)
        corners = [np.vstack(corners)[~inside]]
    return corners, blocks


def _visible_lengths(nodes: FloatArray, blocks: Sequence[tuple[Polygon, Polygon]]) -> FloatArray:
    """Lengths of the legs between ``nodes`` (K, 2) that cross no block (0: no leg)."""
    k = len(nodes)
    pairs = np.array(list(itertools.combinations(range(k), 2)), dtype=np.intp)
    legs = shapely.linestrings(np.stack([nodes[pairs[:, 0]], nodes[pairs[:, 1]]], axis=1))
    blocked = np.zeros(len(pairs), dtype=bool)
    for block, hull in blocks:
        hit = shapely.intersects(legs, block)
        # The ends of the transit may lie in a block (a piece ended near its
        # hole): their legs only have to miss the hole's hull.
        for e in (0, 1):
            if block.contains(Point(nodes[e])):
                mine = np.any(pairs == e, axis=1)
                hit[mine] = shapely.intersects(legs[mine], hull)
        blocked |= hit
    weights = np.zeros((k, k))
    a, b = pairs[~blocked].T
    lengths = np.linalg.norm(nodes[a] - nodes[b], axis=1)
    # A zero weight is "no edge" to scipy: coincident nodes get a tiny length.
    weights[a, b] = weights[b, a] = np.maximum(lengths, 1e-12)
    return weights
