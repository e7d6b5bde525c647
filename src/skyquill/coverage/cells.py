"""Large pieces, split into cells that each plan quickly and fly well.

A covering path is timed on a speed grid of at most
:data:`~skyquill.coverage.plan.covering.GRID_POINTS` points whatever its length: on a
25 km path the nodes are 12 m apart, ten times a corner's rounding, and the plan flies
slower than its limits allow (on the 1 ha square's spiral: 846 s of flight with nodes
4 m apart, 707 s at 0.25 m). One speed plan of a long path is also one long serial
computation. So a piece whose path would be longer than one plan's cap
(:data:`~skyquill.coverage.regions.MAX_PATH_LENGTH_M`) is cut into a lattice of equal
rectangular cells of at most :data:`CELL_PATH_M` of path each, aligned with the piece's
minimum rotated rectangle, as a boustrophedon or grid decomposition does (Fields2Cover
splits a field into cells the same way): the cells are planned at once (one process per
core, or on a dask cluster), the interior ones are copies of each other and planned once
(:mod:`skyquill.coverage.congruent`), and the mission joins them as it joins the pieces
round the holes.
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from shapely.geometry import Polygon

from skyquill.coverage.regions import (
    MAX_MISSION_PATH_M,
    MAX_PATH_LENGTH_M,
    Region,
    estimate_path_length,
)

#: Longest estimated path of one cell, m (at a spacing of one swath): about 5 ha at a 5 m
#: swath, 10 ha at 10 m. Measured on the 100 ha field at a 10 m swath (2 workers), cells
#: of 2.5 / 5 / 10 / 20 km: planned in 24 / 23 / 27 / 30 s, flights of 42,286 / 40,793 /
#: 39,376 / 39,106 s. Smaller cells plan no faster (each speed plan has the same grid) and
#: add transits and laps; larger ones are long serial computations.
CELL_PATH_M = 10_000.0
#: Narrowest line spacing at which a path too long for one plan is planned in pieces, m: a
#: cell of :data:`CELL_PATH_M` then holds at most 100 lanes or rings across (its side is
#: about ``sqrt(CELL_PATH_M * spacing)``).
#: Narrower spacings over regions this large are held to one path's cap: a 10 m square at
#: a 1 mm swath would be 10 cells of 1,500 rings each.
MIN_CELL_SPACING_M = 1.0
#: Grid the cells are snapped to, as a fraction of the piece's length.
_SNAP = 1e-12
#: Cells below this fraction of the piece's area are round-off slivers of the clipping.
_SLIVER = 1e-9


def too_long_for_one_plan(region: Region, spacing: float) -> bool:
    """Whether ``region``'s path at ``spacing`` (m) is too long to plan as one (longer than
    :data:`~skyquill.coverage.regions.MAX_PATH_LENGTH_M`, estimated), at a spacing of at
    least :data:`MIN_CELL_SPACING_M`: then it is planned as a mission of pieces within that
    cap (its pieces round holes and their convex parts, cut into cells where one is still
    over it)."""
    return (
        spacing >= MIN_CELL_SPACING_M and estimate_path_length(region, spacing) > MAX_PATH_LENGTH_M
    )


def path_cap(region: Region, spacing: float) -> float:
    """The longest path accepted for ``region`` at ``spacing`` (m), m: a mission's
    (:data:`~skyquill.coverage.regions.MAX_MISSION_PATH_M`) when it is too long for one
    plan, else one plan's."""
    return MAX_MISSION_PATH_M if too_long_for_one_plan(region, spacing) else MAX_PATH_LENGTH_M


def split_into_cells(piece: Polygon, spacing: float) -> list[Polygon]:
    """``piece`` itself, or near-square cells of paths of at most :data:`CELL_PATH_M` each
    when its path is too long to plan as one (:func:`too_long_for_one_plan`).

    Parameters
    ----------
    piece
        A hole-free polygon (m).
    spacing
        Distance between the covering path's lines, m (the swath: the cells' planners
        may space their lines closer, and the cells are well below the single path's cap).

    Returns
    -------
    list of shapely.geometry.Polygon
        ``[piece]`` when its own path is short enough; else the piece cut by a lattice
        of ``nu x nv`` equal rectangles in the frame of its minimum rotated rectangle,
        row by row (boustrophedon order). Cut from a convex piece, every cell is convex.
    """
    if not too_long_for_one_plan(piece, spacing):
        return [piece]
    origin, axes, lengths = _frame(piece)
    nu, nv = _lattice(lengths, spacing, CELL_PATH_M)
    su, sv = lengths[0] / nu, lengths[1] / nv
    boxes = []
    for j in range(nv):
        columns = range(nu) if j % 2 == 0 else range(nu - 1, -1, -1)
        for i in columns:
            corners = np.array([[i, j], [i + 1, j], [i + 1, j + 1], [i, j + 1]], dtype=float)
            corners *= [su, sv]
            boxes.append(Polygon(origin + corners @ axes))
    # Snap-rounded on a grid far below the cells' size: the plain overlay can misplace a
    # vertex by metres when the piece has one of 1e-23 next to ones of 1e2 (hypothesis).
    grid = _SNAP * float(lengths[0])
    clipped = shapely.intersection(np.array(boxes, dtype=object), piece, grid_size=grid)
    cells: list[Polygon] = []
    for geometry in clipped:
        for part in getattr(geometry, "geoms", [geometry]):
            if isinstance(part, Polygon) and part.area > _SLIVER * piece.area:
                cells.append(shapely.normalize(part))
    return cells


def _frame(piece: Polygon) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The piece's minimum rotated rectangle: a corner (2,), its unit sides (2, 2) as rows,
    the longer first, and their lengths (2,), m."""
    rect = np.asarray(piece.minimum_rotated_rectangle.exterior.coords, dtype=float)[:4]
    sides = np.diff(np.vstack([rect, rect[:1]]), axis=0)[:2]
    lengths = np.linalg.norm(sides, axis=1)
    order = np.argsort(-lengths)
    corner = rect[0] if order[0] == 0 else rect[1]
    axes = sides[order] / lengths[order, None]
    if order[0] == 1:  # the longer side starts at rect[1]; the shorter one then runs back
        axes[1] = -axes[1]
    return corner, axes, lengths[order]


def _lattice(lengths: np.ndarray, spacing: float, max_path_m: float) -> tuple[int, int]:
    """Cells along the rectangle's two sides (``lengths``, m) so that a full cell's path
    (area over ``spacing`` plus perimeter) is at most ``max_path_m``, the cells near square."""
    side = _square_side(spacing, max_path_m)
    nu = max(1, math.ceil(lengths[0] / side))
    nv = max(1, math.ceil(lengths[1] / side))
    return nu, nv


def _square_side(spacing: float, max_path_m: float) -> float:
    """The side ``s`` of a square whose path ``s**2 / spacing + 4 s`` is ``max_path_m``, m."""
    return -2.0 * spacing + math.sqrt(4.0 * spacing**2 + spacing * max_path_m)
