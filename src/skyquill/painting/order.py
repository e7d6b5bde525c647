"""The order the dots are painted in.

* ``given`` -- the file's order.
* ``paper`` -- paper 002 §4.1: "from the right to the left and from the top to the bottom".
  Dots are grouped in rows one median dot spacing high (a stippled picture has no exact rows)
  and each row is painted right to left.
* ``shortest`` -- a short open tour over the dots, starting from the dot nearest the take-off
  point: nearest neighbour, then 2-opt (segment reversals) until no reversal shortens it. The
  flight between two dots is a straight transit between their waiting points, which lie on a
  copy of the drawing moved off the wall, so the distance between dots is the transit length.
* ``spread`` -- information early: first one dot every ``spacing_m`` across the drawing's
  width (the dot nearest each mark at mid-height, swept from the end nearer the start), so
  that the first contacts span the wall; then the shortest tour over the rest. (The other way
  to get them, a probing pass that does not paint, is the mission's ``probe_spacing_m``.)
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np

from skyquill.errors import InputError
from skyquill.painting.dots import nearest_spacing
from skyquill.validation import FloatArray

OrderName = Literal["given", "paper", "shortest", "spread"]
ORDERS: tuple[OrderName, ...] = ("given", "paper", "shortest", "spread")
#: Distance between the first dots of the ``spread`` order, m.
SPREAD_SPACING_M = 0.4
#: Above this many dots 2-opt (O(N^2) per pass) is skipped; nearest neighbour alone is used.
TWO_OPT_MAX_DOTS = 3000


def order_dots(
    dots: FloatArray,
    method: str,
    *,
    start_xz: FloatArray | None = None,
    spacing_m: float = SPREAD_SPACING_M,
) -> np.ndarray:
    """Indices of ``dots`` (N, 2) in painting order, shape (N,), ints.

    ``start_xz`` (2,) is where the drone comes from (the take-off point seen on the wall), used
    by ``shortest`` and ``spread``; ``None`` means ``(0, 0)``. ``spacing_m``: ``spread`` only.
    """
    start = np.zeros(2) if start_xz is None else np.asarray(start_xz, dtype=float)
    if method == "given":
        return np.arange(len(dots))
    if method == "paper":
        return paper_order(dots)
    if method == "shortest":
        first = int(np.argmin(np.linalg.norm(dots - start, axis=1)))
        return _tour(dots, np.arange(len(dots)), first)
    if method == "spread":
        return spread_order(dots, start, spacing_m)
    raise InputError(f"--order: got {method!r}, expected one of {', '.join(ORDERS)}")


def _tour(dots: FloatArray, among: np.ndarray, first: int) -> np.ndarray:
    """Nearest neighbour + 2-opt over ``dots[among]`` from ``among[first]``: indices into dots."""
    sub = dots[among]
    route = nearest_neighbour(sub, first)
    if len(sub) <= TWO_OPT_MAX_DOTS:
        route = two_opt(sub, route)
    out: np.ndarray = among[route]
    return out


def spread_order(dots: FloatArray, start_xz: FloatArray, spacing_m: float) -> np.ndarray:
    """The ``spread`` order: dots one ``spacing_m`` apart across the width, then a short tour."""
    lo, hi = float(dots[:, 0].min()), float(dots[:, 0].max())
    count = max(2, math.ceil((hi - lo) / spacing_m - 1e-9) + 1) if hi > lo else 1
    marks = np.linspace(lo, hi, count)
    if abs(start_xz[0] - hi) < abs(start_xz[0] - lo):
        marks = marks[::-1]  # sweep from the end nearer the start
    mid = 0.5 * float(dots[:, 1].min() + dots[:, 1].max())
    first: list[int] = []
    taken = np.zeros(len(dots), dtype=bool)
    for x in marks:
        cost = np.abs(dots[:, 0] - x) + 0.1 * np.abs(dots[:, 1] - mid)
        cost[taken] = np.inf
        k = int(np.argmin(cost))
        if np.isfinite(cost[k]):
            first.append(k)
            taken[k] = True
    rest = np.flatnonzero(~taken)
    if rest.size == 0:
        return np.array(first, dtype=int)
    last = dots[first[-1]]
    begin = int(np.argmin(np.linalg.norm(dots[rest] - last, axis=1)))
    return np.concatenate([np.array(first, dtype=int), _tour(dots, rest, begin)])


def paper_order(dots: FloatArray) -> np.ndarray:
    """Rows top to bottom, each right to left; rows one median spacing (>= 1 mm) high."""
    spacing = nearest_spacing(dots)
    if not np.isfinite(spacing):
        spacing = 1.0
    spacing = max(spacing, 1e-3)  # duplicate dots: rows of 1 mm, never a division by ~0
    top = dots[:, 1].max()
    row = np.floor((top - dots[:, 1]) / spacing + 0.5).astype(int)
    return np.lexsort((-dots[:, 0], row))


def nearest_neighbour(dots: FloatArray, first: int) -> np.ndarray:
    """Greedy tour from ``first``: always the nearest dot not yet painted, shape (N,)."""
    n = len(dots)
    left = np.ones(n, dtype=bool)
    route = np.empty(n, dtype=int)
    current = first
    for k in range(n):
        route[k] = current
        left[current] = False
        if k == n - 1:
            break
        d = np.linalg.norm(dots - dots[current], axis=1)
        d[~left] = np.inf
        current = int(np.argmin(d))
    return route


def two_opt(dots: FloatArray, route: np.ndarray, *, max_passes: int = 100) -> np.ndarray:
    """Open-path 2-opt with the first dot fixed: reverse ``route[i..j]`` while it shortens.

    For each ``i`` all ``j`` are scored at once; the best improving reversal is applied.
    """
    r = route.copy()
    n = len(r)
    if n < 4:
        return r
    for _ in range(max_passes):
        improved = False
        for i in range(1, n - 1):
            p = dots[r]
            a, b = p[i - 1], p[i]
            js = np.arange(i + 1, n)
            c = p[js]
            after = np.where((js + 1 < n)[:, None], p[np.minimum(js + 1, n - 1)], np.nan)
            old = np.linalg.norm(b - a) + np.nan_to_num(np.linalg.norm(after - c, axis=1))
            new = np.linalg.norm(c - a, axis=1) + np.nan_to_num(np.linalg.norm(after - b, axis=1))
            gain = old - new
            best = int(np.argmax(gain))
            if gain[best] > 1e-12:
                j = int(js[best])
                r[i : j + 1] = r[i : j + 1][::-1]
                improved = True
        if not improved:
            break
    return r


def path_length(dots: FloatArray, route: np.ndarray) -> float:
    """Length of the open path through ``dots[route]``, m."""
    p = dots[route]
    return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
