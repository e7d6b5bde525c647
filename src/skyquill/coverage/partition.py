"""Concave regions, step 1: a few fat convex parts whose union is the region.

Paper 001 §1 (end): a region whose centre is not inside it cannot be covered
by one spiral; it is split into convex parts (:func:`convex_parts`), which
:mod:`skyquill.coverage.part_order` orders and :mod:`skyquill.coverage.joined`
joins into one covering path.  Candidates are Hertel-Mehlhorn's and the cuts
at the reflex vertices; the cheapest (fewest, fattest parts) wins.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import shapely
from shapely.geometry import LineString, Point, Polygon
from shapely.geometry.polygon import orient

from skyquill.coverage.regions import MAX_MISSION_PATH_M, check_width, vertex_turns
from skyquill.errors import InputError
from skyquill.validation import FloatArray

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
#: Weight (in swath areas ``width**2``) of one extra part in the decomposition cost.
_PART_COST = 0.5


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
    # (Its parts' paths are capped when they are planned: a part too long is cut into cells.)
    w = check_width(polygon, width, max_path_m=MAX_MISSION_PATH_M)
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
    cross, dot, scale = vertex_turns(ring)
    turn_back = dot < 0.0  # a zero-width spike turns 360°
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
