"""Concave regions, step 2: the order in which the convex parts are visited.

:func:`order_parts` finds a visiting order in which consecutive parts share an
edge, so the transits between them are short (exact for a few parts, greedy
beyond).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence

import numpy as np
from shapely.geometry import Polygon

from skyquill.coverage.partition import _LEN_TOL, _pairs, _shared_length
from skyquill.errors import InputError
from skyquill.validation import FloatArray, as_int

#: Part count up to which the visiting order is searched exactly (Held-Karp).
_EXACT_ORDER = 9


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
