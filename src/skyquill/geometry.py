"""Small geometric helpers shared by the engine's users (fidelity checks, studies)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.spatial import cKDTree

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
    if p.shape[0] * (v.shape[0] - 1) <= _TABLE_PAIRS:
        return _by_table(p, v)
    a, b = _short_segments(v)
    ab = b - a
    length2 = np.einsum("sd,sd->s", ab, ab)
    # A point's nearest segment has its midpoint within (distance to the nearest
    # midpoint's segment) + (longest half-segment): only those are measured, found by a
    # k-d tree, so memory and time grow with the points and segments, not their product
    # (the table of every point against every segment took 6.7 GB for one drawing).
    tree = cKDTree(0.5 * (a + b))
    reach = 0.5 * float(np.sqrt(length2.max()))
    best = np.empty(p.shape[0])
    for start in range(0, p.shape[0], _CHUNK):
        chunk = p[start : start + _CHUNK]
        _, nearest = tree.query(chunk)
        radius = _segment_distance(chunk, a[nearest], ab[nearest], length2[nearest]) + reach
        near = tree.query_ball_point(chunk, radius * (1.0 + 1e-9) + 1e-12)
        counts = np.fromiter((len(n) for n in near), dtype=np.intp, count=len(near))
        point = np.repeat(np.arange(chunk.shape[0]), counts)
        seg = np.fromiter((k for n in near for k in n), dtype=np.intp, count=int(counts.sum()))
        dist = _segment_distance(chunk[point], a[seg], ab[seg], length2[seg])
        out = np.full(chunk.shape[0], np.inf)
        np.minimum.at(out, point, dist)
        best[start : start + _CHUNK] = out
    return best


def polyline_distances(
    pairs: Sequence[tuple[FloatArray, FloatArray]],
) -> list[FloatArray]:
    """:func:`polyline_distance` of each ``(points, vertices)`` pair, the same numbers.

    The pairs small enough for the table (a writing plan's ink runs against their
    strokes: a few thousand point-segment pairs each) are measured in one table of
    all their pairs, a chunk of :data:`_TABLE_CHUNK` pairs or more at a time, instead
    of one small table per pair (the numpy calls' overhead was most of their time);
    larger ones go to :func:`polyline_distance`.

    Parameters
    ----------
    pairs
        ``(points (N_i, d), vertices (V_i, d))``, ``V_i >= 2``, m, one ``d`` for all.

    Returns
    -------
    list of numpy.ndarray, shape (N_i,) each, m
    """
    out: list[FloatArray | None] = [None] * len(pairs)
    batch: list[tuple[int, FloatArray, FloatArray]] = []
    for i, (p, v) in enumerate(_checked(pairs)):
        if v.shape[0] < 2 or p.shape[0] * (v.shape[0] - 1) > _TABLE_PAIRS:
            out[i] = polyline_distance(p, v)  # its own errors, or the k-d tree
        else:
            batch.append((i, p, v))
    dims = {p.shape[1] for _, p, _ in batch}
    if len(dims) > 1:
        raise InputError(f"pairs: got points of {sorted(dims)} coordinates, expected one")
    start = 0
    while start < len(batch):
        stop, size = start, 0
        while stop < len(batch) and (size < _TABLE_CHUNK or stop == start):
            size += batch[stop][1].shape[0] * (batch[stop][2].shape[0] - 1)
            stop += 1
        chunk = batch[start:stop]
        for (i, _, _), distance in zip(chunk, _by_joint_table(chunk), strict=True):
            out[i] = distance
        start = stop
    return [d for d in out if d is not None]


def _checked(pairs: Sequence[tuple[FloatArray, FloatArray]]) -> list[tuple[FloatArray, FloatArray]]:
    """``pairs`` validated as :func:`polyline_distance` validates each: float arrays of
    rank 2 with one width per pair, finite (checked once for all where they already are
    such arrays: a writing plan's fidelity measures ~70 pairs at a time)."""
    arrays = [a for pair in pairs for a in pair]
    plain = all(
        isinstance(a, np.ndarray) and a.dtype == np.float64 and a.ndim == 2 for a in arrays
    ) and all(p.shape[1] == v.shape[1] for p, v in pairs)
    if plain and (not arrays or np.isfinite(np.concatenate([a.ravel() for a in arrays])).all()):
        return list(pairs)
    checked = []
    for points, vertices in pairs:
        p = as_array("points", points, ndim=2)
        checked.append((p, as_array("vertices", vertices, shape=(None, p.shape[1]))))
    return checked


def _by_joint_table(batch: list[tuple[int, FloatArray, FloatArray]]) -> list[FloatArray]:
    """:func:`_by_table` of several ``(_, points, vertices)`` at once: every point against
    every segment of its own polyline, the same operations element by element."""
    points = np.concatenate([p for _, p, _ in batch])
    if points.shape[0] == 0:
        return [np.zeros(0) for _ in batch]
    a = np.concatenate([v[:-1] for _, _, v in batch])
    ab = np.concatenate([v[1:] - v[:-1] for _, _, v in batch])
    length2 = np.einsum("sd,sd->s", ab, ab)
    divisor = np.where(length2 > 0.0, length2, 1.0)
    n = np.array([p.shape[0] for _, p, _ in batch])
    m = np.array([v.shape[0] - 1 for _, _, v in batch])
    # Pair k: point point_of[k] against segment seg_of[k]; each point's pairs are contiguous.
    per_point = np.repeat(m, n)
    first_pair = np.concatenate([[0], np.cumsum(per_point)[:-1]])
    first_seg = np.repeat(np.concatenate([[0], np.cumsum(m)[:-1]]), n)
    point_of = np.repeat(np.arange(points.shape[0]), per_point)
    seg_of = np.repeat(first_seg - first_pair, per_point) + np.arange(point_of.size)
    # Gathered coordinate by coordinate from contiguous columns by ``take``: the same
    # values as ``points[point_of, i]``, ~4x faster than fancy indexing on a column.
    p_t, a_t, ab_t = points.T.copy(), a.T.copy(), ab.T.copy()
    q = [p_t[i].take(point_of) - a_t[i].take(seg_of) for i in range(points.shape[1])]
    ab_k = [ab_t[i].take(seg_of) for i in range(points.shape[1])]
    s = q[0] * ab_k[0]
    for i in range(1, points.shape[1]):
        s += q[i] * ab_k[i]
    s /= divisor.take(seg_of)
    np.clip(s, 0.0, 1.0, out=s)
    gap2 = (q[0] - s * ab_k[0]) ** 2
    for i in range(1, points.shape[1]):
        gap = q[i] - s * ab_k[i]
        gap *= gap
        gap2 += gap
    distance = np.sqrt(np.minimum.reduceat(gap2, first_pair))
    ends = np.cumsum(n).tolist()  # views by plain slices: np.split's overhead per part
    return [distance[a:b] for a, b in zip([0, *ends[:-1]], ends, strict=True)]


#: Points measured at once.
_CHUNK = 4096
#: Up to this many point-segment pairs every point is measured against every segment:
#: a writing plan's runs and strokes are a few hundred points each (a few thousand
#: pairs), where building and querying the k-d tree costs 5-10x the table. Above ~50,000
#: pairs (256 x 256 points along a curve) the tree is faster.
_TABLE_PAIRS = 1 << 15
#: Pairs measured at once by the table (fits in the cache: 2x faster than 65,536).
_TABLE_CHUNK = 1 << 14


def _by_table(p: FloatArray, v: FloatArray) -> FloatArray:
    """:func:`polyline_distance` by the table of every point against every segment,
    at most ``_TABLE_CHUNK`` pairs at a time (N,).

    Coordinate by coordinate on (points, segments) tables: an ``einsum`` over the
    (points, segments, d) array takes about twice as long.
    """
    a, ab = v[:-1], v[1:] - v[:-1]
    length2 = np.einsum("sd,sd->s", ab, ab)
    # Divided, not multiplied by a reciprocal: 1 / a subnormal squared length overflows.
    divisor = np.where(length2 > 0.0, length2, 1.0)
    rows = max(1, _TABLE_CHUNK // a.shape[0])
    best = np.empty(p.shape[0])
    for start in range(0, p.shape[0], rows):
        chunk = p[start : start + rows]
        q = [chunk[:, i, None] - a[None, :, i] for i in range(p.shape[1])]
        s = q[0] * ab[:, 0]
        for i in range(1, p.shape[1]):
            s += q[i] * ab[:, i]
        s /= divisor
        np.clip(s, 0.0, 1.0, out=s)
        gap2 = (q[0] - s * ab[:, 0]) ** 2
        for i in range(1, p.shape[1]):
            gap = q[i] - s * ab[:, i]
            gap *= gap
            gap2 += gap
        best[start : start + rows] = gap2.min(axis=1)
    distance: FloatArray = np.sqrt(best)
    return distance


def _segment_distance(
    p: FloatArray, a: FloatArray, ab: FloatArray, length2: FloatArray
) -> FloatArray:
    """Distance from each ``p[k]`` to the segment ``a[k] + [0, 1] ab[k]``, shape (K,)."""
    s = np.einsum("kd,kd->k", p - a, ab) / np.where(length2 > 0.0, length2, 1.0)
    gap = p - a - np.clip(s, 0.0, 1.0)[:, None] * ab
    distance: FloatArray = np.sqrt(np.einsum("kd,kd->k", gap, gap))
    return distance


def _short_segments(v: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The polyline's segments ``(starts, ends)``, long ones cut into pieces.

    Cutting changes no distance (the same points), but bounds the longest half-segment
    the k-d tree search must allow for: no piece is longer than twice the mean.
    """
    a, b = v[:-1], v[1:]
    length = np.linalg.norm(b - a, axis=1)
    limit = 2.0 * float(length.mean())
    pieces = np.maximum(1, np.ceil(length / limit).astype(np.intp)) if limit > 0.0 else None
    if pieces is None or np.all(pieces == 1):
        return a, b
    seg = np.repeat(np.arange(a.shape[0]), pieces)
    first = np.repeat(np.cumsum(pieces) - pieces, pieces)
    k = np.arange(seg.size) - first
    u0 = (k / pieces[seg])[:, None]
    u1 = ((k + 1) / pieces[seg])[:, None]
    return a[seg] + u0 * (b - a)[seg], a[seg] + u1 * (b - a)[seg]
