"""The keep-out check: how close a flown trajectory comes to each hole, independent of the planner.

It takes nothing from the planner but the positions it flies and when the
spray is on: the vehicle must never be over a hole, and while spraying the
swath's footprint (a disc of half the swath around the vehicle) must not
reach into one. Samples are joined by straight lines and the distances are
exact for that polyline (shapely), so a dense sampling of the trajectory
(e.g. ``trajectory.csv`` as written) is checked between its samples too.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray
from shapely.geometry import Polygon
from shapely.geometry.base import BaseGeometry

from skyquill.errors import InputError
from skyquill.validation import FloatArray, as_array, as_float

#: Relative round-off allowed on the margin (of the margin).
MARGIN_TOLERANCE = 1e-6


@dataclass(frozen=True)
class HoleClearance:
    """How close the flight comes to one hole.

    Attributes
    ----------
    hole : int
        Index of the hole (from 0, in the order given to :func:`check_keepout`).
    centroid : tuple of float
        ``(x, y)`` of the hole's centroid, m (to tell the holes apart on a map).
    closest_m : float
        Smallest distance from the vehicle to the hole, m (0: it flew over it).
    closest_spraying_m : float or None
        Smallest distance while spraying, m; ``None`` if it never sprays.
    """

    hole: int
    centroid: tuple[float, float]
    closest_m: float
    closest_spraying_m: float | None


@dataclass(frozen=True)
class KeepoutCheck:
    """The verdict of :func:`check_keepout`.

    Attributes
    ----------
    margin_m : float
        Half the swath: the least distance to a hole while spraying, m.
    holes : tuple of HoleClearance
        One per hole.
    passed : bool
        Whether the vehicle stays off every hole and, while spraying, at least
        ``margin_m`` from each.
    """

    margin_m: float
    holes: tuple[HoleClearance, ...]
    passed: bool

    def summary(self) -> dict[str, Any]:
        """JSON-ready: the margin, the verdict and each hole's closest approaches (m)."""
        return {
            "margin_m": self.margin_m,
            "passed": self.passed,
            "holes": [
                {
                    "hole": h.hole,
                    "centroid_m": list(h.centroid),
                    "closest_m": h.closest_m,
                    "closest_spraying_m": h.closest_spraying_m,
                }
                for h in self.holes
            ],
        }


def check_keepout(
    positions: Any, spraying: Any, holes: list[Polygon], margin: float
) -> KeepoutCheck:
    """Check a sampled flight against keep-out zones.

    Parameters
    ----------
    positions
        Vehicle positions ``(N, 2)`` or ``(N, 3)`` in flight order, m (z ignored).
    spraying
        ``(N,)`` truthy where the spray is on (e.g. ``trajectory.csv``'s ``pen``).
    holes
        Keep-out zones (m).
    margin
        Least distance from a hole while spraying (half the swath), m, >= 0.

    Returns
    -------
    KeepoutCheck

    Raises
    ------
    InputError
        If the shapes do not match or ``margin`` is negative.
    """
    p = as_array("positions", positions, ndim=2)
    if p.shape[1] not in (2, 3) or len(p) < 1:
        raise InputError(f"positions: got shape {p.shape}, expected (N >= 1, 2 or 3)")
    on = np.asarray(spraying).astype(bool)
    if on.shape != (len(p),):
        raise InputError(f"spraying: got shape {on.shape}, expected ({len(p)},)")
    m = as_float("margin", margin)
    if m < 0.0:
        raise InputError(f"margin: got {m:g} m, expected >= 0")
    flight = _polyline(p[:, :2])
    sprayed = [_polyline(p[run, :2]) for run in _runs(on)]
    clearances = []
    for k, hole in enumerate(holes):
        near = float(shapely.distance(flight, hole))
        spray = min((float(shapely.distance(g, hole)) for g in sprayed), default=None)
        centre = (float(hole.centroid.x), float(hole.centroid.y))
        clearances.append(HoleClearance(k, centre, near, spray))
    passed = all(
        h.closest_m > 0.0
        and (h.closest_spraying_m is None or h.closest_spraying_m >= m * (1 - MARGIN_TOLERANCE))
        for h in clearances
    )
    return KeepoutCheck(m, tuple(clearances), passed)


def _polyline(points: FloatArray) -> BaseGeometry:
    return shapely.points(points[0]) if len(points) == 1 else shapely.linestrings(points)


def _runs(on: NDArray[np.bool_]) -> list[slice]:
    """Slices of consecutive ``True`` entries."""
    edges = np.diff(np.concatenate([[0], on.astype(np.int8), [0]]))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    return [slice(int(a), int(b)) for a, b in zip(starts, stops, strict=True)]
