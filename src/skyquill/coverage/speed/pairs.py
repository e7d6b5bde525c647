"""The linearised jerk-limited grid problem by TOPP-RA lifted to pairs ``(b_i, b_{i+1})``.

Once the pseudo-jerk iteration has linearised the jerk rows (:mod:`.iteration`), every row
of the grid problem is linear and couples at most three consecutive nodes:

* the acceleration rows of interval ``i``: ``|alpha x + beta y| <= r`` in
  ``(x, y) = (b_i, b_{i+1})``;
* the jerk rows of node ``i``: ``|p b_{i-1} + c b_i + s b_{i+1}| <= L``;
* the column bounds ``0 <= b <= ub``.

The *controllable set* ``K_i`` is the set of pairs ``(b_i, b_{i+1})`` from which the rest of
the path can still be followed. It is a convex polygon (the projection of a polyhedron) and
is computed backward: ``K_{n-2}`` is the box of the last interval clipped by its
acceleration rows; ``K_i`` is the box of interval ``i`` clipped by its acceleration rows and
by the Fourier-Motzkin elimination of ``b_{i+2}`` from "``(b_{i+1}, b_{i+2})`` in
``K_{i+1}`` and the jerk rows of node ``i + 1``". A forward pass then takes, node by node,
the largest ``b_{i+1}`` with ``(b_i, b_{i+1})`` in ``K_i`` inside the jerk rows of node
``i``: it never gets stuck, because ``(b_{i-1}, b_i)`` in ``K_{i-1}`` says such a
``b_{i+1}`` exists.

Two things keep the cost linear in ``n`` with a small constant:

* **A cap on the vertices.** Each ``K_i`` keeps at most ``cap`` vertices: while it has
  more, the vertex whose removal loses the least area goes. The convex hull of a subset of
  the vertices lies inside the polygon, so this is an *inner* approximation: every pair
  kept is still controllable, and ``K_{i-1}`` is then computed from the smaller ``K_i``
  (the forward pass stays consistent). ``b = 0`` is feasible for every row (they are
  homogeneous, their bounds ``>= 0``), so ``(0, 0)`` is a vertex of every ``K_i``; it is
  never removed, and every right-hand side is clamped at ``>= 0`` so that round-off cannot
  cut it off either: the forward pass always has somewhere to go.
* **Few clips.** The Fourier-Motzkin pairs of two edges of ``K_{i+1}`` are replaced by
  what they say, ``b_{i+1} <= max`` over ``K_{i+1}`` (the polygon's projection); a
  half-plane that holds on the current polygon's bounding box is skipped before it is
  clipped by.

Greedy is not optimal for ``sum(b)`` (the feasible set has no greatest element once rows
couple three nodes, see ``docs/coverage-speed.md``), and the cap shrinks the polygons: the
answer is feasible but a little below the LP's optimum. :func:`certify` then scales it by
the largest row excess (round-off, the rows being homogeneous in ``b``) so that every row
holds exactly.

The kernels are compiled by numba (``cache=True``: once per machine; a read-only install
falls back to numba's user cache directory).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar, cast

import numba
import numpy as np

from skyquill.validation import FloatArray

#: Vertices each controllable polygon keeps at most (an inner approximation past that).
VERTEX_CAP = 48
#: A vertex whose corner holds less than ``AREA_RTOL / (n - 1)`` of the polygon's area is
#: dropped. Measured on the spiral, wiggle and zigzag at 2,000 points: 0.1 planned within
#: 0.02-0.54 % of the LP, 0.3 within 0.05-0.75 %; relative to the bounding box instead (the
#: polygons are slivers along the diagonal, thinner as the grid is refined) 1e-5 planned
#: +5.5 % on the zigzag (16-gon) at 2,000 points and +9.3 % on the wiggle at 8,000.
AREA_RTOL = 0.1
#: Room for the vertices of a polygon while it is being clipped (the cap applies after).
_BUFFER = 256
#: Relative slack of "inside a half-plane" (round-off of the clipping).
_INSIDE_RTOL = 1e-12
#: Relative distance under which two consecutive vertices are one.
_SAME_RTOL = 1e-13
#: An edge narrower than this in ``x`` (relative) is vertical but for round-off.
_STEEP_RTOL = 1e-9

_F = TypeVar("_F", bound=Callable[..., Any])
#: ``alpha, beta, r`` of the acceleration rows, shape (n - 1, m) (or one interval's, (m,)).
AccRows = tuple[FloatArray, FloatArray, FloatArray]
#: ``p, c, s, L`` of the linearised jerk rows, shape (n - 2, q) (or one node's, (q,)).
JerkRows = tuple[FloatArray, FloatArray, FloatArray, FloatArray]
#: A polygon being cut: vertex ``x``, ``y`` (buffers) and its bounding box.
_Polygon = tuple[FloatArray, FloatArray, FloatArray]
#: Buffers of a cut: vertex ``x``, ``y`` and each vertex's excess over the half-plane.
_Scratch = tuple[FloatArray, FloatArray, FloatArray]


def _compiled(fn: _F) -> _F:
    """``numba.njit(cache=True)`` with the function's own type for mypy.

    The machine code is cached beside this file, or in the user's cache directory when the
    install is read-only; where neither can be written numba refuses ``cache=True`` (a
    ``RuntimeError`` at import), and the kernels are then compiled in every process.
    """
    try:
        return cast(_F, numba.njit(cache=True)(fn))
    except RuntimeError:
        return cast(_F, numba.njit(fn))


@_compiled
def _dedupe(px: FloatArray, py: FloatArray, nv: int) -> int:
    """Merge consecutive vertices (and the last with the first) that are one; new count."""
    if nv <= 1:
        return nv
    scale = 0.0
    for k in range(nv):
        scale = max(scale, abs(px[k]), abs(py[k]))
    tol = _SAME_RTOL * scale
    m = 1
    for k in range(1, nv):
        if abs(px[k] - px[m - 1]) + abs(py[k] - py[m - 1]) > tol:
            px[m] = px[k]
            py[m] = py[k]
            m += 1
    while m > 1 and abs(px[m - 1] - px[0]) + abs(py[m - 1] - py[0]) <= tol:
        m -= 1
    return m


@_compiled
def _corner(px: FloatArray, py: FloatArray, nv: int, k: int) -> float:
    """Twice the area of the triangle of vertex ``k`` and its neighbours (``inf`` at the
    origin, which is never dropped)."""
    if px[k] == 0.0 and py[k] == 0.0:
        return np.inf
    a = k - 1 if k > 0 else nv - 1
    z = k + 1 if k + 1 < nv else 0
    return float(abs((px[k] - px[a]) * (py[z] - py[a]) - (py[k] - py[a]) * (px[z] - px[a])))


@_compiled
def _unsteep(px: FloatArray, py: FloatArray, nv: int) -> int:
    """Drop the outer end (larger ``x``, never the origin) of every edge that is vertical
    but for round-off; new count.

    Such an edge turns into ``x <= const`` in the Fourier-Motzkin step of the node before
    (its ``y`` coefficient is lost against the jerk rows'), which then allows an ``x`` at
    which this polygon's range of ``y`` is one point: the forward pass broke a jerk row
    24-fold (the spiral, 2,000 points). Dropping a vertex keeps the polygon inside.
    """
    scale = 0.0
    for k in range(nv):
        scale = max(scale, abs(px[k]))
    near = _STEEP_RTOL * scale
    k = 0
    while k < nv and nv > 2:
        k1 = k + 1 if k + 1 < nv else 0
        dx = abs(px[k1] - px[k])
        if dx == 0.0 or dx > near:
            k += 1
            continue
        out = k1 if px[k1] > px[k] else k
        if px[out] == 0.0 and py[out] == 0.0:
            out = k if out == k1 else k1
        for j in range(out, nv - 1):
            px[j], py[j] = px[j + 1], py[j + 1]
        nv -= 1
        k = max(k - 1, 0)
    return nv


@_compiled
def _simplify(px: FloatArray, py: FloatArray, nv: int, cap: int, rtol: float) -> int:
    """Drop vertices (never the origin), least area lost first, while one loses less than
    ``rtol`` of the polygon's area or more than ``cap`` are left; new count. The hull of the
    vertices kept lies inside the polygon."""
    nv = _unsteep(px, py, nv)
    if nv <= 3:
        return nv
    twice_area = 0.0  # the shoelace formula (counter-clockwise: positive)
    for k in range(nv):
        k1 = k + 1 if k + 1 < nv else 0
        twice_area += px[k] * py[k1] - px[k1] * py[k]
    small = rtol * twice_area
    area = np.empty(nv)
    for k in range(nv):
        area[k] = _corner(px, py, nv, k)
    while nv > 3:
        best = 0
        for k in range(1, nv):
            if area[k] < area[best]:
                best = k
        if area[best] > small and nv <= cap:
            break
        for k in range(best, nv - 1):
            px[k], py[k], area[k] = px[k + 1], py[k + 1], area[k + 1]
        nv -= 1
        before = best - 1 if best > 0 else nv - 1
        after = best if best < nv else 0
        area[before] = _corner(px, py, nv, before)
        area[after] = _corner(px, py, nv, after)
    return nv


@_compiled
def _bounding_box(px: FloatArray, py: FloatArray, nv: int, box: FloatArray) -> None:
    """``box`` = ``(x_lo, x_hi, y_lo, y_hi)`` of the polygon."""
    box[0], box[1], box[2], box[3] = px[0], px[0], py[0], py[0]
    for k in range(1, nv):
        box[0], box[1] = min(box[0], px[k]), max(box[1], px[k])
        box[2], box[3] = min(box[2], py[k]), max(box[3], py[k])


@_compiled
def _apply(
    poly: _Polygon,
    nv: int,
    hp: tuple[float, float, float],
    scratch: _Scratch,
) -> int:
    """Cut the polygon ``(px, py, box)`` in place by ``a x + b y <= c``; new count.

    The half-plane is normalised and ``c`` clamped at ``>= 0`` so that the origin stays. It
    is skipped when it holds on the bounding box ``box`` (kept up to date), or on every
    vertex; else the polygon is cut as Sutherland-Hodgman does, consecutive vertices that
    are one merged.
    """
    px, py, box = poly
    qx, qy, f = scratch
    a, b, c = hp
    s = abs(a) + abs(b)
    if s == 0.0:
        return nv  # 0 <= c: no constraint on (x, y)
    a, b, c = a / s, b / s, max(c / s, 0.0)
    if a * (box[1] if a > 0.0 else box[0]) + b * (box[3] if b > 0.0 else box[2]) <= c:
        return nv
    outside = False
    for k in range(nv):
        f[k] = a * px[k] + b * py[k] - c
        if f[k] <= _INSIDE_RTOL * (abs(a * px[k]) + abs(b * py[k]) + c):
            f[k] = min(f[k], 0.0)  # inside, up to round-off
        else:
            outside = True
    if not outside:
        return nv
    same = _SAME_RTOL * max(abs(box[0]), abs(box[1]), abs(box[2]), abs(box[3]))
    m = 0
    for k in range(nv):
        k1 = k + 1 if k + 1 < nv else 0
        for take in range(2):
            if take == 0:
                if f[k] > 0.0:
                    continue
                x, y = px[k], py[k]
            else:
                if (f[k] > 0.0) == (f[k1] > 0.0):
                    continue
                t = f[k] / (f[k] - f[k1])
                x, y = px[k] + t * (px[k1] - px[k]), py[k] + t * (py[k1] - py[k])
            if m > 0 and abs(x - qx[m - 1]) + abs(y - qy[m - 1]) <= same:
                continue
            qx[m], qy[m] = x, y
            m += 1
    while m > 1 and abs(qx[m - 1] - qx[0]) + abs(qy[m - 1] - qy[0]) <= same:
        m -= 1
    for k in range(m):
        px[k], py[k] = qx[k], qy[k]
    if m >= _BUFFER - 4:
        m = _simplify(px, py, m, _BUFFER // 2, 0.0)
    _bounding_box(px, py, m, box)
    return m


@_compiled
def _edges(vx: FloatArray, vy: FloatArray, nv: int, out: FloatArray) -> int:
    """Half-planes ``a y + b z <= c`` of the polygon ``vx, vy`` (in ``(y, z)``), rows of
    ``out``; a segment or a point adds its bounding box in ``z``. Returns the count."""
    m = 0
    for k in range(nv if nv > 1 else 0):
        k1 = k + 1 if k + 1 < nv else 0
        dy, dz = vx[k1] - vx[k], vy[k1] - vy[k]
        a, b = dz, -dy  # outward normal of a counter-clockwise edge
        out[m, 0], out[m, 1], out[m, 2] = a, b, max(a * vx[k] + b * vy[k], 0.0)
        m += 1
    if nv <= 2:
        zmax = vy[0]
        for k in range(nv):
            zmax = max(zmax, vy[k])
        out[m, 0], out[m, 1], out[m, 2] = 0.0, 1.0, zmax
        out[m + 1, 0], out[m + 1, 1], out[m + 1, 2] = 0.0, -1.0, 0.0
        m += 2
    return m


@_compiled
def _start(
    poly: _Polygon,
    corner: tuple[float, float],
    acc: AccRows,
    scratch: _Scratch,
) -> int:
    """The box ``[0, x_max] x [0, y_max]`` of one interval cut by its acceleration rows
    ``|alpha x + beta y| <= r`` (``acc``: one interval's rows); the vertex count."""
    px, py, box = poly
    xmax, ymax = corner
    al, be, racc = acc
    px[0], py[0], px[1], py[1] = 0.0, 0.0, xmax, 0.0
    px[2], py[2], px[3], py[3] = xmax, ymax, 0.0, ymax
    nv = _dedupe(px, py, 4)
    _bounding_box(px, py, nv, box)
    for j in range(al.size):
        if np.isfinite(racc[j]):
            nv = _apply(poly, nv, (al[j], be[j], racc[j]), scratch)
            nv = _apply(poly, nv, (-al[j], -be[j], racc[j]), scratch)
    return nv


@_compiled
def _lift(
    later: tuple[FloatArray, FloatArray, int],
    jerk: JerkRows,
    rows: FloatArray,
) -> int:
    """The constraints on ``(x, y, z) = (b_i, b_{i+1}, b_{i+2})``: the edges of ``K_{i+1}``
    (in ``(y, z)``) and both sides of the jerk rows of node ``i + 1`` (``jerk``: that node's
    ``p, c, s, L``), as rows ``(x, y, z, c, owner)`` of ``rows`` (``owner``: the jerk row, or
    -1 for an edge); their count."""
    vx, vy, nv = later
    cm, cc, cp, rj = jerk
    ne = _edges(vx, vy, nv, rows)
    for k in range(ne - 1, -1, -1):  # (a, b, c) -> (0, a, b, c, -1)
        rows[k, 4], rows[k, 3], rows[k, 2] = -1.0, rows[k, 2], rows[k, 1]
        rows[k, 1], rows[k, 0] = rows[k, 0], 0.0
    m = ne
    for k in range(cm.size):
        if not np.isfinite(rj[k]):
            continue
        for sign in (1.0, -1.0):
            rows[m, 0], rows[m, 1], rows[m, 2] = sign * cm[k], sign * cc[k], sign * cp[k]
            rows[m, 3], rows[m, 4] = rj[k], k
            m += 1
    return m


@_compiled
def _eliminate(
    poly: _Polygon,
    nv: int,
    lifted: tuple[FloatArray, int],
    scratch: _Scratch,
) -> int:
    """Cut the polygon by the Fourier-Motzkin elimination of ``z`` from the ``count`` rows
    ``(x, y, z, c, owner)``; the vertex count.

    Pairs of two edges of ``K_{i+1}`` are skipped: together they say ``y`` lies in the
    projection of ``K_{i+1}``, which the starting box already holds. So are the two sides
    of one jerk row (``0 <= 2 L``).
    """
    rows, count = lifted
    for u in range(count):
        if rows[u, 2] == 0.0:
            nv = _apply(poly, nv, (rows[u, 0], rows[u, 1], rows[u, 3]), scratch)
    for u in range(count):
        if rows[u, 2] <= 0.0:
            continue
        for d in range(count):
            if rows[d, 2] >= 0.0 or rows[u, 4] == rows[d, 4]:
                continue
            wu, wd = -rows[d, 2], rows[u, 2]
            hp = (
                wu * rows[u, 0] + wd * rows[d, 0],
                wu * rows[u, 1] + wd * rows[d, 1],
                wu * rows[u, 3] + wd * rows[d, 3],
            )
            nv = _apply(poly, nv, hp, scratch)
    return nv


@_compiled
def _controllable(
    acc: AccRows,
    jerk: JerkRows,
    ub: FloatArray,
    simplify: tuple[int, float],
) -> tuple[FloatArray, FloatArray, Any]:
    """The controllable polygons ``K_0 .. K_{n-2}`` (backward), as vertices.

    Returns
    -------
    tuple
        ``vx, vy`` of shape (n - 1, cap) (``b_i``, ``b_{i+1}`` of every vertex,
        counter-clockwise) and the vertex counts, shape (n - 1,).
    """
    al, be, racc = acc
    cm, cc, cp, rj = jerk
    cap, rtol = simplify
    n = ub.size
    vx = np.zeros((n - 1, cap))
    vy = np.zeros((n - 1, cap))
    vn = np.zeros(n - 1, dtype=np.int64)
    px, py = np.empty(_BUFFER), np.empty(_BUFFER)
    poly = (px, py, np.empty(4))
    scratch = (np.empty(_BUFFER), np.empty(_BUFFER), np.empty(_BUFFER))
    rows = np.empty((cap + 2 + 2 * cm.shape[1], 5))
    for i in range(n - 2, -1, -1):
        ymax = ub[i + 1]
        if i < n - 2:  # y within the projection of K_{i+1}
            ymax = min(ymax, vx[i + 1, : vn[i + 1]].max())
        nv = _start(poly, (ub[i], ymax), (al[i], be[i], racc[i]), scratch)
        if i < n - 2:
            count = _lift((vx[i + 1], vy[i + 1], vn[i + 1]), (cm[i], cc[i], cp[i], rj[i]), rows)
            nv = _eliminate(poly, nv, (rows, count), scratch)
        nv = _simplify(px, py, nv, cap, rtol)
        vn[i] = nv
        vx[i, :nv] = px[:nv]
        vy[i, :nv] = py[:nv]
    return vx, vy, vn


@_compiled
def _column(vx: FloatArray, vy: FloatArray, nv: int, x: float) -> tuple[float, float]:
    """The range of ``y`` with ``(x, y)`` in the polygon (``x`` clamped to its extent)."""
    xlo, xhi = vx[0], vx[0]
    for k in range(1, nv):
        xlo, xhi = min(xlo, vx[k]), max(xhi, vx[k])
    x = min(max(x, xlo), xhi)
    lo, hi = np.inf, -np.inf
    for k in range(nv):
        k1 = k + 1 if k + 1 < nv else 0
        x0, x1 = vx[k], vx[k1]
        if x0 == x:
            lo, hi = min(lo, vy[k]), max(hi, vy[k])
        if min(x0, x1) < x < max(x0, x1):
            y = vy[k] + (x - x0) / (x1 - x0) * (vy[k1] - vy[k])
            lo, hi = min(lo, y), max(hi, y)
    return lo, hi


@_compiled
def _least_broken(bounds: FloatArray, m: int) -> float:
    """The ``z`` that breaks the rows ``(lo, hi, weight)`` (``m`` rows of ``bounds``) least,
    ``max(weight (z - hi), weight (lo - z))`` over them, by bisection (their ranges do not
    meet: round-off)."""
    a, z = np.inf, -np.inf
    for k in range(m):
        a, z = min(a, bounds[k, 1]), max(z, bounds[k, 0])
    for _ in range(60):
        mid = 0.5 * (a + z)
        over = under = 0.0
        for k in range(m):
            over = max(over, bounds[k, 2] * (mid - bounds[k, 1]))
            under = max(under, bounds[k, 2] * (bounds[k, 0] - mid))
        if over > under:
            z = mid
        else:
            a = mid
    return 0.5 * (a + z)


@_compiled
def _forward(
    polygons: tuple[FloatArray, FloatArray, Any],
    jerk: JerkRows,
    ub: FloatArray,
) -> FloatArray:
    """The greedy pass: node by node the largest ``b_{i+1}`` inside ``K_i`` and the jerk rows
    of node ``i``.

    Where the jerk rows' ranges do not meet (round-off: a row of a direction almost normal
    to the path, whose ``b_{i+1}`` coefficient is 1e-4 of another's, at 32,000 points),
    the ``b_{i+1}`` that breaks them least relative to their bounds is taken, not the top
    of their range: that broke the other row 4.5-fold.
    """
    vx, vy, vn = polygons
    cm, cc, cp, rj = jerk
    n = ub.size
    q = cm.shape[1]
    b = np.zeros(n)
    rows = np.empty((q, 3))  # (lo, hi, weight) of every jerk row of the node
    for k in range(vn[0]):
        b[0] = max(b[0], vx[0, k])
    b[0] = min(b[0], ub[0])
    for i in range(n - 1):
        hi = min(_column(vx[i], vy[i], vn[i], b[i])[1], ub[i + 1])
        m = 0
        jlo, jhi = -np.inf, np.inf
        for k in range(q if i >= 1 else 0):
            lim = rj[i - 1, k]
            s = cp[i - 1, k]
            if not np.isfinite(lim) or s == 0.0:
                continue
            t = cm[i - 1, k] * b[i - 1] + cc[i - 1, k] * b[i]
            rlo, rhi = min((lim - t) / s, (-lim - t) / s), max((lim - t) / s, (-lim - t) / s)
            rows[m, 0], rows[m, 1], rows[m, 2] = rlo, rhi, abs(s) / lim
            jlo, jhi = max(jlo, rlo), min(jhi, rhi)
            m += 1
        if jlo > jhi:
            jhi = _least_broken(rows, m)
        b[i + 1] = max(min(hi, jhi), 0.0)
    return b


def solve_pairs(
    acc: AccRows,
    jerk: JerkRows,
    ub: FloatArray,
    *,
    cap: int = VERTEX_CAP,
    rtol: float = AREA_RTOL,
) -> tuple[FloatArray, float]:
    """A feasible, near-optimal ``b`` of the linearised grid problem (backward polygons, greedy
    forward pass, certified by :func:`certify`).

    Parameters
    ----------
    acc : tuple of ndarray, shape (n - 1, m)
        ``alpha``, ``beta`` and the bound ``r`` (``inf``: free) of every acceleration row
        ``|alpha b_i + beta b_{i+1}| <= r`` of interval ``i``.
    jerk : tuple of ndarray, shape (n - 2, q)
        ``p``, ``c``, ``s`` and the bound ``L`` (``inf``: free) of every linearised jerk row
        ``|p b_{i-1} + c b_i + s b_{i+1}| <= L`` of node ``i = 1 .. n - 2``.
    ub : ndarray, shape (n,)
        Column bounds (``>= 0``).
    cap : int, default VERTEX_CAP
        Vertices each controllable polygon keeps.

    Returns
    -------
    b : ndarray, shape (n,)
        ``0 <= b <= ub`` holding every row exactly.
    excess : float
        The largest ``|row| / bound`` before the scaling (1 + round-off: a larger one is
        a fault of the polygons, which the caller should not take).
    """
    al, be, racc = (np.ascontiguousarray(x, dtype=np.float64) for x in acc)
    cm, cc, cp, rj = (np.ascontiguousarray(x, dtype=np.float64) for x in jerk)
    acc_c, jerk_c = (al, be, racc), (cm, cc, cp, rj)
    ub_c = np.ascontiguousarray(np.maximum(ub, 0.0), dtype=np.float64)
    # The corners dropped at every node add up over the nodes a polygon depends on, whose
    # number grows with the grid: the tolerance per node shrinks with it.
    per_node = float(rtol) / (ub_c.size - 1)
    polygons = _controllable(acc_c, jerk_c, ub_c, (int(cap), per_node))
    b = _forward(polygons, jerk_c, ub_c)
    return certify(b, acc, jerk, ub_c)


def row_excess(
    b: FloatArray,
    acc: AccRows,
    jerk: JerkRows,
) -> float:
    """The largest ``|row| / bound`` of ``b`` over the acceleration and jerk rows."""
    al, be, racc = acc
    cm, cc, cp, rj = jerk
    with np.errstate(divide="ignore", invalid="ignore"):
        ra = np.abs(al * b[:-1, None] + be * b[1:, None]) / racc
        rjerk = np.abs(cm * b[:-2, None] + cc * b[1:-1, None] + cp * b[2:, None]) / rj
    worst = 0.0
    for ratio in (ra, rjerk):
        finite = np.isfinite(ratio)
        if np.any(finite):
            worst = max(worst, float(np.max(ratio[finite])))
    return worst


def certify(
    b: FloatArray,
    acc: AccRows,
    jerk: JerkRows,
    ub: FloatArray,
) -> tuple[FloatArray, float]:
    """``b`` clipped to ``[0, ub]`` and scaled down by its largest row excess, if any: the rows
    are homogeneous in ``b``, so the scaled ``b`` holds every row (a round-off excess costs
    that much speed everywhere). Returns it and the excess before the scaling."""
    b = np.clip(b, 0.0, ub)
    worst = row_excess(b, acc, jerk)
    if worst > 1.0:
        b = b / worst
        # One more ulp of room: |A (b / w)| / r can round to 1 + 1e-16.
        b = b * (1.0 - 4.0 * np.finfo(np.float64).eps)
    return np.asarray(b, dtype=np.float64), worst
