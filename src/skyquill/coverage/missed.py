"""What a covering path misses: the area, its share of the region, and where it lies."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from shapely.geometry.base import BaseGeometry

#: Gaps listed in a :class:`Missed` (the largest first).
MAX_GAPS = 10


@dataclass(frozen=True)
class Gap:
    """One connected piece of the region the swath missed.

    Attributes
    ----------
    area_m2 : float
        Its area, m².
    centroid : tuple of float
        ``(x, y)`` of its centroid, m (the region's frame).
    bounds : tuple of float
        ``(min_x, min_y, max_x, max_y)``, m.
    """

    area_m2: float
    centroid: tuple[float, float]
    bounds: tuple[float, float, float, float]


@dataclass(frozen=True)
class Missed:
    """The part of a region a covering path's swath does not reach.

    Attributes
    ----------
    area_m2 : float
        Missed area, m².
    fraction : float
        ``area_m2`` over the region's area (``1 - coverage``).
    gaps : tuple of Gap
        The :data:`MAX_GAPS` largest pieces, largest first.
    gap_count : int
        How many pieces there are in all.
    """

    area_m2: float
    fraction: float
    gaps: tuple[Gap, ...]
    gap_count: int

    def summary(self) -> dict[str, Any]:
        """JSON-ready: ``missed_area_m2``, ``missed_fraction``, ``gap_count``, ``gaps``."""
        return {
            "missed_area_m2": self.area_m2,
            "missed_fraction": self.fraction,
            "gap_count": self.gap_count,
            "gaps": [
                {"area_m2": g.area_m2, "centroid_m": list(g.centroid), "bounds_m": list(g.bounds)}
                for g in self.gaps
            ],
        }


def missed_area(region: BaseGeometry, swept: BaseGeometry) -> Missed:
    """What of ``region`` lies outside ``swept`` (:func:`~skyquill.coverage.regions.swept`)."""
    rest = region.difference(swept)
    pieces = [p for p in getattr(rest, "geoms", [rest]) if not p.is_empty and p.area > 0.0]
    pieces.sort(key=lambda p: p.area, reverse=True)
    gaps = tuple(
        Gap(
            area_m2=float(p.area),
            centroid=(float(p.centroid.x), float(p.centroid.y)),
            bounds=tuple(float(v) for v in p.bounds),  # type: ignore[arg-type]
        )
        for p in pieces[:MAX_GAPS]
    )
    area = float(rest.area)
    return Missed(area, area / float(region.area), gaps, len(pieces))
