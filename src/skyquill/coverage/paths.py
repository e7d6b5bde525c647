"""Covering paths for a region: the paper's spiral spline and a boustrophedon.

Implements §1 of the coverage-path paper (``001_61beb0e01a19013a``, Chen, Dong,
Sheng, Zhu, "Regional trajectory planning of UAVs based on spiral spline"):

* :func:`contours` -- nested closed rings, outside in (eq. 1-3, or true
  inward offsets);
* :func:`spiral_control_points` -- the spiral control polygon (eq. 4-5) with
  the corner control points governed by ``delta`` (Fig. 2);
* :func:`spiral_curve` -- the degree-4 B-spline (NURBS with unit weights,
  eq. 10) on ``u in [0, 1]`` with Hartley-Judd knots;
* :func:`zigzag` -- the boustrophedon ("Z-shaped") waypoints the paper
  compares against (§4).

Only convex regions are handled: the paper splits concave regions into convex
parts first (Fig. 5); that decomposition is a later step.
"""

from __future__ import annotations

import itertools
import math
from typing import Literal

import numpy as np
import shapely
from numpy.typing import NDArray
from scipy.interpolate import BSpline
from shapely import affinity
from shapely.geometry import LineString, MultiPolygon, Polygon
from shapely.geometry.base import BaseGeometry
from shapely.geometry.polygon import orient

from skyquill.coverage.regions import check_width, vertex_turns
from skyquill.errors import InputError
from skyquill.validation import as_array, as_float, as_int

FloatArray = NDArray[np.float64]
ContourMode = Literal["offset", "homothetic"]
DriftMode = Literal["lap", "step"]

#: Relative tolerance (of the region's size) for coincident points.
_REL_TOL = 1e-12


def contours(
    region: Polygon,
    width: float,
    mode: ContourMode = "offset",
    *,
    epsilon: float = 1.0,
    sigma: float | None = None,
) -> list[FloatArray]:
    """Nested closed rings covering ``region``, from the outside in.

    Parameters
    ----------
    region
        A convex region (shapely ``Polygon``, metres).
    width
        Coverage diameter ``2R`` (m).
    mode
        ``"offset"``: true inward offsets at ``(i + 0.5) * width``, so every
        ring is ``width`` from the next on every side. ``"homothetic"``: the
        paper's rings, shrunk toward the vertex centroid (eq. 1-3).
    epsilon
        The paper's density factor ``ε in (0, 1]``: the ring spacing is
        ``ε width`` (offset rings: the first at ``ε width / 2`` inside).
    sigma
        The paper's offset σ of the first homothetic ring (m), measured at the
        vertex farthest from the centre (the ring is a homothety, so nearer
        vertices move less); defaults to ``width / 2``.

    Returns
    -------
    list of ndarray
        Rings ``(K, 2)`` without the repeated closing vertex, counter-clockwise,
        each starting at its vertex nearest to the previous ring's start.
    """
    eps = as_float("epsilon", epsilon, positive=True)
    if eps > 1.0:
        raise InputError(f"epsilon: got {eps:g}, expected a value in (0, 1]")
    w = check_width(region, width, eps)
    if mode == "offset":
        rings = _offset_rings(region, eps * w)
    elif mode == "homothetic":
        s = 0.5 * w if sigma is None else as_float("sigma", sigma, nonneg=True)
        rings = _homothetic_rings(region, w, eps, s)
    else:
        raise InputError(f"mode: got {mode!r}, expected 'offset' or 'homothetic'")
    return _aligned(rings)


def _homothetic_rings(region: Polygon, width: float, eps: float, sigma: float) -> list[FloatArray]:
    """Eq. 1-3: ``m`` rings shrunk linearly toward the vertex centroid ``o``.

    The layer count uses the farthest vertex, ``m = ceil(|q_t - o| / (2 R ε))``,
    but every ring is the same homothety of the first one, so the spacing is
    only ``2Rε`` along the farthest direction and much less across the short
    side of an elongated region: a 30 m x 12 m rectangle at 2 m gets 9 rings
    0.6 m apart across its width where 3 offset rings suffice (over-coverage).
    """
    q0 = _vertices(region)
    o = q0.mean(axis=0)  # the paper's centre: the mean of the contour points
    r_max = float(np.max(np.linalg.norm(q0 - o, axis=1)))
    m = math.ceil(r_max / (width * eps))  # eq. 1
    if sigma >= r_max:
        raise InputError(f"sigma: got {sigma:g} m, expected less than {r_max:.3g} m")
    # First layer: the contour moved toward o by sigma at its farthest point.
    q1 = o + (1.0 - sigma / r_max) * (q0 - o)
    return [q1 + i * (o - q1) / m for i in range(m)]  # eq. 3, i = 0 .. m-1


def _offset_rings(region: Polygon, width: float) -> list[FloatArray]:
    """Inward offsets ``buffer(-(i + 0.5) * width)`` until the result is empty."""
    rings: list[FloatArray] = []
    for i in range(10**6):
        inner = region.buffer(-(i + 0.5) * width)
        if inner.is_empty or inner.area <= _REL_TOL * region.area:
            break
        if isinstance(inner, MultiPolygon):
            # A concave region splits into parts; only the largest is kept
            # here -- covering the others needs decomposition (a later step).
            inner = max(inner.geoms, key=lambda g: g.area)
        assert isinstance(inner, Polygon)
        rings.append(_vertices(inner))
    return rings


def _vertices(polygon: Polygon) -> FloatArray:
    """Counter-clockwise exterior vertices ``(K, 2)`` without the closing repeat, nor those
    where the ring goes on straight (:func:`_without_straight`)."""
    ccw = orient(polygon, sign=1.0)
    pts = np.asarray(ccw.exterior.coords, dtype=np.float64)[:-1, :2]
    return _without_straight(_dedupe(pts, closed=True))


#: A ring's vertex where it turns by less than this, rad, is no corner (over a 100 m edge
#: the ring moves by 1 mm at most without it).
STRAIGHT_TURN_RAD = 1e-5


def _without_straight(ring: FloatArray) -> FloatArray:
    """The closed ``ring`` (K, 2) without the vertices where it turns by less than
    :data:`STRAIGHT_TURN_RAD` (going on forward).

    A region's edge bent by 1e-7 rad at a vertex (random convex regions with vertices
    a micrometre or less off a straight line: hypothesis) kept that vertex in every inset
    ring, and the spiral through them could not be timed on any grid (2.4 % over the
    limits, or stopping the vehicle mid-path); without it, it flies.
    """
    if len(ring) <= 3:
        return ring
    cross, dot, scale = vertex_turns(ring)
    straight = (dot > 0.0) & (np.abs(cross) <= STRAIGHT_TURN_RAD * scale)
    kept = ring[~straight]
    return kept if len(kept) >= 3 else ring


def _dedupe(pts: FloatArray, *, closed: bool = False) -> FloatArray:
    """Drop consecutive (near-)coincident points."""
    if len(pts) < 2:
        return pts
    tol = _REL_TOL * max(1.0, float(np.abs(pts).max()))
    keep = np.ones(len(pts), dtype=bool)
    keep[1:] = np.linalg.norm(np.diff(pts, axis=0), axis=1) > tol
    out = pts[keep]
    if closed and len(out) > 1 and np.linalg.norm(out[-1] - out[0]) <= tol:
        out = out[:-1]
    return out


def merge_close(points: FloatArray, tol: float) -> FloatArray:
    """``points`` (K, 2) without the points closer than ``tol`` (m) to their predecessor.

    A leg of nanometres (a perimeter lap starting at the sweep line nudged
    1e-9 m inside the region's corner) makes the spline's parametric speed
    vary by 1e5-1e8 along the path; the speed LP's columns ``b ~ 1 / |C'|^2``
    then span ten and more orders of magnitude, HiGHS's hot starts stall and
    the cold ``linprog`` solves that replace them ran for minutes.
    """
    if len(points) < 2:
        return points
    keep = np.ones(len(points), dtype=bool)
    keep[1:] = np.linalg.norm(np.diff(points, axis=0), axis=1) > tol
    return points[keep]


def _aligned(rings: list[FloatArray]) -> list[FloatArray]:
    """Roll each ring to start at its vertex nearest the previous ring's start."""
    out: list[FloatArray] = []
    for ring in rings:
        start = int(np.argmin(np.linalg.norm(ring - out[-1][0], axis=1))) if out else 0
        out.append(np.roll(ring, -start, axis=0))
    return out


def spiral_control_points(
    rings: list[FloatArray], delta: float, *, drift: DriftMode = "lap"
) -> FloatArray:
    """The spiral control polygon of eq. 4-5 with corner points at ``delta``.

    Eq. 4 moves vertex ``j`` (``j = 0 .. n-1``) of ring ``i`` toward its
    counterpart on ring ``i+1`` by the fraction ``j / n``, so one lap drifts
    one ring inward and the laps chain into a spiral (eq. 5, outside in).
    Choices where the paper is silent or ambiguous:

    * Counterpart: vertex ``j`` of ring ``i+1`` when both rings have the same
      vertex count (the paper's homothetic rings, offsets of most convex
      polygons), else the nearest point of ring ``i+1``. The innermost ring
      drifts toward the nearest point of its *core* (itself shrunk by 99 % of
      its inradius: a point for a square, the spine of a long thin ring) and
      the path ends at the core's centroid. Eq. 3 with ``i = m`` would send it
      to the centre ``o``, which cuts the ends of an elongated last ring (a
      30 m x 12 m rectangle: 96 % instead of 99 % coverage).
    * The path first goes once around the outer ring undrifted, then spirals:
      with eq. 4 alone lap 1 sweeps side ``s`` at ``s / n`` of a ring spacing
      inside the outer ring, leaving a boundary strip up to a swath wide
      uncovered (a 10 m square at 2 m: 79 % instead of 99 % coverage).
    * Fig. 2 (not legible in the text): "between every two adjacent points of
      D" two control points are inserted, at ``delta`` from each end of the
      leg (at most half the leg); ``D``'s points are kept. Smaller ``delta``
      gives sharper corners (higher curvature, less corner cutting).

    Parameters
    ----------
    rings
        Closed rings ``(K, 2)`` outside in, counter-clockwise with aligned
        starts, as returned by :func:`contours`.
    delta
        Distance (m) of the corner control points from each corner, > 0.
    drift
        ``"lap"``: the paper's eq. 4, each lap drifting one ring inward all
        along. ``"step"``: every ring is flown whole and the path steps to
        the next ring on the last side (:func:`_stepped`) -- no undrifted
        extra lap, so a shorter path with the same spacing.

    Returns
    -------
    ndarray
        Control points ``(P, 2)``.
    """
    d = as_float("delta", delta, positive=True)
    checked = [_checked_ring(f"rings[{i}]", r) for i, r in enumerate(rings)]
    if not checked:
        raise InputError("rings: got an empty list, expected at least one ring")
    core = _core(checked[-1])
    if drift == "step":
        polygon = _stepped(checked, core)
    elif drift == "lap":
        laps = [_drifted(ring, _counterparts(checked, i, core)) for i, ring in enumerate(checked)]
        centre = np.asarray(core.centroid.coords, dtype=np.float64)
        polygon = np.vstack([checked[0], *laps, centre])
    else:
        raise InputError(f"drift: got {drift!r}, expected 'lap' or 'step'")
    return with_corner_points(_dedupe(polygon), d)


def _stepped(rings: list[FloatArray], core: BaseGeometry) -> FloatArray:
    """Whole rings joined by a step on each ring's last side, then the core's spine.

    Ring ``i`` is flown from its start round to its last vertex and back
    down its last side to half a ring spacing short of the start (nearer
    would only re-cover the first side; farther leaves a gap between the
    start's and the last side's swaths), then across to ring ``i+1``'s
    start. After the innermost ring the path steps onto the core's spine and
    runs along it: the innermost ring's inradius is below one spacing (else
    another ring would fit), so every point it encloses lies within half a
    spacing of the ring or of the spine.
    """
    spine = _spine(core, rings[-1][0])
    pieces: list[FloatArray] = []
    for i, ring in enumerate(rings):
        target = rings[i + 1][0] if i + 1 < len(rings) else spine[0]
        pieces.append(np.vstack([ring, _step_point(ring[-1], ring[0], target)]))
    pieces.append(spine)
    return np.vstack(pieces)


def _step_point(last: FloatArray, start: FloatArray, target: FloatArray) -> FloatArray:
    """Where the last side ``last -> start`` leaves for ``target``: half a spacing before ``start``.

    The spacing is ``target``'s distance from the side's line.
    """
    side = start - last
    length = float(np.linalg.norm(side))
    if length <= 0.0:
        return start
    unit = side / length
    rel = target - start
    spacing = abs(float(unit[0] * rel[1] - unit[1] * rel[0]))
    back = min(0.5 * spacing, 0.5 * length)
    return np.asarray(start - back * unit, dtype=np.float64)


def _spine(core: BaseGeometry, near: FloatArray) -> FloatArray:
    """The core's longest chord ``(2, 2)`` (one point twice if it is a point), near end first."""
    pts = shapely.get_coordinates(core)
    gaps = np.linalg.norm(pts[:, None, :] - pts[None, :, :], axis=2)
    i, j = np.unravel_index(int(np.argmax(gaps)), gaps.shape)
    ends = pts[[i, j]]
    if np.linalg.norm(ends[1] - near) < np.linalg.norm(ends[0] - near):
        ends = ends[::-1]
    return np.asarray(ends, dtype=np.float64)


def _checked_ring(name: str, ring: object) -> FloatArray:
    pts = _dedupe(as_array(name, ring, ndim=2), closed=True)
    if pts.shape[1] != 2 or pts.shape[0] < 3:
        raise InputError(f"{name}: got shape {pts.shape}, expected (K >= 3, 2) ring vertices")
    return pts


def _core(ring: FloatArray) -> BaseGeometry:
    """The ring's polygon shrunk by 99 % of its inradius (its centre if that fails)."""
    polygon = Polygon(ring)
    radius = shapely.maximum_inscribed_circle(polygon)
    core = polygon.buffer(-0.99 * radius.length)
    return shapely.Point(radius.coords[0]) if core.is_empty else core


def _counterparts(rings: list[FloatArray], i: int, core: BaseGeometry) -> FloatArray:
    """Where each vertex of ring ``i`` heads: its counterpart on ring ``i+1``."""
    ring = rings[i]
    if i + 1 == len(rings):
        links = shapely.shortest_line(shapely.points(ring), core)
        return np.asarray(shapely.get_coordinates(links)[1::2], dtype=np.float64)
    nxt = rings[i + 1]
    if len(nxt) == len(ring):
        return nxt
    line = LineString(np.vstack([nxt, nxt[:1]]))
    at = shapely.line_locate_point(line, shapely.points(ring))
    return np.asarray(shapely.get_coordinates(shapely.line_interpolate_point(line, at)))


def _drifted(ring: FloatArray, target: FloatArray) -> FloatArray:
    """Eq. 4: ``d_j = q_j + (j / n) (q'_j - q_j)``, ``j = 0 .. n-1``."""
    n = len(ring)
    frac = np.arange(n, dtype=np.float64)[:, None] / n
    return ring + frac * (target - ring)


#: Turns sharper than this (rad) are reversals: the spline would stop in a cusp there.
REVERSAL_RAD = np.radians(170.0)


def with_corner_points(polygon: FloatArray, delta: float) -> FloatArray:
    """Insert points at ``min(delta, leg / 2)`` from both ends of every leg.

    A reversal (the path doubling back, e.g. into a spike or along a spine)
    is first opened into a U-turn ``delta / 2`` wide (:func:`_opened_reversals`):
    through a reversal the spline has a cusp, where the speed must vanish.
    """
    polygon = _opened_reversals(_dedupe(polygon), 0.25 * delta)
    out = [polygon[:1]]
    for a, b in itertools.pairwise(polygon):
        leg = b - a
        length = float(np.linalg.norm(leg))
        step = min(delta, 0.5 * length) / length
        out.append(np.array([a + step * leg, b - step * leg, b]))
    return _dedupe(np.vstack(out))


def _opened_reversals(polygon: FloatArray, half_width: float) -> FloatArray:
    """Each vertex where the path turns back by more than 170 deg becomes a U-turn.

    The tip ``b`` is replaced by ``b - h e + h n`` and ``b - h e - h n`` (``e``
    the incoming direction, ``n`` its normal toward the outgoing leg's side,
    ``h`` the half width): both stay ``h`` short of the tip, so the turn stays
    inside a region whose spike is at least ``2 h`` wide there.
    """
    if len(polygon) < 3:
        return polygon
    legs = np.diff(polygon, axis=0)
    unit = legs / np.linalg.norm(legs, axis=1)[:, None]
    out = [polygon[:1]]
    for k in range(1, len(polygon) - 1):
        e_in, e_out, tip = unit[k - 1], unit[k], polygon[k]
        if float(np.dot(e_in, e_out)) > np.cos(REVERSAL_RAD):
            out.append(tip[None, :])
            continue
        normal = np.array([-e_in[1], e_in[0]])
        if float(np.dot(normal, e_out)) < 0.0:
            normal = -normal
        back = tip - half_width * e_in
        out.append(np.array([back - half_width * normal, back + half_width * normal]))
    out.append(polygon[-1:])
    return np.vstack(out)


def hartley_judd_knots(control_points: FloatArray, degree: int) -> FloatArray:
    """Clamped knot vector on ``[0, 1]`` by the Hartley-Judd method.

    With control points ``d_0 .. d_n``, legs ``l_j = |d_j - d_{j-1}|`` and
    degree ``k``, the interior knots are (Hartley & Judd, "Parametrization and
    shape of B-spline curves for CAD", Computer-Aided Design 12(5), 1980,
    235-238; as given in Shi Fazhong, *CAGD & NURBS*, 2001, §9)::

        u_0 = ... = u_k = 0,   u_{n+1} = ... = u_{n+k+1} = 1,
        u_i - u_{i-1} = S_i / sum_{s=k+1}^{n+1} S_s,   S_i = sum_{j=i-k}^{i-1} l_j,
        i = k+1 .. n+1,

    i.e. each knot span is proportional to the length of the ``k`` legs of the
    control polygon it depends on.

    Parameters
    ----------
    control_points
        ``(n + 1, dim)`` with ``n + 1 > degree`` and a positive polygon length.
    degree
        Spline degree ``k >= 1``.

    Returns
    -------
    ndarray
        ``n + k + 2`` non-decreasing knots, clamped at 0 and 1.
    """
    k = as_int("degree", degree, low=1)
    pts = as_array("control_points", control_points, ndim=2)
    n = len(pts) - 1
    if n < k:
        raise InputError(f"control_points: got {n + 1} points, expected at least {k + 1}")
    legs = np.linalg.norm(np.diff(pts, axis=0), axis=1)  # l_1 .. l_n
    spans = np.array([legs[i - k - 1 : i - 1].sum() for i in range(k + 1, n + 2)])
    total = float(spans.sum())
    if not total > 0.0:
        raise InputError("control_points: got a polygon of zero length, expected distinct points")
    interior = np.cumsum(spans)[:-1] / total
    return np.concatenate([np.zeros(k + 1), interior, np.ones(k + 1)])


def spiral_curve(control_points: FloatArray, degree: int = 4) -> BSpline:
    """The clamped B-spline (eq. 10: NURBS with unit weights) on ``u in [0, 1]``.

    Parameters
    ----------
    control_points
        ``(P, 2)``, e.g. from :func:`spiral_control_points`; consecutive
        duplicates are dropped.
    degree
        Spline degree; the paper uses 4 so that jerk is differentiable.

    Returns
    -------
    scipy.interpolate.BSpline
        ``C(u)`` with Hartley-Judd knots (:func:`hartley_judd_knots`); it lies
        in the convex hull of its control points and starts/ends at the first
        and last of them.
    """
    pts = _dedupe(as_array("control_points", control_points, ndim=2))
    knots = hartley_judd_knots(pts, degree)
    return BSpline(knots, pts, degree, extrapolate=False)


def zigzag(
    region: Polygon, width: float, angle: float | None = None, *, perimeter: bool = False
) -> FloatArray:
    """Boustrophedon waypoints for a convex region.

    Sweep lines run at ``angle`` (rad; parallel to the longest edge if
    ``None``), are clipped to the region shrunk by ``width / 2`` and are
    joined end to end in alternating directions. They span the shrunk region
    from side to side, ``width`` apart (evenly closer if its extent is not a
    multiple of ``width``); the first lies ``width / 2`` inside an edge
    parallel to the sweep.

    Parameters
    ----------
    region
        Convex region (m).
    width
        Coverage diameter (m).
    angle
        Sweep direction (rad) in the region's frame, or ``None``.
    perimeter
        Start with one lap around the shrunk region. The bare boustrophedon
        leaves slivers along slanted sides between the ends of consecutive
        sweep lines (a turn joins them on one side only); the lap sweeps them.

    Returns
    -------
    ndarray
        Waypoints ``(K, 2)``.

    Raises
    ------
    InputError
        If the region is concave (a sweep line may meet it in several
        pieces): concave regions need decomposition (a later step).
    """
    w = check_width(region, width)
    if region.convex_hull.area - region.area > 1e-9 * region.area:
        # Turns between sweep lines could leave a concave region even when
        # no sweep line splits; refuse it up front with the same message.
        raise _concave_error()
    theta = _longest_edge_angle(region) if angle is None else as_float("angle", angle)
    origin = region.centroid
    flat = affinity.rotate(region, -theta, origin=origin, use_radians=True)
    shrunk = flat.buffer(-0.5 * w)
    if not isinstance(shrunk, Polygon):
        raise _concave_error()
    rows = [_sweep_segment(shrunk, y) for y in _sweep_levels(shrunk, w)]
    for k in range(1, len(rows), 2):
        rows[k] = rows[k][::-1]
    if perimeter:
        rows.insert(0, _lap(shrunk, rows[0][0]))
    path = LineString(_dedupe(np.vstack(rows))) if len(rows) > 1 else LineString(rows[0])
    back = affinity.rotate(path, theta, origin=origin, use_radians=True)
    return np.asarray(back.coords, dtype=np.float64)


def _lap(shrunk: Polygon, start: FloatArray) -> FloatArray:
    """One lap of ``shrunk``'s boundary from the boundary point ``start`` back to it."""
    ring = LineString(shrunk.exterior.coords)
    vertices = np.asarray(ring.coords, dtype=np.float64)[:-1]
    along = shapely.line_locate_point(ring, shapely.points(vertices))
    ahead = np.mod(along - ring.project(shapely.Point(start)), ring.length)
    return np.vstack([start, vertices[np.argsort(ahead)], start])


def _longest_edge_angle(region: Polygon) -> float:
    pts = np.asarray(region.exterior.coords, dtype=np.float64)
    legs = np.diff(pts, axis=0)
    dx, dy = legs[int(np.argmax(np.hypot(legs[:, 0], legs[:, 1])))]
    return float(np.arctan2(dy, dx))


def _sweep_levels(shrunk: Polygon, width: float) -> FloatArray:
    """``y`` of the sweep lines: both extremes of ``shrunk``, spacing <= width."""
    _, lo, _, hi = shrunk.bounds
    nudge = 1e-9 * max(1.0, hi - lo)  # stay strictly inside at the extremes
    count = math.ceil((hi - lo) / width - 1e-9) + 1
    if count == 1 or hi - lo <= 2 * nudge:
        return np.array([0.5 * (lo + hi)])
    return np.linspace(lo + nudge, hi - nudge, count)


def _sweep_segment(shrunk: Polygon, y: float) -> FloatArray:
    """The piece of the line at height ``y`` inside ``shrunk``, left to right."""
    minx, _, maxx, _ = shrunk.bounds
    cut = shrunk.intersection(LineString([(minx - 1.0, y), (maxx + 1.0, y)]))
    pieces = [g for g in getattr(cut, "geoms", [cut]) if isinstance(g, LineString)]
    pieces = [g for g in pieces if not g.is_empty]
    if len(pieces) != 1:
        if not pieces:
            xy = shapely.get_coordinates(cut)
            if len(xy):
                return np.asarray(xy[:1], dtype=np.float64)
        raise _concave_error()
    xy = np.asarray(pieces[0].coords, dtype=np.float64)
    ends = xy[np.argsort(xy[:, 0])][[0, -1]]
    # A row that only touches a vertex is one point (two would make a cusp).
    return ends[:1] if ends[1, 0] - ends[0, 0] <= 1e-6 * max(1.0, maxx - minx) else ends


def _concave_error() -> InputError:
    return InputError(
        "region: got a concave region (a sweep line can meet it in several pieces); "
        "concave regions need decomposition into convex parts (a later step), "
        "expected a convex region"
    )
