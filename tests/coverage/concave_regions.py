"""Concave test regions and checks shared by the partition, order and joined-path tests."""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry import Polygon

from skyquill.coverage.regions import region_from_vertices

L_SHAPE = region_from_vertices([[0, 0], [12, 0], [12, 4], [4, 4], [4, 12], [0, 12]])
U_SHAPE = region_from_vertices(
    [[0, 0], [15, 0], [15, 12], [11, 12], [11, 4], [4, 4], [4, 12], [0, 12]]
)
FIELD = region_from_vertices(
    [[0, 0], [14, -2], [21, 3], [15, 8], [18, 16], [9, 19], [2, 14], [-1, 6]]
)
_ANGLES = np.arange(10) * np.pi / 5
STAR = region_from_vertices(
    np.c_[np.cos(_ANGLES), np.sin(_ANGLES)] * np.where(np.arange(10) % 2 == 0, 12.0, 6.0)[:, None]
)
CONCAVE = {"L": L_SHAPE, "U": U_SHAPE, "field": FIELD, "star": STAR}
WIDTH = 2.0


def is_convex(part: Polygon) -> bool:
    """Whether ``part`` equals its convex hull (to round-off)."""
    return bool(part.convex_hull.area - part.area <= 1e-9 * part.area)


def union_error(region: Polygon, parts: list[Polygon]) -> float:
    """Area of the symmetric difference of ``region`` and the union of ``parts``, relative."""
    return float(region.symmetric_difference(shapely.union_all(parts)).area / region.area)
