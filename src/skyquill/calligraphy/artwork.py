"""Many drones on one artwork: a grid of sky boards, or one drawing split among drones.

Two ways to share a light painting (issue 18, part 2):

* **A grid**: one character (or word) per drone, each on its own sky board,
  the boards laid out in rows and columns on one plane in the sky
  (:func:`grid_shape`, :func:`sky_grid`), the homes on the ground in front.
* **A split** (``--split strokes``): one drawing on one sky board, its strokes
  shared among the drones (:func:`split_strokes`): ordered along the drawing's
  longer side and cut into contiguous bands of about equal flight time, so
  every drone's flight takes about as long and neighbours work in different
  bands; each drone sweeps its band in the same direction, so neighbours move
  alike at about the same pace and stay about a band apart (for light the
  order of the strokes does not show in the picture). Whether they stay far
  enough apart is then decided by the guaranteed separation check
  (:func:`~skyquill.calligraphy.mission.check_separation`).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from skyquill.calligraphy.board import Board, sky_board
from skyquill.calligraphy.options import WritingOptions
from skyquill.calligraphy.route import densify
from skyquill.calligraphy.timing import route_times
from skyquill.errors import InputError
from skyquill.strokes import Strokes
from skyquill.validation import FloatArray, as_float, as_int

#: Extra room between boards beyond the required separation, m (as
#: :data:`skyquill.calligraphy.show.BOARD_MARGIN_M`: the smoothed path's
#: overshoot at stroke ends).
GRID_MARGIN_M = 0.25
#: Homes stand this far in front of the nearest part of the artwork, m.
HOME_DISTANCE_M = 1.0


def grid_shape(n: int, grid: tuple[int, int] | None = None) -> tuple[int, int]:
    """Rows and columns for ``n`` boards: ``grid`` checked, or the most nearly square.

    Automatic: ``columns = ceil(sqrt(n))``, ``rows = ceil(n / columns)`` (20 ->
    4 x 5, 100 -> 10 x 10); the last row may be short.

    Raises
    ------
    InputError
        ``grid`` not two positive integers, or with fewer cells than ``n``.
    """
    n = as_int("drones", n, low=1)
    if grid is None:
        columns = math.ceil(math.sqrt(n))
        return math.ceil(n / columns), columns
    if len(grid) != 2:
        raise InputError(f"grid: got {grid!r}, expected (rows, columns)")
    rows, columns = as_int("grid rows", grid[0], low=1), as_int("grid columns", grid[1], low=1)
    if rows * columns < n:
        raise InputError(
            f"grid: got {rows}x{columns} = {rows * columns} cells for {n} drones, expected "
            "at least one cell per drone"
        )
    return rows, columns


def sky_grid(
    n: int,
    size_m: float,
    separation_m: float,
    *,
    height_m: float = 1.0,
    yaw_deg: float = 0.0,
    tilt_deg: float = 0.0,
    grid: tuple[int, int] | None = None,
) -> list[tuple[Board, FloatArray]]:
    """``n`` sky boards in a grid on one plane, and each drone's home (3,), m.

    Board ``i`` is in row ``i // columns`` (row 0 on top: the text reads left to
    right, top to bottom) and column ``i % columns``, its bottom-left corner at
    ``c pitch e_u + (rows - 1 - r) pitch e_v`` from the grid's, which is at
    height ``height_m``; ``pitch = size + separation + GRID_MARGIN_M``. Homes
    are on the ground in front, below each column, in rows ``pitch`` apart:
    the bottom row's drones nearest, so a drone bound for a higher board climbs
    and crosses in front of the lower ones above their boards' height (at least
    ``pitch - size`` above them), never through them.
    """
    rows, columns = grid_shape(n, grid)
    size = as_float("size_m", size_m, positive=True)
    pitch = size + as_float("separation_m", separation_m, positive=True) + GRID_MARGIN_M
    base = sky_board(np.array([0.0, 0.0, as_float("board_height_m", height_m)]), yaw_deg, tilt_deg)
    e_u, e_v, _ = base.axes
    facing = _facing(base)
    overhang = _overhang(base, rows * pitch)  # homes clear a forward lean's top
    out = []
    for i in range(n):
        r, c = divmod(i, columns)
        up = rows - 1 - r
        origin = base.origin + c * pitch * e_u + up * pitch * e_v
        ahead = HOME_DISTANCE_M + overhang + up * pitch
        home = (c * pitch + 0.5 * size) * e_u + ahead * facing
        out.append((sky_board(origin, yaw_deg, tilt_deg), np.array([home[0], home[1], 0.0])))
    return out


@dataclass(frozen=True)
class Split:
    """One drawing's strokes shared among drones.

    Attributes
    ----------
    parts
        What each drone writes: its strokes in flight order, each part with
        the whole drawing's layout box (so all are scaled and placed alike).
    strokes
        Indices into the drawing's strokes, per drone.
    estimated_s
        Each drone's estimated writing time (strokes and the moves between
        them, without the legs from and to home), s.
    """

    parts: tuple[Strokes, ...]
    strokes: tuple[tuple[int, ...], ...]
    estimated_s: tuple[float, ...]

    @property
    def balance(self) -> float:
        """Longest over shortest estimated writing time (1 is perfect)."""
        return max(self.estimated_s) / min(self.estimated_s)


def split_strokes(drawing: Strokes, n: int, board: Board, options: WritingOptions) -> Split:
    """Share ``drawing``'s strokes among ``n`` drones writing it on ``board``.

    Each stroke's time is estimated as it will be flown (:func:`route_times` of
    the stroke at ``options.size_m``), and each move between two strokes as a
    rest-to-rest straight move at the timing's speed and acceleration. The
    strokes are ordered by their centre along the drawing's longer side and
    the order is cut into ``n`` contiguous bands whose largest time is the
    least possible (binary search on it with a greedy cut); each drone flies
    its band's strokes in that order, a sweep along the band (module docstring).

    Raises
    ------
    InputError
        ``n`` not an integer >= 1, or more drones than strokes.
    """
    n = as_int("drones", n, low=1)
    count = drawing.n_strokes
    if n > count:
        raise InputError(
            f"drones: got {n} drones for a drawing of {count} strokes, expected at most one "
            "drone per stroke (--split strokes)"
        )
    scaled = drawing.scaled(options.size_m)
    world = [board.to_world(p) for p in scaled.paths]
    lo, hi = scaled.bounds()
    axis = int(np.argmax(hi - lo))
    order = sorted(range(count), key=lambda i: float(np.mean(scaled.paths[i][:, axis])))
    stroke_s = np.array([_stroke_time(world[i], board, options) for i in order])
    move_s = np.array(
        [_move_time(world[a][-1], world[b][0], options) for a, b in itertools.pairwise(order)]
    )
    groups = _bands(stroke_s, move_s, n)
    parts, members, estimates = [], [], []
    for first, stop in groups:
        chosen = tuple(order[first:stop])
        members.append(chosen)
        estimates.append(float(stroke_s[first:stop].sum() + move_s[first : stop - 1].sum()))
        parts.append(
            Strokes(
                paths=tuple(drawing.paths[i] for i in chosen),
                source=f"{drawing.source or 'drawing'}, strokes {', '.join(map(str, chosen))}",
                box=np.stack(drawing.bounds()),
            )
        )
    return Split(tuple(parts), tuple(members), tuple(estimates))


def _stroke_time(stroke_W: FloatArray, board: Board, options: WritingOptions) -> float:
    """How long ``stroke_W`` (K, 3) takes, rest to rest, as :func:`route_times` times it."""
    points = densify(stroke_W)
    return float(route_times(points, np.zeros(len(points)), board, options)[-1])


def _move_time(a: FloatArray, b: FloatArray, options: WritingOptions) -> float:
    """A rest-to-rest straight move from ``a`` to ``b`` at the route's speed and
    half the acceleration (:func:`route_times`' share off the tip), s."""
    vmax, amax = options.limits.timing_bounds()
    accel = 0.5 * amax
    d = float(np.linalg.norm(b - a))
    if d <= vmax**2 / accel:  # never reaches full speed
        return 2.0 * math.sqrt(d / accel)
    return d / vmax + vmax / accel


def _bands(stroke_s: FloatArray, move_s: FloatArray, n: int) -> list[tuple[int, int]]:
    """``n`` contiguous ``[first, stop)`` groups of the strokes minimising the longest."""
    lo, hi = float(stroke_s.max()), float(stroke_s.sum() + move_s.sum())
    for _ in range(60):  # bisection on the longest band's time, to ~1e-18 of the range
        mid = 0.5 * (lo + hi)
        if len(_greedy(stroke_s, move_s, mid)) <= n:
            hi = mid
        else:
            lo = mid
    groups = _greedy(stroke_s, move_s, hi)
    while len(groups) < n:  # fewer bands than drones: halve the longest (never longer)
        k = max(
            (j for j, (a, b) in enumerate(groups) if b - a > 1),
            key=lambda j: _cost(stroke_s, move_s, *groups[j]),
        )
        a, b = groups[k]
        groups[k : k + 1] = [(a, a + (b - a) // 2), (a + (b - a) // 2, b)]
    return groups


def _greedy(stroke_s: FloatArray, move_s: FloatArray, limit: float) -> list[tuple[int, int]]:
    """Bands of at most ``limit`` s (a stroke longer alone is a band), each as long as it can be."""
    groups, first = [], 0
    while first < len(stroke_s):
        stop = first + 1
        while stop < len(stroke_s) and _cost(stroke_s, move_s, first, stop + 1) <= limit:
            stop += 1
        groups.append((first, stop))
        first = stop
    return groups


def _cost(stroke_s: FloatArray, move_s: FloatArray, first: int, stop: int) -> float:
    return float(stroke_s[first:stop].sum() + move_s[first : stop - 1].sum())


def split_homes(split: Split, board: Board, size_m: float, separation_m: float) -> list[FloatArray]:
    """Homes (3,) on the ground in front of ``board``, one per part of ``split``.

    Each below its band's centre along the board's ``e_u``, pushed apart (in
    that order) to at least ``separation + GRID_MARGIN_M`` from the previous
    one, the row re-centred on the bands; :data:`HOME_DISTANCE_M` in front.
    """
    gap = as_float("separation_m", separation_m, positive=True) + GRID_MARGIN_M
    centres = np.array(
        [float(np.concatenate(p.scaled(size_m).paths)[:, 0].mean()) for p in split.parts]
    )
    u, last = np.empty(len(centres)), -math.inf
    for k in np.argsort(centres, kind="stable"):
        u[k] = last = max(float(centres[k]), last + gap)
    u += centres.mean() - u.mean()
    ahead = HOME_DISTANCE_M + _overhang(board, size_m)
    homes = board.origin + np.outer(u, board.axes[0]) + ahead * _facing(board)
    homes[:, 2] = 0.0
    return list(homes)


def _facing(board: Board) -> FloatArray:
    """The horizontal unit vector from a sky board towards its audience (3,)."""
    yaw = math.radians(board.yaw_deg)
    return np.array([math.sin(yaw), -math.cos(yaw), 0.0])


def _overhang(board: Board, height_m: float) -> float:
    """How far a board leaning forward reaches in front of its bottom edge at
    ``height_m`` up along it, m (0 leaning back)."""
    return max(0.0, float(height_m * board.axes[1] @ _facing(board)))
