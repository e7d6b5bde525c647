"""Which boxes come close: sweep and prune over axis-aligned boxes, in time linear in the output.

Comparing every pair of ``N`` boxes costs ``N^2 / 2``: half a million pairs per
window at 1,000 drones, most of them a show's width apart. Sorting the boxes
along one axis instead leaves, for each box, only the run of boxes that start
before it ends (plus the gap) as candidates (Baraff's sweep and prune, as in
every physics engine's broad phase); the Euclidean gap between the boxes then
decides. The axis is the one along which the fewest candidates overlap.

Boxes carry a *group* (a time window of the separation check): only boxes of
one group are paired, and all groups are swept at once, laid side by side
along the axis.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
from numpy.typing import NDArray

from skyquill.validation import FloatArray

IntArray = NDArray[np.intp]

#: Candidates generated at once before the exact filter (memory: ~50 bytes each).
BATCH = 2_000_000
#: Relative slack of the sweep's comparison: the exact gap decides, so rounding in
#: the groups' offsets must only ever add candidates, never drop one.
SLACK = 1e-9


def close_boxes(
    lo: FloatArray, hi: FloatArray, gap: float, groups: IntArray | None = None
) -> tuple[IntArray, IntArray]:
    """Pairs of boxes at most ``gap`` apart (Euclidean distance between the boxes).

    Parameters
    ----------
    lo, hi
        Corners of the boxes, shape (M, D), ``lo <= hi``.
    gap
        Largest distance between two boxes that pairs them, >= 0 (same unit).
    groups
        Shape (M,), integers: only boxes of the same group are paired; ``None``: one group.

    Returns
    -------
    first, second
        Indices into the boxes (K,) with ``first < second``, sorted by ``(first, second)``.
    """
    m = lo.shape[0]
    empty = np.zeros(0, dtype=np.intp)
    if m < 2:
        return empty, empty
    group = np.zeros(m, dtype=np.intp) if groups is None else np.asarray(groups, dtype=np.intp)
    keys = [_laid_out(lo[:, k], hi[:, k], gap, group) for k in range(lo.shape[1])]
    sweeps = [_sweep(start, end, gap) for start, end in keys]
    order, ends = min(sweeps, key=lambda s: _count(s[1]))
    pieces = []
    for first, second in _candidates(order, ends):
        i, j = order[first], order[second]
        far = np.maximum(0.0, np.maximum(lo[i] - hi[j], lo[j] - hi[i]))
        keep = (np.einsum("kd,kd->k", far, far) <= gap * gap) & (group[i] == group[j])
        pieces.append((np.minimum(i, j)[keep], np.maximum(i, j)[keep]))
    if not pieces:
        return empty, empty
    first = np.concatenate([p for p, _ in pieces])
    second = np.concatenate([q for _, q in pieces])
    sort = np.lexsort((second, first))
    return first[sort], second[sort]


def _laid_out(
    lo: FloatArray, hi: FloatArray, gap: float, group: IntArray
) -> tuple[FloatArray, FloatArray]:
    """One axis's intervals with each group shifted past the one before (never overlapping)."""
    base = float(lo.min())
    stride = float(hi.max()) - base + 2.0 * gap + 1.0
    shift = group * stride - base
    return lo + shift, hi + shift


def _sweep(start: FloatArray, end: FloatArray, gap: float) -> tuple[IntArray, IntArray]:
    """The boxes sorted by ``start``, and for each the end of its run of overlapping ones."""
    order = np.argsort(start, kind="stable")
    starts = start[order]
    reach = end[order] + gap
    reach += SLACK * (1.0 + np.abs(reach))
    return order, np.searchsorted(starts, reach, side="right")


def _count(ends: IntArray) -> int:
    return int(np.maximum(0, ends - np.arange(1, ends.size + 1)).sum())


def _candidates(order: IntArray, ends: IntArray) -> Iterator[tuple[IntArray, IntArray]]:
    """Positions (in sorted order) of every candidate pair, in batches of about :data:`BATCH`."""
    counts = np.maximum(0, ends - np.arange(1, order.size + 1))
    total = np.cumsum(counts)
    begin = 0
    while begin < order.size:
        stop = int(np.searchsorted(total, (total[begin - 1] if begin else 0) + BATCH, "right"))
        stop = max(stop, begin + 1)
        c = counts[begin:stop]
        first = np.repeat(np.arange(begin, stop), c)
        offsets = np.arange(c.sum()) - np.repeat(np.cumsum(c) - c, c)
        yield first, first + 1 + offsets
        begin = stop
