"""The order the dots are painted in.

* ``given`` -- the file's order.
* ``paper`` -- paper 002 §4.1: "from the right to the left and from the top to the bottom".
  Dots are grouped in rows one median dot spacing high (a stippled picture has no exact rows)
  and each row is painted right to left.
* ``shortest`` -- a short open tour over the dots, starting from the dot nearest the take-off
  point: nearest neighbour, then 2-opt (segment reversals) until no reversal shortens it. The
  flight between two dots is a straight transit between their waiting points, which lie on a
  copy of the drawing moved off the wall, so the distance between dots is the transit length.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from skyquill.errors import InputError
from skyquill.painting.dots import nearest_spacing
from skyquill.validation import FloatArray

OrderName = Literal["given", "paper", "shortest"]
ORDERS: tuple[OrderName, ...] = ("given", "paper", "shortest")
#: Above this many dots 2-opt (O(N^2) per pass) is skipped; nearest neighbour alone is used.
TWO_OPT_MAX_DOTS = 3000


def order_dots(dots: FloatArray, method: str, *, start_xz: FloatArray | None = None) -> np.ndarray:
    """Indices of ``dots`` (N, 2) in painting order, shape (N,), ints.

    ``start_xz`` (2,) is where the drone comes from (the take-off point seen on the wall), used
    by ``shortest`` only; ``None`` means ``(0, 0)``.
    """
    if method == "given":
        return np.arange(len(dots))
    if method == "paper":
        return paper_order(dots)
    if method == "shortest":
        start = np.zeros(2) if start_xz is None else start_xz
        first = int(np.argmin(np.linalg.norm(dots - start, axis=1)))
        route = nearest_neighbour(dots, first)
        return two_opt(dots, route) if len(dots) <= TWO_OPT_MAX_DOTS else route
    raise InputError(f"--order: got {method!r}, expected one of {', '.join(ORDERS)}")


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
