"""Turning points of a stroke by split-and-merge (paper 000, section 4).

The paper keeps only the "meaningful" points of a handwritten stroke: its start,
its end and its turning points, found as the endpoints of the line segments a
split-and-merge segmentation (Borges & Aldon 2000, the paper's reference [2])
cuts the stroke into. The paper's Fig. 5 / steps 1-5 describe only the split;
the merge that gives the method its name is added here as in [2].
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.validation import as_array, as_float

FloatArray = NDArray[np.float64]
IndexArray = NDArray[np.intp]


def segment_distances(points: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """Euclidean distance of each point to the closed segment ``a``-``b``.

    Parameters
    ----------
    points
        ``(N, 2)`` points, any length unit.
    a, b
        ``(2,)`` segment endpoints, same unit; ``a == b`` gives the distance to
        that point.

    Returns
    -------
    numpy.ndarray
        ``(N,)`` distances, same unit.
    """
    ab = b - a
    ap = points - a
    denom = float(ab @ ab)
    if denom > 0.0:
        s = np.clip((ap @ ab) / denom, 0.0, 1.0)
        diff = ap - s[:, None] * ab
    else:
        diff = ap
    return np.hypot(diff[:, 0], diff[:, 1])


def segment_distances_pairwise(p: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """Distance of each point ``p[i]`` to its own segment ``a[i]``-``b[i]``.

    Parameters
    ----------
    p, a, b
        ``(N, 2)`` points and segment endpoints, one length unit.

    Returns
    -------
    numpy.ndarray
        ``(N,)`` distances, same unit.
    """
    ab = b - a
    ap = p - a
    denom = np.einsum("ij,ij->i", ab, ab)
    proj = np.einsum("ij,ij->i", ap, ab)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(denom > 0.0, np.clip(proj / denom, 0.0, 1.0), 0.0)
    diff = ap - s[:, None] * ab
    return np.hypot(diff[:, 0], diff[:, 1])


def _fits(stroke: FloatArray, i: int, j: int, threshold: float) -> bool:
    """Whether points ``i..j`` all lie within ``threshold`` of segment ``i``-``j``."""
    if j - i < 2:
        return True
    return bool(segment_distances(stroke[i + 1 : j], stroke[i], stroke[j]).max() <= threshold)


def turning_points(stroke: Any, threshold: float) -> IndexArray:
    """Indices of a stroke's start, end and turning points (split-and-merge).

    Split (paper 000, section 4, steps 1-5): join the first point A and the last
    point B, find the point C farthest from A-B; if it is farther than
    ``threshold`` split into A-C and C-B and repeat on each part, until every
    point is within ``threshold`` of its part's chord. Merge (Borges & Aldon
    2000): walk the resulting endpoints in order and drop an endpoint whenever
    the two segments meeting there can be replaced by one chord that still keeps
    every point between them within ``threshold``.

    Distances are to the chord as a *segment*, not to the infinite line through
    A and B (which is what the paper's "perpendicular distance to line A-B"
    says): a stroke that goes out and doubles back along itself has all its
    points on the line through its ends, so a line distance would find nothing
    to split and lose the turn at the far end; and a closed stroke (A == B) has
    no line at all. The segment distance equals the perpendicular one wherever
    the foot of the perpendicular falls inside the segment.

    The paper's recursion is run breadth first, one vectorised pass per level of
    the split tree, so a stroke of a million points cannot exhaust Python's
    recursion limit. The cost is ``O(K log K)`` for strokes whose splits are
    roughly balanced (handwriting, noise below the threshold) and ``O(K^2)`` at
    worst (a stroke whose every point is a corner and whose farthest point is
    always next to an end, such as a dense zigzag along a diagonal).

    Parameters
    ----------
    stroke
        ``(K, 2)`` points in chronological order, K >= 2, in any length unit
        (metres after :meth:`Strokes.scaled`).
    threshold
        Largest distance a dropped point may have from the simplified polyline,
        in the stroke's unit; > 0.

    Returns
    -------
    numpy.ndarray
        Sorted ``(M,)`` integer indices into ``stroke``, 2 <= M <= K, always
        starting with 0 and ending with ``K - 1``. Every point ``i`` with
        ``idx[j] <= i <= idx[j + 1]`` is within ``threshold`` of the segment
        ``stroke[idx[j]]``-``stroke[idx[j + 1]]``.

    Raises
    ------
    InputError
        If ``stroke`` is not a finite ``(K, 2)`` array with K >= 2, or
        ``threshold`` is not a finite number > 0.
    """
    pts = as_array("stroke", stroke, shape=(None, 2))
    if pts.shape[0] < 2:
        raise InputError(f"stroke: got {pts.shape[0]} point(s), expected at least 2")
    threshold = as_float("threshold", threshold, positive=True)

    if pts.shape[0] <= _SHORT:
        return _short_turning_points(pts, threshold)
    ends = _split(pts, threshold)
    return _merge(pts, ends, threshold)


#: Strokes of at most this many points are simplified point by point in plain Python
#: (:func:`_short_turning_points`): a character's strokes have 5-20 points, where the
#: vectorised sweep's array operations (a few microseconds each, dozens per level) cost
#: ~10x the arithmetic itself.
_SHORT = 64


def _short_turning_points(pts: FloatArray, threshold: float) -> IndexArray:
    """:func:`_split` then :func:`_merge` of a short stroke, on Python floats.

    The same rules and the same arithmetic per distance as
    :func:`segment_distances_pairwise` (``proj / denom`` clipped to [0, 1], then the
    hypotenuse of the gap); the farthest point of an interval is its first one at the
    maximum, as ``np.argmax``; the set of split points does not depend on the order
    the intervals are visited in.
    """
    xy = pts.tolist()

    def distances(i: int, j: int) -> list[float]:
        (ax, ay), (bx, by) = xy[i], xy[j]
        abx, aby = bx - ax, by - ay
        denom = abx * abx + aby * aby
        out = []
        for px, py in xy[i + 1 : j]:
            apx, apy = px - ax, py - ay
            s = min(max((apx * abx + apy * aby) / denom, 0.0), 1.0) if denom > 0.0 else 0.0
            out.append(math.hypot(apx - s * abx, apy - s * aby))
        return out

    last = len(xy) - 1
    keep = {0, last}
    stack = [(0, last)]
    while stack:
        i, j = stack.pop()
        if j - i < 2:
            continue
        d = distances(i, j)
        far = max(d)
        if far > threshold:
            k = i + 1 + d.index(far)
            keep.add(k)
            stack += [(i, k), (k, j)]
    ends = sorted(keep)
    if len(ends) <= 2:
        return np.asarray(ends, dtype=np.intp)
    merged, pending = [ends[0]], ends[1]
    for nxt in ends[2:]:
        if max(distances(merged[-1], nxt), default=0.0) > threshold:
            merged.append(pending)
        pending = nxt
    merged.append(pending)
    return np.asarray(merged, dtype=np.intp)


#: Intervals with at least this many inner points are searched one by one on
#: contiguous slices; smaller ones are searched together in one gathered sweep.
_BATCH_BELOW = 4096


def _farthest_batched(
    pts: FloatArray, lo: IndexArray, hi: IndexArray
) -> tuple[IndexArray, FloatArray]:
    """Farthest inner point of each interval ``lo[m]..hi[m]`` (all inner >= 1)."""
    inner = hi - lo - 1
    seg = np.repeat(np.arange(lo.size), inner)
    starts = np.cumsum(inner) - inner
    idx = np.arange(seg.size) - starts[seg] + lo[seg] + 1
    # Distance to each chord as a segment, not as a line: a stroke that doubles
    # back lies on the line through its ends (see turning_points).
    d = segment_distances_pairwise(pts[idx], pts[lo][seg], pts[hi][seg])
    far = np.maximum.reduceat(d, starts)
    # the first point of each interval that attains its maximum, as np.argmax
    hits = np.flatnonzero(d == far[seg])
    _, first = np.unique(seg[hits], return_index=True)
    return idx[hits[first]], far


def _split(pts: FloatArray, threshold: float) -> IndexArray:
    """Split step: endpoints of intervals whose points all fit their chord.

    The paper's recursion is run breadth first: each pass finds the farthest
    point (the first one, on ties) of every open interval and splits those
    where it exceeds the threshold. Large intervals are searched on contiguous
    slices, the many small ones of the deep levels together in one vectorised
    sweep, so there is neither recursion nor per-interval Python overhead where
    intervals are small. The result is the same set as the paper's depth-first
    recursion gives.
    """
    last = pts.shape[0] - 1
    keep = np.zeros(pts.shape[0], dtype=bool)
    keep[0] = keep[last] = True
    lo = np.array([0], dtype=np.intp)
    hi = np.array([last], dtype=np.intp)
    while lo.size:
        inner = hi - lo - 1
        open_ = inner > 0
        lo, hi, inner = lo[open_], hi[open_], inner[open_]
        if lo.size == 0:
            break
        k = np.empty(lo.size, dtype=np.intp)
        far = np.empty(lo.size)
        big = inner >= _BATCH_BELOW
        for m in np.flatnonzero(big):
            i, j = int(lo[m]), int(hi[m])
            d = segment_distances(pts[i + 1 : j], pts[i], pts[j])
            k[m] = i + 1 + int(np.argmax(d))
            far[m] = d[k[m] - i - 1]
        small = ~big
        if np.any(small):
            k[small], far[small] = _farthest_batched(pts, lo[small], hi[small])
        split = far > threshold
        ks = k[split]
        keep[ks] = True
        lo, hi = np.concatenate([lo[split], ks]), np.concatenate([ks, hi[split]])
    return np.flatnonzero(keep).astype(np.intp)


def _merge(pts: FloatArray, ends: IndexArray, threshold: float) -> IndexArray:
    """Merge step: drop endpoints whose two segments fit one chord.

    Walks the endpoints in order, extending the current segment over the next
    endpoint while every point of the union stays within ``threshold`` of the
    longer chord. An endpoint farther than ``threshold`` from the chord of its
    two neighbours cannot be dropped while its left neighbour is still the
    anchor; that cheap test, vectorised up front, skips most full checks.
    """
    if ends.size <= 2:
        return ends
    mid = segment_distances_pairwise(pts[ends[1:-1]], pts[ends[:-2]], pts[ends[2:]])
    stuck = mid > threshold
    merged = [int(ends[0])]
    pending = int(ends[1])
    for n in range(2, ends.size):
        nxt = int(ends[n])
        if merged[-1] == int(ends[n - 2]) and stuck[n - 2]:
            fits = False
        else:
            fits = _fits(pts, merged[-1], nxt, threshold)
        if not fits:
            merged.append(pending)
        pending = nxt
    merged.append(pending)
    return np.asarray(merged, dtype=np.intp)
