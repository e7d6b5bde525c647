"""A formation stepped out of its plane into depth layers, so that its points are farther apart.

Synchronised straight moves with the minimum-squared-distance assignment keep two
drones at least ``1/sqrt(2)`` of the smaller of the two formations' spacings apart
(CAPT: Turpin, Michael & Kumar, IJRR 2014): formations ``sqrt(2)`` times the safety
distance apart need no delays at all. A formation on a plane that is tighter than
that can be made as loose without moving any point within the plane: points closer
than ``sqrt(2) d`` are coloured apart (a greedy colouring of the graph of close
pairs) and each colour is stepped out along the plane's normal to its own layer. Two
points of one colour were already ``sqrt(2) d`` apart; two of different colours,
at least ``rho`` apart in the plane (the formation's spacing) and ``h`` apart along
the normal, are ``sqrt(rho^2 + h^2)`` apart, so layers ``h = sqrt(2 d^2 - rho^2)``
apart suffice.

Stepping out and back in is safe whatever the timing: every drone moves along the
one normal, so the part of two drones' separation within the plane, at least the
formation's spacing, never changes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from skyquill.validation import FloatArray

#: Largest distance of a point from its formation's plane that still counts as on it, m.
PLANE_TOLERANCE_M = 1e-6
#: Relative margin of the layers' distance over the one that is just enough.
LAYER_MARGIN = 1e-5
#: A plane whose normal is this close to vertical is horizontal: its layers go up only
#: (never below the formation, towards the ground).
HORIZONTAL = 0.9

IntArray = NDArray[np.intp]


@dataclass(frozen=True)
class Layers:
    """Points of a formation, stepped out of its plane.

    Attributes
    ----------
    points
        The stepped-out points (N, 3), m.
    depth
        Each point's layer (N,): its step along the normal in units of ``step_m``
        (0: stays in the plane; half steps when the layers are centred on it).
    normal
        The plane's unit normal (3,).
    step_m
        Distance between two neighbouring layers, m (0 when no point steps out).
    """

    points: FloatArray
    depth: FloatArray
    normal: FloatArray
    step_m: float

    @property
    def moved(self) -> bool:
        """Whether any point steps out."""
        return bool(np.any(self.depth != 0))


def spacing(points: FloatArray) -> float:
    """The smallest distance between two of ``points`` (N, 3), m; ``inf`` for one point."""
    if len(points) < 2:
        return math.inf
    distance = np.asarray(cKDTree(points).query(points, k=2)[0])
    return float(distance[:, 1].min())


def plane_normal(points: FloatArray) -> FloatArray | None:
    """The unit normal of the plane that holds ``points``, or ``None`` if none does.

    The normal points up for a horizontal plane and towards +y otherwise (so that
    layer -1 is in front of a formation facing -y).
    """
    centred = points - points.mean(axis=0)
    _, _, vt = np.linalg.svd(centred, full_matrices=True)
    normal = vt[-1]
    if len(points) > 2 and np.abs(centred @ normal).max() > PLANE_TOLERANCE_M:
        return None
    axis = 2 if abs(normal[2]) >= HORIZONTAL else 1
    if normal[axis] < 0.0 or (normal[axis] == 0.0 and normal.sum() < 0.0):
        normal = -normal
    return np.asarray(normal, dtype=float)


def colour_close(points: FloatArray, distance_m: float) -> IntArray:
    """A greedy colouring of the points closer than ``distance_m``: most neighbours first (N,)."""
    n = len(points)
    pairs = cKDTree(points).query_pairs(distance_m, output_type="ndarray")
    neighbours: list[list[int]] = [[] for _ in range(n)]
    for i, j in pairs.tolist():
        neighbours[i].append(j)
        neighbours[j].append(i)
    colour = np.full(n, -1, dtype=np.intp)
    for k in np.argsort([-len(v) for v in neighbours], kind="stable").tolist():
        taken = {int(colour[m]) for m in neighbours[k]}
        colour[k] = next(c for c in range(n + 1) if c not in taken)
    return colour


def step_out(points: FloatArray, spread_m: float) -> Layers | None:
    """``points`` stepped into layers along their plane's normal, at least ``spread_m`` apart.

    Returns the points themselves (depth 0) when they are already that far apart,
    and ``None`` when they are not and do not lie on one plane.
    """
    tight = spacing(points)
    zero = np.zeros(len(points))
    normal = plane_normal(points)
    if tight >= spread_m:
        return Layers(points, zero, np.array([0.0, 1.0, 0.0]) if normal is None else normal, 0.0)
    if normal is None:
        return None
    colour = colour_close(points, spread_m)
    depth = layer_depths(int(colour.max()) + 1, upward=abs(normal[2]) >= HORIZONTAL)[colour]
    step = math.sqrt(max(spread_m**2 - tight**2, 0.0)) * (1.0 + LAYER_MARGIN)
    layered = points + (depth * step)[:, None] * normal
    if spacing(layered) < spread_m:
        return None
    return Layers(layered, depth, normal, step)


def layer_depths(count: int, *, upward: bool) -> FloatArray:
    """The depth of each of ``count`` layers, in steps, the first (the most points) nearest 0.

    Layers of a horizontal formation go up only (0, 1, 2, ...: never towards the
    ground); those of a vertical one are centred on it, so that no drone steps
    farther than it must (two layers: half a step in front, half behind; three: in
    front, on the plane, behind).
    """
    if upward:
        return np.arange(count, dtype=float)
    centred = np.arange(count) - (count - 1) / 2.0
    return np.asarray(sorted(centred.tolist(), key=lambda x: (abs(x), x)), dtype=float)
