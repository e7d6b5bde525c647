"""Concave regions: convex decomposition and the paper's multi-spiral (Fig. 5).

Paper 001 §1 (end): a region whose centre is not inside it cannot be covered
by one spiral; it is split into convex parts, each part gets its spiral
control points, the control points of the parts are *connected* and one
B-spline is fitted through all of them, giving one continuous "double" (or
multi-) spiral. This module does that:

* :func:`convex_parts` -- a few fat convex parts whose union is the region;
* :func:`order_parts` -- a visiting order in which consecutive parts share an
  edge, so transits are short;
* :func:`multi_spiral_control_points` -- the joined control polygon; feed it to
  :func:`~skyquill.coverage.paths.spiral_curve` for the single C³ curve;
* :func:`multi_zigzag` -- the same for the boustrophedon the paper compares
  against.

Joins between parts are routed inside the region: straight when the segment
lies in the region, else through "portals" (points on the edges shared by
consecutive parts of the adjacency graph). Every leg of such a route lies in
one convex part, and around each corner of the route a few collinear control
points are packed so that every window of ``degree + 1 = 5`` consecutive
control points straddling the corner lies in a disc around it that is inside
the region -- the B-spline stays in the convex hull of each such window, so
the curve provably stays inside the region (up to round-off).

Two additions to the paper make the joined paths cover >= 97 % at a
2 m swath: the corners of each part's first spiral lap are pulled toward the
part's corners (the B-spline cuts corners), and each zigzag lap gets a short
out-and-back spike into corners sharper than about 84°.
"""

from __future__ import annotations

import itertools
import math
from collections import deque
from collections.abc import Sequence

import numpy as np
import shapely
from shapely.geometry import LineString, Point, Polygon
from shapely.geometry.polygon import orient

from skyquill.coverage.paths import ContourMode, contours, spiral_control_points, zigzag
from skyquill.coverage.regions import check_width
from skyquill.errors import InputError
from skyquill.validation import FloatArray, as_float, as_int

#: Relative tolerance (of the region's area) for "convex" and "same area".
_AREA_TOL = 1e-9
#: Relative tolerance (of the region's size) for coincident points and collinearity.
_LEN_TOL = 1e-9
#: Parts below this fraction of the region's area are round-off slivers (zero-width spikes).
_SLIVER = 1e-12
#: Parts narrower than this many swath widths are not flown (see ``_flown_parts``).
_SLIVER_WIDTH = 1e-3
#: Reflex vertices whose two cut choices are all enumerated (2**n candidates).
_ENUMERATED_REFLEX = 4
#: Part count up to which the visiting order is searched exactly (Held-Karp).
_EXACT_ORDER = 9
#: Collinear control points packed on each side of a join corner (degree 4: 4).
_PACKED = 4
#: Weight (in swath areas ``width**2``) of one extra part in the decomposition cost.
_PART_COST = 0.5
#: Outer-lap corners are pulled to this many half-widths from the part's corner.
_CORNER_PULL = 0.5
#: Zigzag laps get a spike at corners whose lap vertex is farther than this many half-widths.
_SPIKE_GAP = 1.5


# ---------------------------------------------------------------------------
# Decomposition
# ---------------------------------------------------------------------------


def convex_parts(region: Polygon, width: float) -> list[Polygon]:
    """Split a simple polygon into few fat convex parts.

    Two well-known methods give candidate decompositions and the cheapest one
    is kept:

    * **Hertel-Mehlhorn**: a constrained Delaunay triangulation (shapely),
      then diagonals are removed greedily -- longest first, which leaves fat
      parts -- whenever the two parts they separate merge into a convex one.
      At most 4x the optimal number of convex parts (Hertel & Mehlhorn 1983),
      but its cuts only join vertices: an L gets two trapezoids with 45°
      corners.
    * **Reflex-vertex cuts**: each reflex vertex is resolved by extending one
      of its two edges into the region until it meets the boundary (for
      ``<= 4`` reflex vertices every combination of choices is tried, else the
      shorter cut is taken), then adjacent pieces are merged greedily while
      the union stays convex. This is the cellular decomposition a
      boustrophedon planner uses for polygons with axis-like edges; an L gets
      two rectangles.

    The cost of a decomposition is the area a disc of diameter ``width``
    cannot reach from inside its own part (the morphological opening of each
    part: acute corners made by a cut are lost) plus ``0.5 width²`` per part
    (each part adds a transit). Parts narrower than ``width`` are kept, not
    dropped: the covering paths fly along their long axis (a spiral of a thin
    part is a line); the cost charges them for what that line misses. Only
    round-off slivers (area below ``1e-12`` of the region's, e.g. from
    near-coincident vertices) are dropped. Candidates whose parts are not all
    convex or do not tile the region (round-off at near-degenerate input) are
    discarded.

    Parameters
    ----------
    region
        Simple polygon without holes (m), e.g. from
        :func:`~skyquill.coverage.regions.region_from_vertices`.
    width
        Coverage diameter (m), as in :func:`~skyquill.coverage.regions.check_width`.

    Returns
    -------
    list of shapely.geometry.Polygon
        Convex parts (m) whose union is ``region``; ``[region]`` if it is convex.

    Raises
    ------
    InputError
        If ``region`` is not a hole-free polygon, ``width`` is not positive
        and smaller than the region's inner width, or no candidate survives
        the checks (near-degenerate region).
    """
    polygon = _checked_region(region)
    w = check_width(polygon, width)
    if _is_convex(polygon):
        return [polygon]
    candidates = [_hertel_mehlhorn(polygon), *_reflex_cut_decompositions(polygon)]
    # Round-off slivers of no area (collinear triangles, cuts along edges) hold nothing.
    # Normalised before the tiling check: GEOS unions depend on vertex order,
    # so the parts are checked exactly as they are returned.
    candidates = [
        [shapely.normalize(p) for p in c if p.area > _SLIVER * polygon.area] for c in candidates
    ]
    candidates = [c for c in candidates if _tiles(polygon, c)]
    if not candidates:
        raise InputError(
            "region: got a polygon that could not be split into convex parts (near-degenerate "
            "spikes or collinear vertices?), expected a simple polygon of positive width"
        )
    # Straight vertices left by cuts are kept: a neighbour may have a corner
    # there, and dropping it makes GEOS unions of the parts unreliable.
    return min(candidates, key=lambda parts: _decomposition_cost(polygon, parts, w))


def _tiles(region: Polygon, parts: list[Polygon]) -> bool:
    """Whether ``parts`` are convex and tile the region (up to round-off)."""
    total = sum(p.area for p in parts)
    if abs(total - region.area) > _AREA_TOL * region.area or not all(map(_is_convex, parts)):
        return False
    # Equal areas could still hide an overlap plus a gap.
    gap = region.symmetric_difference(shapely.union_all(parts)).area
    return bool(gap <= _AREA_TOL * region.area)


def _checked_region(region: object) -> Polygon:
    if not isinstance(region, Polygon) or region.is_empty:
        raise InputError(f"region: got {type(region).__name__}, expected a shapely Polygon")
    if region.interiors:
        raise InputError(
            f"region: got a polygon with {len(region.interiors)} hole(s), expected none"
        )
    if not region.is_valid or region.area <= 0.0:
        raise InputError("region: got an invalid or empty polygon, expected a simple one")
    return region


def _is_convex(polygon: Polygon) -> bool:
    return bool(polygon.convex_hull.area - polygon.area <= _AREA_TOL * polygon.area)


def _ccw_ring(polygon: Polygon) -> FloatArray:
    """Counter-clockwise exterior vertices ``(K, 2)``, no closing repeat or duplicates."""
    pts = np.asarray(orient(polygon, sign=1.0).exterior.coords, dtype=np.float64)[:-1, :2]
    step = np.linalg.norm(pts - np.roll(pts, 1, axis=0), axis=1)
    out: FloatArray = pts[step > _LEN_TOL * max(1.0, float(np.abs(pts).max()))]
    return out


def _hertel_mehlhorn(region: Polygon) -> list[Polygon]:
    """Triangulate, then drop diagonals (longest first) while both sides stay convex."""
    triangles = list(shapely.constrained_delaunay_triangles(region).geoms)
    owners: dict[tuple[tuple[float, float], ...], list[int]] = {}
    for t, tri in enumerate(triangles):
        corners = [(float(x), float(y)) for x, y in tri.exterior.coords[:3]]
        for a, b in itertools.combinations(corners, 2):
            owners.setdefault(tuple(sorted((a, b))), []).append(t)
    diagonals = sorted(
        ((edge, ts) for edge, ts in owners.items() if len(ts) == 2),
        key=lambda item: -math.dist(*item[0]),
    )
    root = list(range(len(triangles)))
    shape: dict[int, Polygon] = dict(enumerate(triangles))

    def find(i: int) -> int:
        while root[i] != i:
            i = root[i]
        return i

    for _, (t1, t2) in diagonals:
        r1, r2 = find(t1), find(t2)
        if r1 == r2:
            continue
        merged = shapely.union(shape[r1], shape[r2])
        if isinstance(merged, Polygon) and _is_convex(merged):
            root[r2] = r1
            shape[r1] = merged
            del shape[r2]
    return list(shape.values())


def _reflex_cut_decompositions(region: Polygon) -> list[list[Polygon]]:
    """Reflex-vertex edge-extension decompositions, one per combination of cut choices."""
    reflex = _reflex_vertices(_ccw_ring(region))
    keys = [(float(x), float(y)) for x, y in reflex[:_ENUMERATED_REFLEX]]
    out: list[list[Polygon]] = []
    for choice in itertools.product((0, 1), repeat=len(keys)):
        pieces = _cut_to_convex(region, dict(zip(keys, choice, strict=True)))
        if pieces is not None:
            out.append(_merge_convex(pieces))
    return out


def _reflex_vertices(ring: FloatArray) -> FloatArray:
    """The vertices ``(R, 2)`` of a counter-clockwise ring with an interior angle > 180°."""
    into = ring - np.roll(ring, 1, axis=0)
    out = np.roll(ring, -1, axis=0) - ring
    cross = into[:, 0] * out[:, 1] - into[:, 1] * out[:, 0]
    scale = np.linalg.norm(into, axis=1) * np.linalg.norm(out, axis=1)
    turn_back = np.einsum("ij,ij->i", into, out) < 0.0  # a zero-width spike turns 360°
    reflex: FloatArray = ring[
        (cross < -_LEN_TOL * scale)
        | ((cross <= 0.0) & turn_back & (np.abs(cross) <= _LEN_TOL * scale))
    ]
    return reflex


def _cut_to_convex(region: Polygon, choice: dict[tuple[float, float], int]) -> list[Polygon] | None:
    """Cut at reflex vertices until every piece is convex; ``None`` if a cut degenerates."""
    todo, done = [_ccw_ring(region)], list[Polygon]()
    for _ in range(4 * len(todo[0]) + 8):  # each cut removes a reflex vertex
        if not todo:
            return done
        ring = todo.pop()
        reflex = _reflex_vertices(ring)
        if not len(reflex):
            done.append(Polygon(ring))
            continue
        key = (float(reflex[0, 0]), float(reflex[0, 1]))
        pieces = _cut_at(ring, reflex[0], choice.get(key))
        if pieces is None:
            return None
        todo.extend(pieces)
    return None


def _cut_at(ring: FloatArray, vertex: FloatArray, choice: int | None) -> list[FloatArray] | None:
    """Split ``ring`` along the extension of one of ``vertex``'s edges (shorter if ``None``)."""
    i = int(np.flatnonzero(np.all(ring == vertex, axis=1))[0])
    n = len(ring)
    prev, nxt = ring[(i - 1) % n], ring[(i + 1) % n]
    rays = [vertex - prev, vertex - nxt]  # continue the incoming edge / the outgoing one back
    hits = [_first_hit(ring, i, ray) for ray in rays]
    options = [k for k in (0, 1) if hits[k] is not None]
    if choice is None or choice not in options:
        if not options:
            return None
        choice = min(options, key=lambda k: _hit_distance(hits[k]))
    hit = hits[choice]
    assert hit is not None
    return _split_ring(ring, i, hit)


def _hit_distance(hit: tuple[FloatArray, int, float] | None) -> float:
    return math.inf if hit is None else hit[2]


def _first_hit(ring: FloatArray, i: int, ray: FloatArray) -> tuple[FloatArray, int, float] | None:
    """Where the ray from vertex ``i`` first meets the boundary: (point, edge index, distance).

    Edge ``j`` runs from vertex ``j`` to ``j + 1``; a hit at a vertex is
    snapped to it (edge index of the edge that starts there, parameter 0).
    """
    n = len(ring)
    origin = ring[i]
    direction = ray / np.linalg.norm(ray)
    a, b = ring, np.roll(ring, -1, axis=0)
    edge = b - a
    denom = direction[0] * edge[:, 1] - direction[1] * edge[:, 0]
    rel = a - origin
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (rel[:, 0] * edge[:, 1] - rel[:, 1] * edge[:, 0]) / denom
        s = (rel[:, 0] * direction[1] - rel[:, 1] * direction[0]) / denom
    scale = float(np.abs(ring).max()) + 1.0
    tol = _LEN_TOL * scale
    ok = (np.abs(denom) > _LEN_TOL) & (t > tol) & (s >= -_LEN_TOL) & (s <= 1 + _LEN_TOL)
    ok[[i, (i - 1) % n]] = False  # the vertex's own edges
    if not ok.any():
        return None
    j = int(np.argmin(np.where(ok, t, np.inf)))
    point = origin + t[j] * direction
    for k in (j, (j + 1) % n):
        if np.linalg.norm(ring[k] - point) <= tol:
            return ring[k].copy(), k, float(t[j])
    return point, j, float(t[j])


def _split_ring(
    ring: FloatArray, i: int, hit: tuple[FloatArray, int, float]
) -> list[FloatArray] | None:
    """The two rings on either side of the chord from vertex ``i`` to ``hit``.

    ``None`` if a side is degenerate (the chord ran along collinear edges).
    """
    point, j, _ = hit
    n = len(ring)
    on_vertex = bool(np.all(ring[j] == point))
    # Walk i -> ... -> j (and the hit) for one side, hit -> ... -> i for the other.
    first = [ring[(i + k) % n] for k in range((j - i) % n + 1)]
    second = [ring[(j + 1 + k) % n] for k in range((i - j - 1) % n + 1)]
    if on_vertex:
        second.insert(0, point)
    else:
        first.append(point)
        second.insert(0, point)
    pieces = [np.asarray(first), np.asarray(second)]
    area = Polygon(ring).area
    if any(len(p) < 3 or Polygon(p).area <= _AREA_TOL * area for p in pieces):
        return None
    return pieces


def _merge_convex(pieces: list[Polygon]) -> list[Polygon]:
    """Greedily merge pairs sharing an edge while the union stays convex (longest edge first)."""
    parts = list(pieces)
    while True:
        pairs = sorted(
            ((_shared_length(parts[a], parts[b]), a, b) for a, b in _pairs(len(parts))),
            reverse=True,
        )
        for length, a, b in pairs:
            if length <= 0.0:
                return parts
            merged = shapely.union(parts[a], parts[b])
            if isinstance(merged, Polygon) and _is_convex(merged):
                # Round-off at a cut's end can leave a pinhole: drop it.
                merged = Polygon(merged.exterior)
                parts = [p for k, p in enumerate(parts) if k not in (a, b)] + [merged]
                break
        else:
            return parts


def _pairs(n: int) -> list[tuple[int, int]]:
    return list(itertools.combinations(range(n), 2))


def _shared_length(a: Polygon, b: Polygon) -> float:
    """Length of the boundary two parts share (0 if they only touch at points)."""
    return float(sum(line.length for line in _shared_lines(a, b)))


def _shared_lines(a: Polygon, b: Polygon) -> list[LineString]:
    """Pieces of ``a``'s boundary along ``b``'s, within round-off.

    A cut's end point is computed, so it lies on the cut edge only up to
    round-off and an exact boundary intersection may miss the shared edge;
    pieces shorter than ``1e-6`` of the parts' size (where an edge leaves
    ``b`` at a small angle) do not count.
    """
    scale = 1.0 + math.sqrt(max(a.area, b.area))
    tol = _LEN_TOL * scale
    if a.distance(b) > tol:
        return []
    near = shapely.intersection(a.boundary, b.buffer(tol, quad_segs=2))
    pieces = shapely.get_parts(shapely.line_merge(near) if near.geom_type != "Point" else near)
    return [g for g in pieces if g.geom_type == "LineString" and g.length > 1e-6 * scale]


def _decomposition_cost(region: Polygon, parts: list[Polygon], width: float) -> float:
    """Area (m²) no disc of the swath can reach inside its own part, plus a per-part charge."""
    reach = shapely.union_all([_reachable(part, width) for part in parts])
    missed = region.area - region.intersection(reach).area
    return float(missed + _PART_COST * width**2 * len(parts))


def _reachable(part: Polygon, width: float) -> Polygon:
    """What a disc of diameter ``width`` sweeps inside ``part``: its opening, or the spine's."""
    if _is_thin(part, width):
        spine = _spine(part, width)
        line = Point(spine[0]) if len(spine) == 1 else LineString(spine)
        return part.intersection(line.buffer(0.5 * width))
    return part.buffer(-0.5 * width).buffer(0.5 * width)


def _is_thin(part: Polygon, width: float) -> bool:
    inner = part.buffer(-0.5 * width)
    return bool(inner.is_empty or inner.area <= 1e-12 * part.area)


def _spine(part: Polygon, width: float) -> FloatArray:
    """The long axis of a thin part ``(2, 2)`` (``(1, 2)`` if short), ends ``width/2`` in.

    A disc flown along it covers a part narrower than the swath: the chord
    through the centroid parallel to the part's diameter (farthest vertices).
    """
    corners = _ccw_ring(part)
    if len(corners) < 3:  # a degenerate part: a point will do
        return np.asarray(shapely.get_coordinates(part.centroid), dtype=np.float64)
    span = corners[:, None, :] - corners[None, :, :]
    i, j = np.unravel_index(int(np.argmax(np.einsum("ijk,ijk->ij", span, span))), span.shape[:2])
    axis = span[i, j] / float(np.linalg.norm(span[i, j]))  # along the diameter
    centre = np.asarray(part.centroid.coords[0], dtype=np.float64)
    reach = float(np.linalg.norm(span[i, j])) + 1.0
    chord = part.intersection(LineString([centre - reach * axis, centre + reach * axis]))
    ends = np.asarray(shapely.get_coordinates(chord), dtype=np.float64)
    if len(ends) < 2:
        return np.array([centre])
    a, b = ends[0], ends[-1]
    length = float(np.linalg.norm(b - a))
    if length <= width:
        return np.array([0.5 * (a + b)])
    u = (b - a) / length
    return np.array([a + 0.5 * width * u, b - 0.5 * width * u])


# ---------------------------------------------------------------------------
# Order
# ---------------------------------------------------------------------------


def order_parts(parts: Sequence[Polygon], start: int | None = None) -> list[Polygon]:
    """Order convex parts so that consecutive ones share an edge where possible.

    The order minimises the number of adjacency-graph hops between consecutive
    parts (ties: the distance between their centroids), i.e. it is a
    Hamiltonian path of the adjacency graph when one exists. Up to 9 parts the
    search is exact (Held-Karp over subsets); beyond, the best greedy walk
    (nearest unvisited part in hops) over all starts is taken.

    Parameters
    ----------
    parts
        Convex parts (m) of one region, e.g. from :func:`convex_parts`; two
        parts are adjacent when their boundaries share a segment.
    start
        Index into ``parts`` of the part to visit first, or ``None`` to choose
        the start that gives the cheapest order.

    Returns
    -------
    list of shapely.geometry.Polygon
        The same parts, reordered.

    Raises
    ------
    InputError
        If ``parts`` is empty or holds something else than polygons, or
        ``start`` is not a valid index.
    """
    items = list(parts)
    if not items or not all(isinstance(p, Polygon) and not p.is_empty for p in items):
        raise InputError(
            f"parts: got {len(items)} item(s) of types "
            f"{sorted({type(p).__name__ for p in items})}, expected one or more Polygons"
        )
    first = None if start is None else as_int("start", start, low=0, high=len(items) - 1)
    cost = _transit_costs(items)
    sequence = (
        _exact_order(cost, first) if len(items) <= _EXACT_ORDER else _greedy_order(cost, first)
    )
    return [items[k] for k in sequence]


def _adjacency(parts: Sequence[Polygon]) -> list[list[int]]:
    n = len(parts)
    graph: list[list[int]] = [[] for _ in range(n)]
    for a, b in _pairs(n):
        if _shared_length(parts[a], parts[b]) > _LEN_TOL * (1.0 + math.sqrt(parts[a].area)):
            graph[a].append(b)
            graph[b].append(a)
    return graph


def _hops(graph: list[list[int]]) -> FloatArray:
    """All-pairs hop counts of the adjacency graph (inf when disconnected)."""
    n = len(graph)
    hops = np.full((n, n), np.inf)
    for source in range(n):
        hops[source, source] = 0.0
        queue = deque([source])
        while queue:
            node = queue.popleft()
            for other in graph[node]:
                if hops[source, other] == np.inf:
                    hops[source, other] = hops[source, node] + 1.0
                    queue.append(other)
    return hops


def _transit_costs(parts: Sequence[Polygon]) -> FloatArray:
    """Pairwise cost: hops, plus centroid distance as a tie-breaker (< 1 hop in total)."""
    hops = _hops(_adjacency(parts))
    hops[np.isinf(hops)] = len(parts) + 1.0  # touching at a point only: a long transit
    centres = np.array([p.centroid.coords[0] for p in parts], dtype=np.float64)
    dist = np.linalg.norm(centres[:, None, :] - centres[None, :, :], axis=2)
    return np.asarray(hops + dist / (len(parts) * (float(dist.max()) + 1.0)), dtype=np.float64)


def _exact_order(cost: FloatArray, first: int | None) -> list[int]:
    """Cheapest open Hamiltonian path over all parts (Held-Karp), from ``first`` if given."""
    n = len(cost)
    full = (1 << n) - 1
    best: dict[tuple[int, int], tuple[float, int]] = {}
    for k in range(n) if first is None else [first]:
        best[(1 << k, k)] = (0.0, -1)
    for mask in range(1, full + 1):
        for last in range(n):
            entry = best.get((mask, last))
            if entry is None:
                continue
            for nxt in range(n):
                if mask & (1 << nxt):
                    continue
                key = (mask | (1 << nxt), nxt)
                value = entry[0] + float(cost[last, nxt])
                if key not in best or value < best[key][0]:
                    best[key] = (value, last)
    last = min((k for k in range(n) if (full, k) in best), key=lambda k: best[(full, k)][0])
    order, mask = [], full
    while last >= 0:
        order.append(last)
        prev = best[(mask, last)][1]
        mask &= ~(1 << last)
        last = prev
    return order[::-1]


def _greedy_order(cost: FloatArray, first: int | None) -> list[int]:
    """Best nearest-neighbour walk over the allowed starts."""
    n = len(cost)
    walks = []
    for begin in range(n) if first is None else [first]:
        walk, total = [begin], 0.0
        left = set(range(n)) - {begin}
        while left:
            nxt = min(left, key=lambda k: float(cost[walk[-1], k]))
            total += float(cost[walk[-1], nxt])
            walk.append(nxt)
            left.remove(nxt)
        walks.append((total, walk))
    return min(walks)[1]


# ---------------------------------------------------------------------------
# Joined covering paths
# ---------------------------------------------------------------------------


def multi_spiral_control_points(
    region: Polygon,
    width: float,
    *,
    mode: ContourMode = "offset",
    delta: float = 0.5,
) -> FloatArray:
    """The multi-spiral control polygon of a (possibly concave) region (paper Fig. 5).

    Each convex part (:func:`convex_parts`, in :func:`order_parts` order)
    gets its spiral control polygon
    (:func:`~skyquill.coverage.paths.spiral_control_points` of its
    :func:`~skyquill.coverage.paths.contours`), and consecutive polygons are
    joined end to start; :func:`~skyquill.coverage.paths.spiral_curve` of the
    result is one C³ degree-4 B-spline covering the whole region.

    * Every part after the first spirals outside in, starting at the vertex of
      its outer ring nearest to where the previous part ended. The first part
      is flown inside out (its control polygon reversed), so it ends on its
      outer ring next to the second part: with two parts this is the paper's
      "double spiral" without any transit; each further part costs one
      transit from its centre to the next part.
    * Joins: a straight leg if it lies in the region, else legs through
      points on the edges shared along the shortest adjacency path (each leg
      then lies in one convex part). Around each corner of a join four
      collinear control points are packed closer than a quarter of the
      corner's clearance, so the curve stays inside the region there.
    * The corners of each part's first (undrifted) lap are pulled to
      ``width / 4`` from the part's corners (see ``_pulled_corners``): the
      spline cuts corners, and without this an L at ``delta = 1`` is only
      94 % covered (99.7 % with it, for 7 % more length).
    * Parts narrower than ``width`` are flown along their long axis; zero-width
      slivers (inscribed radius below ``1e-3 width``) are not flown.

    Each part is spiralled whole, as the paper's Fig. 5 text describes
    ("generate control points for each of the 2 regions, connect them").
    The alternative "outer laps first" (one lap along the whole region's
    boundary, then the interiors) was not built: the parts' own first laps
    already sweep every part's boundary strip, a region-wide lap would still
    leave the corners where cuts meet the boundary to the parts, and the
    interiors would then need a decomposition of the inset region and a
    second transit into each part -- more length for no coverage to gain
    (per-part spirals already reach 97.8-99.99 % on the test shapes).

    Parameters
    ----------
    region
        Simple polygon without holes (m).
    width
        Coverage diameter (m).
    mode
        Ring construction passed to :func:`~skyquill.coverage.paths.contours`.
    delta
        Corner control-point distance (m) of
        :func:`~skyquill.coverage.paths.spiral_control_points`, > 0.

    Returns
    -------
    ndarray
        Control points ``(P, 2)`` (m).

    Raises
    ------
    InputError
        On a malformed region, ``width``, ``mode`` or ``delta``.
    """
    polygon = _checked_region(region)
    d = as_float("delta", delta, positive=True)
    spirals, routes, parts = _spirals_and_routes(polygon, width, mode=mode, delta=d)
    pieces = [spirals[0]]
    for k, (route, spiral) in enumerate(zip(routes, spirals[1:], strict=True), start=1):
        pieces.append(_packed(route, polygon, parts[k - 1 : k + 1], delta=d))
        pieces.append(spiral)
    return _dedupe(np.vstack(pieces))


def multi_spiral_pieces(
    region: Polygon, width: float, *, mode: ContourMode = "offset", delta: float = 0.5
) -> tuple[list[FloatArray], list[FloatArray]]:
    """The parts' spiral control polygons and the join routes between them, unjoined.

    For flights that stop between parts: each spiral is its own spline, each
    route a polyline flown straight (its corners inside the region). Same
    parts, order and routes as :func:`multi_spiral_control_points`.

    Returns
    -------
    spirals : list of ndarray
        Control polygons ``(P_k, 2)``, one per part, in flight order (m).
    routes : list of ndarray
        Polylines ``(R_k, 2)`` from the end of spiral ``k`` to the start of
        spiral ``k + 1`` (m).
    """
    polygon = _checked_region(region)
    d = as_float("delta", delta, positive=True)
    spirals, routes, _ = _spirals_and_routes(polygon, width, mode=mode, delta=d)
    return spirals, routes


def _spirals_and_routes(
    polygon: Polygon, width: float, *, mode: ContourMode, delta: float
) -> tuple[list[FloatArray], list[FloatArray], list[Polygon]]:
    w = check_width(polygon, width)
    parts = _flown_parts(polygon, w)
    spirals: list[FloatArray] = []
    routes: list[FloatArray] = []
    for k, part in enumerate(parts):
        if k == 0:
            aim = _portal(polygon, parts, 0, 1) if len(parts) > 1 else None
            spirals.append(_part_spiral(part, w, mode=mode, delta=delta, aim=aim)[::-1])
            continue
        spiral = _part_spiral(part, w, mode=mode, delta=delta, aim=spirals[-1][-1])
        routes.append(_join(polygon, parts, k, spirals[-1][-1], spiral[0]))
        spirals.append(spiral)
    return spirals, routes, parts


def _flown_parts(region: Polygon, width: float) -> list[Polygon]:
    """The ordered convex parts, without zero-width slivers (nothing to cover there).

    A part whose inscribed circle is narrower than ``1e-3 * width`` (a spike
    left by near-coincident vertices) holds less than ``1e-3 * width`` times
    its length of area; flying into it would need control points closer
    together than round-off allows, so it is not flown.
    """
    parts = order_parts(convex_parts(region, width))
    radius = [shapely.maximum_inscribed_circle(p).length for p in parts]
    kept = [p for p, r in zip(parts, radius, strict=True) if r >= _SLIVER_WIDTH * width]
    return kept or parts[:1]


def _part_spiral(
    part: Polygon, width: float, *, mode: ContourMode, delta: float, aim: FloatArray | None
) -> FloatArray:
    """One part's spiral control polygon, starting on its outer ring nearest ``aim``."""
    if _is_thin(part, width):
        spine = _spine(part, width)
        return _toward(spine, aim)
    rings = contours(part, width, mode)
    if not rings:
        return _toward(_spine(part, width), aim)
    if aim is not None:
        rings = _realigned(rings, aim)
    return _pulled_corners(spiral_control_points(rings, delta), rings[0], part, width)


def _pulled_corners(
    points: FloatArray, ring: FloatArray, part: Polygon, width: float
) -> FloatArray:
    """Move the outer lap's corners toward the part's corners (control points ``(P, 2)``).

    The outer ring's corner lies ``width / 2`` from both sides, so its disc
    misses the part's corner, and the B-spline cuts the corner further (by
    about ``delta``): an L at ``delta = 1`` loses 5.7 % instead of the 1.4 %
    no disc-swept path inside it can reach. Each corner of the first,
    undrifted lap is moved toward its nearest part vertex until it is at most
    ``0.5 * width / 2`` from it (a point of the convex part, so the curve
    stays inside); the spiral laps, which follow from the unmoved rings, keep
    their spacing.
    """
    corners = _ccw_ring(part)
    same = np.flatnonzero(np.all(points == ring[0], axis=1))
    stop = int(same[1]) if len(same) > 1 else len(points)  # the lap ends back at ring[0]
    out = points.copy()
    for k in range(stop):
        if not np.any(np.all(ring == points[k], axis=1)):
            continue  # an inserted corner point, not a ring vertex
        corner = corners[int(np.argmin(np.linalg.norm(corners - points[k], axis=1)))]
        gap = _dist(points[k], corner)
        if gap > 0.0:
            out[k] = corner + (points[k] - corner) * min(1.0, _CORNER_PULL * 0.5 * width / gap)
    return out


def _toward(line: FloatArray, aim: FloatArray | None) -> FloatArray:
    """``line`` (N, 2) oriented to start at its end nearer ``aim``."""
    if aim is None or len(line) < 2:
        return line
    return line if _dist(line[0], aim) <= _dist(line[-1], aim) else line[::-1]


def _dist(a: FloatArray, b: FloatArray) -> float:
    return float(np.linalg.norm(a - b))


def _realigned(rings: list[FloatArray], aim: FloatArray) -> list[FloatArray]:
    """Roll the outer ring to its vertex nearest ``aim``, each inner one to follow it."""
    out: list[FloatArray] = []
    anchor = aim
    for ring in rings:
        start = int(np.argmin(np.linalg.norm(ring - anchor, axis=1)))
        out.append(np.roll(ring, -start, axis=0))
        anchor = out[-1][0]
    return out


def _portal(region: Polygon, parts: Sequence[Polygon], a: int, b: int) -> FloatArray:
    """A point on the boundary ``parts[a]`` and ``parts[b]`` share, far from the region's.

    Samples the longest shared segment and keeps the sample farthest from the
    region's boundary (the route's corner there then needs little packing).
    """
    lines = _shared_lines(parts[a], parts[b])
    if not lines:  # touching at a point (not adjacent): fall back to the nearest points
        link = shapely.shortest_line(parts[a], parts[b])
        return np.asarray(link.coords[0], dtype=np.float64)
    line = max(lines, key=lambda g: g.length)
    samples = shapely.line_interpolate_point(line, np.linspace(0.1, 0.9, 9), normalized=True)
    clearance = shapely.distance(samples, region.exterior)
    return np.asarray(samples[int(np.argmax(clearance))].coords[0], dtype=np.float64)


def _join(
    region: Polygon, parts: Sequence[Polygon], k: int, begin: FloatArray, end: FloatArray
) -> FloatArray:
    """Route ``(M, 2)`` from ``begin`` (in ``parts[k-1]``) to ``end`` (in ``parts[k]``).

    Straight if that segment lies in the region; else through portals along
    the shortest adjacency path between the two parts (each leg then lies in
    a convex part, hence in the region).
    """
    if _dist(begin, end) <= _LEN_TOL or _inside(region, np.array([begin, end])):
        return np.array([begin, end])
    chain = _shortest_path(_adjacency(parts), k - 1, k)
    via = [_portal(region, parts, a, b) for a, b in itertools.pairwise(chain)]
    return np.array([begin, *via, end])


def _inside(region: Polygon, polyline: FloatArray) -> bool:
    scale = math.sqrt(region.area)
    return bool(region.buffer(_LEN_TOL * scale).covers(LineString(polyline)))


def _shortest_path(graph: list[list[int]], source: int, target: int) -> list[int]:
    """Nodes from ``source`` to ``target`` by breadth-first search (direct if unreachable)."""
    parent = {source: source}
    queue = deque([source])
    while queue and target not in parent:
        node = queue.popleft()
        for other in graph[node]:
            if other not in parent:
                parent[other] = node
                queue.append(other)
    if target not in parent:
        return [source, target]
    path = [target]
    while path[-1] != source:
        path.append(parent[path[-1]])
    return path[::-1]


def _packed(
    route: FloatArray, region: Polygon, ends: Sequence[Polygon], *, delta: float
) -> FloatArray:
    """``route`` with 4 collinear points packed on each side of every corner.

    A corner ``x`` with clearance ``r`` (to its own part's boundary at the two
    ends, to the region's boundary at a portal) gets points at ``s, 2s, 3s,
    4s`` with ``4 s <= r``; every window of five consecutive control points
    that straddles ``x`` then lies in the disc ``(x, r)``, inside the region,
    and so does the B-spline piece it controls (convex hull property).
    """
    clear = [float(ends[0].exterior.distance(Point(route[0])))]
    clear += [float(region.exterior.distance(Point(p))) for p in route[1:-1]]
    clear.append(float(ends[-1].exterior.distance(Point(route[-1]))))
    out = [route[:1]]
    for k, (a, b) in enumerate(itertools.pairwise(route)):
        length = _dist(a, b)
        if length <= _LEN_TOL:
            continue
        u = (b - a) / length
        cap = min(delta, length / (2 * _PACKED + 2))
        sa, sb = min(cap, clear[k] / _PACKED), min(cap, clear[k + 1] / _PACKED)
        steps = np.arange(1, _PACKED + 1, dtype=np.float64)[:, None]
        out += [a + sa * steps * u, b - sb * steps[::-1] * u, b[None, :]]
    return _dedupe(np.vstack(out))


def _dedupe(points: FloatArray) -> FloatArray:
    """Drop consecutive (near-)coincident points ``(N, 2)``."""
    tol = _LEN_TOL * max(1.0, float(np.abs(points).max()))
    keep = np.ones(len(points), dtype=bool)
    keep[1:] = np.linalg.norm(np.diff(points, axis=0), axis=1) > tol
    return points[keep]


def multi_zigzag(region: Polygon, width: float, *, perimeter: bool = False) -> FloatArray:
    """Boustrophedon waypoints for a (possibly concave) region, part by part.

    Each convex part (:func:`convex_parts`, :func:`order_parts` order) gets
    :func:`~skyquill.coverage.paths.zigzag` with sweep lines parallel to the
    part's edge of least perpendicular extent (fewest sweep lines, hence
    fewest turns; ties go to the longer edge). Of the four ways to fly it
    (the two sweep directions, forwards or backwards) the one starting
    nearest the previous part's end is used (for the first part: the one
    ending nearest the second part). Joins are straight when inside the
    region, else routed through the edges shared along the adjacency graph.
    Parts narrower than ``width`` are flown along their long axis.

    Parameters
    ----------
    region
        Simple polygon without holes (m).
    width
        Coverage diameter (m).
    perimeter
        Passed to :func:`~skyquill.coverage.paths.zigzag`: one lap around
        each part before its sweep lines. The lap then also gets an
        out-and-back spike into every part corner sharper than about 84°
        (``_corner_spikes``), whose tip the lap's disc would otherwise miss.

    Returns
    -------
    ndarray
        Waypoints ``(K, 2)`` (m).

    Raises
    ------
    InputError
        On a malformed region or ``width``.
    """
    polygon = _checked_region(region)
    w = check_width(polygon, width)
    parts = _flown_parts(polygon, w)
    pieces: list[FloatArray] = []
    for k, part in enumerate(parts):
        options = _zigzag_options(part, w, perimeter=perimeter)
        if k == 0:
            aim = _portal(polygon, parts, 0, 1) if len(parts) > 1 else options[0][-1]
            pieces.append(min(options, key=lambda path: _dist(path[-1], aim)))
            continue
        begin = pieces[-1][-1]
        path = min(options, key=lambda p: _dist(p[0], begin))
        pieces.append(_join(polygon, parts, k, begin, path[0]))
        pieces.append(path)
    return _dedupe(np.vstack(pieces))


def _zigzag_options(part: Polygon, width: float, *, perimeter: bool) -> list[FloatArray]:
    """The ways to fly one part: both sweep directions, forwards and backwards."""
    if _is_thin(part, width):
        spine = _spine(part, width)
        return [spine, spine[::-1]]
    theta = _sweep_angle(part)
    paths = [zigzag(part, width, angle, perimeter=perimeter) for angle in (theta, theta + np.pi)]
    if perimeter:
        paths = [_corner_spikes(path, part, width) for path in paths]
    return [p for path in paths for p in (path, path[::-1])]


def _corner_spikes(path: FloatArray, part: Polygon, width: float) -> FloatArray:
    """Waypoints ``(K, 2)`` with an out-and-back spike from each lap corner to its corner.

    The perimeter lap's corners lie ``width / 2`` from both sides, so at an
    acute corner the disc stops far short of it (a 36° star tip: 3.2 m); a
    spike to ``width / 2`` from the corner lets the disc reach it. The spike
    lies on the segment to the part's vertex, inside the convex part.
    """
    shrunk = part.buffer(-0.5 * width, join_style="mitre")
    if not isinstance(shrunk, Polygon) or shrunk.is_empty:
        return path  # round-off split a near-degenerate part: no lap corners to find
    lap = _ccw_ring(shrunk)
    corners = _ccw_ring(part)
    tol = 1e-6 * (1.0 + math.sqrt(part.area))
    rows: list[FloatArray] = []
    for point in path:
        rows.append(point[None, :])
        if np.min(np.linalg.norm(lap - point, axis=1)) > tol:
            continue
        corner = corners[int(np.argmin(np.linalg.norm(corners - point, axis=1)))]
        gap = _dist(point, corner)
        if gap > _SPIKE_GAP * 0.5 * width:  # sharper than ~84°: a 90° corner only loses 0.2 m²
            tip = corner + (point - corner) * (0.5 * width / gap)
            rows.append(np.array([tip, point]))
    return np.vstack(rows)


def _sweep_angle(part: Polygon) -> float:
    """Direction (rad) of the edge across which the convex part is narrowest."""
    ring = _ccw_ring(part)
    edges = np.roll(ring, -1, axis=0) - ring
    lengths = np.linalg.norm(edges, axis=1)
    units = edges / lengths[:, None]
    normal = np.stack([-units[:, 1], units[:, 0]], axis=1)
    extent = np.ptp(ring @ normal.T, axis=0)
    # Narrowest first; among (nearly) equal widths the longest edge.
    best = min(
        range(len(ring)), key=lambda j: (round(extent[j] / (1e-6 + extent.max()), 6), -lengths[j])
    )
    return float(np.arctan2(edges[best, 1], edges[best, 0]))
