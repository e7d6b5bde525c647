"""How well a writing plan writes: its distance from the strokes, and the ink it leaves.

The brush hangs along the thrust axis, so its tip swings as the vehicle tilts:
it is at ``P + L (e_z - b3)`` for the untilted tip ``P`` (:func:`swung_tip`).
:func:`measure_deviation` compares a pen-down path with the strokes (in 3-D, or
in the board's plane); :func:`planned_ink` finds where the swung tip touches
the board over the whole flight and compares those runs of contact -- the ink
the plan leaves -- with the strokes (:class:`Contact`). The simulated ink is
measured by :mod:`skyquill.calligraphy.ink`.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.brush import Brush
from skyquill.geometry import polyline_distances
from skyquill.io.trajectory_json import pen_down
from skyquill.trajectory import Trajectory
from skyquill.validation import FloatArray

#: Sampling step of the planned ink (:func:`planned_ink`), s: 4 mm at 1 m/s
#: (distances are to the polyline through the samples).
INK_SAMPLE_S = 0.004

GRAVITY = 9.81  # m/s^2


@dataclass(frozen=True)
class Deviation:
    """Two-sided distance between the pen-down path and the input strokes, m.

    ``max_m`` is the Hausdorff distance: the larger of the two one-sided maxima.
    """

    path_to_input_max_m: float
    input_to_path_max_m: float
    mean_m: float

    @property
    def max_m(self) -> float:
        """Largest of both one-sided distances (the Hausdorff distance), m."""
        return max(self.path_to_input_max_m, self.input_to_path_max_m)

    def as_dict(self) -> dict[str, float]:
        """``summary.json`` form."""
        return {
            "max_m": self.max_m,
            "mean_m": self.mean_m,
            "hausdorff_m": self.max_m,
            "path_to_input_max_m": self.path_to_input_max_m,
            "input_to_path_max_m": self.input_to_path_max_m,
        }


@dataclass(frozen=True)
class Contact:
    """The swung brush tip against the board (``follow="tip"``): the ink the plan leaves.

    Attributes
    ----------
    min_depth_m, max_depth_m
        The shallowest press while the pen is down and the deepest anywhere,
        m (positive: into the board; the shallowest is at a touch-down or a
        lift-off).
    clearance_m
        The least, over the pen-up gaps, of the highest the tip rises, m.
    travel_m
        The brush bearing's travel, m.
    ink_strokes, strokes
        Runs of contact, and input strokes.
    """

    min_depth_m: float
    max_depth_m: float
    clearance_m: float
    travel_m: float
    ink_strokes: int
    strokes: int

    @property
    def holds(self) -> bool:
        """One ink stroke per input stroke, pressed within the bearing's travel."""
        return self.ink_strokes == self.strokes and self.max_depth_m <= self.travel_m

    def as_dict(self) -> dict[str, float | int | bool]:
        """``summary.json`` form."""
        return {
            "min_depth_m": self.min_depth_m,
            "max_depth_m": self.max_depth_m,
            "clearance_m": self.clearance_m,
            "travel_m": self.travel_m,
            "ink_strokes": self.ink_strokes,
            "strokes": self.strokes,
            "holds": self.holds,
        }


def swung_tip(traj: Trajectory, t: FloatArray, brush_length_m: float) -> FloatArray:
    """Where the hanging brush's tip really is (N, 3): ``P + L (e_z - b3)``.

    ``P`` is the planned (untilted) tip, ``b3`` the thrust direction the
    acceleration demands, ``(a + g e_z) / |a + g e_z|``.
    """
    return swung_tip_of(traj.evaluate(t), traj.evaluate(t, 2), brush_length_m)


def swung_tip_of(
    position: FloatArray, acceleration: FloatArray, brush_length_m: float
) -> FloatArray:
    """:func:`swung_tip` from the planned tip's positions and accelerations (N, 3)."""
    thrust = acceleration + np.array([0.0, 0.0, GRAVITY])
    b3 = thrust / np.linalg.norm(thrust, axis=1, keepdims=True)
    return np.asarray(position + brush_length_m * (np.array([0.0, 0.0, 1.0]) - b3))


def planned_ink(
    traj: Trajectory,
    windows: tuple[tuple[float, float], ...],
    strokes_world: tuple[FloatArray, ...],
    board: Board,
    *,
    brush: Brush,
    size_m: float,
) -> tuple[Deviation, Contact]:
    """The ink the swung tip leaves where it touches the board, against the strokes.

    The tip is sampled every :data:`INK_SAMPLE_S` over the whole flight; each
    run of samples on the board (below its surface, above its underside, over
    it: :func:`on_board`) is one ink stroke. When there are as
    many as input strokes, the ``i``-th is measured against stroke ``i`` (in
    the board's plane, two-sided): a touch-down a little late or a lift-off a
    little early costs what it leaves out, no more. Otherwise the pen windows
    are measured as they are (and the contact does not hold).
    """
    t = np.linspace(0.0, traj.duration, max(2, math.ceil(traj.duration / INK_SAMPLE_S) + 1))
    tip = board.to_board(swung_tip(traj, t, brush.length_m))
    depth = -tip[:, 2]
    runs = contact_runs(on_board(tip, size_m))
    pen = pen_down(t, windows) > 0.0
    contact = Contact(
        min_depth_m=float(depth[pen].min()) if np.any(pen) else 0.0,
        max_depth_m=float(max((depth[a:b].max() for a, b in runs), default=0.0)),
        clearance_m=_clearance(t, -depth, windows, traj.duration),
        travel_m=brush.travel_m,
        ink_strokes=len(runs),
        strokes=len(strokes_world),
    )
    if len(runs) != len(strokes_world):
        length = brush.length_m
        return measure_deviation(traj, windows, strokes_world, length, plane=board), contact
    flat = tuple(board.to_board(s)[:, :2] for s in strokes_world)
    return _two_sided([tip[a:b, :2] for a, b in runs], list(flat)), contact


def on_board(local: FloatArray, size_m: float) -> NDArray[np.bool_]:
    """Which tip positions ``(u, v, height)`` (N, 3), board frame, m, touch the board.

    The board as the simulator has it
    (:func:`~skyquill.calligraphy.mission.contact_board`): the
    character's square ``size_m`` wide, :data:`BOARD_MARGIN_M` more on every
    side, a slab :data:`BOARD_THICKNESS_M` thick.
    """
    lo, hi = -BOARD_MARGIN_M, size_m + BOARD_MARGIN_M
    over = np.all((local[:, :2] >= lo) & (local[:, :2] <= hi), axis=1)
    return np.asarray(over & (local[:, 2] < 0.0) & (local[:, 2] >= -BOARD_THICKNESS_M))


def contact_runs(mask: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """``[start, stop)`` of every run of True in ``mask`` (N,)."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    starts, stops = np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist()
    return list(zip(starts, stops, strict=True))


def _clearance(
    t: FloatArray, height: FloatArray, windows: tuple[tuple[float, float], ...], end: float
) -> float:
    """The least, over the pen-up gaps (and before the first and after the last
    window), of the highest the tip rises in the gap, m."""
    edges = [0.0, *itertools.chain.from_iterable(windows), end]
    highest = []
    for a, b in zip(edges[::2], edges[1::2], strict=True):
        inside = (t >= a) & (t <= b)
        highest.append(float(height[inside].max()) if np.any(inside) else -math.inf)
    return min(highest)


def measure_deviation(
    traj: Trajectory,
    windows: tuple[tuple[float, float], ...],
    strokes_world: tuple[FloatArray, ...],
    brush_length_m: float = 0.0,
    samples_per_stroke: int = 400,
    *,
    plane: Board | None = None,
) -> Deviation:
    """Two-sided distance between the pen-down path and the input strokes.

    For each stroke: the largest distance from pen-down samples to the
    stroke's polyline, and from the stroke's points to the pen-down path
    (its dense samples as a polyline). With ``brush_length_m > 0`` the path is
    the swung tip (:func:`swung_tip`), else the planned curve itself. 3-D
    distances (lifting off the board counts), or with ``plane`` distances in
    that board's plane (the ink's view: a pressed tip is not off the stroke).
    """
    if not windows:
        return _two_sided([], [])
    # Every stroke's samples in one evaluation (one spline call per derivative, not per stroke).
    t = np.concatenate([np.linspace(t0, t1, samples_per_stroke) for t0, t1 in windows])
    path = swung_tip(traj, t, brush_length_m) if brush_length_m else traj.evaluate(t)
    strokes = list(strokes_world)
    if plane is not None:
        path = plane.to_board(path)[:, :2]
        strokes = [plane.to_board(stroke)[:, :2] for stroke in strokes]
    paths = np.split(path, np.arange(1, len(windows)) * samples_per_stroke)
    return _two_sided(paths, strokes)


def _two_sided(paths: list[FloatArray], strokes: list[FloatArray]) -> Deviation:
    """Distances between each path (K, d) and its stroke (J, d), both ways."""
    forward, backward, total, count = 0.0, 0.0, 0.0, 0
    # A touch of one sample is a polyline of zero length.
    runs = [np.vstack([run, run]) if run.shape[0] == 1 else run for run in paths]
    pairs = list(zip(runs, strokes, strict=True))
    # Both ways of every stroke in one call (one table of all their pairs).
    distances = polyline_distances(pairs + [(stroke, path) for path, stroke in pairs])
    for to_input, to_path in zip(distances[: len(pairs)], distances[len(pairs) :], strict=True):
        forward = max(forward, float(to_input.max()))
        backward = max(backward, float(to_path.max()))
        total += float(to_input.sum())
        count += to_input.size
    return Deviation(forward, backward, total / count)


#: How far the simulated board reaches beyond the writing on every side, m.
BOARD_MARGIN_M = 0.1
#: The simulated board is a slab this thick, m: a tip below it is under the
#: board (taking off from the floor beneath it), not pressing on it.
BOARD_THICKNESS_M = 0.05
