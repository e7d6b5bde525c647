"""The simulated ink against the input strokes: its fidelity, as numbers and shapes.

(:func:`skyquill.viz.ink_plot.render_ink` draws the shapes as ``ink.png``.)

The simulator records the brush tip while it touches the board
(:attr:`skyquill.sim.Flight.ink`, one run per contact), and the contact model
makes the mark as wide as the brush's footprint at the pressing depth
(:meth:`~skyquill.calligraphy.brush.Brush.ink_width`). Everything here is in the
board's plane, (u, v) in metres (:meth:`~skyquill.calligraphy.board.Board.to_board`):

* the ink as a shape: each segment between consecutive tip samples swept by a
  disc whose diameter goes from the width at one end to the width at the other
  (the convex hull of the two end discs), all of them unioned (samples closer
  than :data:`MERGE_M` and about as wide merged first);
* the input as a shape: its strokes swept by a disc of the planned stroke width;
* their intersection over union (IoU), from the areas of these polygons
  (shapely, exact for the polygons; the discs are 64-gons, whose area is
  0.2 % short of the circle's);
* the two-sided distance between the centre lines (a Hausdorff distance): every
  ink sample to the nearest input stroke, and every input point (the strokes
  resampled every :data:`SAMPLE_M`) to the nearest ink (its centre line
  simplified within :data:`SIMPLIFY_M`).

Measured: 永 flown for 20 s at 500 Hz (2,700 ink samples) in ~0.2 s, on a
2-core machine shared with other work; 10,000 ink samples in ~0.5 s.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

from skyquill.calligraphy.mission import Mission, contact_board
from skyquill.errors import InputError
from skyquill.geometry import polyline_distance
from skyquill.validation import FloatArray, as_array, as_float

if TYPE_CHECKING:
    from skyquill.sim import Flight

#: Spacing of the points the input strokes are resampled at for the input-to-ink
#: distance, m: a gap in the ink shorter than this can hide between two of them.
SAMPLE_M = 5e-4

#: The ink's centre line is simplified (Douglas-Peucker) within this, m, before
#: the input's points are measured against it: the samples at 500 Hz are far
#: denser than the curve needs, and each costs a segment per input point.
SIMPLIFY_M = 2e-5

#: Consecutive ink samples closer than this in the plane (and of about the same
#: width) are merged before the ink is swept, m: at 500 Hz a slow landing leaves
#: hundreds of samples on one spot, which only slow the union down.
MERGE_M = 5e-4

#: Width change that keeps a close ink sample anyway, m (a tip pressed in place).
MERGE_WIDTH_M = 1e-4

#: Segments per quarter circle of the discs the strokes are swept with.
QUAD_SEGS = 16

#: Segments per piece of a polyline that distances are pruned by (:func:`_nearest`).
_PIECE = 32


@dataclass(frozen=True)
class InkFidelity:
    """How well the simulated ink reproduces the input, in the board's plane (SI units).

    Attributes
    ----------
    max_deviation_m
        Two-sided (Hausdorff) distance between the ink's and the input's centre
        lines, m: the larger of the next two; ``inf`` when there is no ink.
    ink_to_input_max_m
        Farthest ink sample from the nearest input stroke, m (0 without ink).
    input_to_ink_max_m
        Farthest input point from the nearest ink, m (``inf`` without ink):
        what the ink misses.
    mean_m
        The mean distance of the ink samples to the input and the mean of the
        input points to the ink, averaged, m (``inf`` without ink).
    ink_strokes
        Contact runs that left ink (non-empty).
    input_strokes
        Strokes of the input.
    iou
        Area of ink and input drawn at ``width_m`` in common, over the area of
        either (0 when neither has an area).
    width_m
        The planned stroke width the input is drawn at, m.
    ink_shape, input_shape
        The two shapes (shapely, (u, v) in m) the IoU is measured on.
    """

    max_deviation_m: float
    ink_to_input_max_m: float
    input_to_ink_max_m: float
    mean_m: float
    ink_strokes: int
    input_strokes: int
    iou: float
    width_m: float
    ink_shape: BaseGeometry = field(repr=False, compare=False)
    input_shape: BaseGeometry = field(repr=False, compare=False)

    def as_dict(self) -> dict[str, Any]:
        """The numbers for ``summary.json``; a distance that is infinite (no ink) is ``None``."""
        distances = ("max_deviation_m", "ink_to_input_max_m", "input_to_ink_max_m", "mean_m")
        out: dict[str, Any] = {name: _finite_or_none(getattr(self, name)) for name in distances}
        return out | {
            "ink_strokes": self.ink_strokes,
            "input_strokes": self.input_strokes,
            "iou": self.iou,
            "width_m": self.width_m,
        }


def flight_ink(flight: Flight, mission: Mission) -> InkFidelity | None:
    """The fidelity of ``flight``'s ink to ``mission``'s strokes; ``None`` off a contact board.

    The surface is the simulator's contact board under the mission
    (:func:`~skyquill.calligraphy.mission.contact_board`); a wall has none, and no ink.
    """
    board = contact_board(mission)
    if board is None:
        return None
    return measure_ink(flight.ink, mission, board.height_m)


def measure_ink(
    flight_ink: Sequence[FloatArray], mission: Mission, surface_height_m: float
) -> InkFidelity:
    """Measure simulated ink against the strokes ``mission`` was planned to write.

    Parameters
    ----------
    flight_ink
        Brush-tip positions while touching the board, one (K, 3) array per
        contact run (K may be 0), world frame, z up, m.
    mission
        The writing mission: its board, input strokes and brush.
    surface_height_m
        World z of the board's surface, m: a tip at ``z`` is pressed
        ``surface_height_m - z`` into it and leaves a mark that wide
        (:meth:`~skyquill.calligraphy.brush.Brush.ink_width`).

    Returns
    -------
    InkFidelity
    """
    surface = as_float("surface_height_m", surface_height_m)
    brush, board = mission.options.brush, mission.board
    runs = [as_array(f"flight_ink[{i}]", r, shape=(None, 3)) for i, r in enumerate(flight_ink)]
    runs = [r for r in runs if len(r)]
    return ink_fidelity(
        [board.to_board(r)[:, :2] for r in runs],
        [brush.ink_width(surface - r[:, 2]) for r in runs],
        [board.to_board(s)[:, :2] for s in mission.strokes_world],
        brush.stroke_width_m,
    )


def ink_fidelity(
    ink_uv: Sequence[FloatArray],
    ink_width_m: Sequence[FloatArray],
    input_uv: Sequence[FloatArray],
    width_m: float,
) -> InkFidelity:
    """Compare ink runs with input strokes, both in the board's plane.

    Parameters
    ----------
    ink_uv
        Ink centre line, one (K, 2) array per contact run, (u, v), m. Empty
        runs are ignored.
    ink_width_m
        The mark's width at each ink sample, one (K,) array per run, m, >= 0.
    input_uv
        The input strokes, at least one, each (V, 2), V >= 1, (u, v), m.
    width_m
        The planned stroke width the input is drawn at, m, >= 0.

    Returns
    -------
    InkFidelity
    """
    runs = _ink_runs(ink_uv, ink_width_m)
    width = as_float("width_m", width_m, nonneg=True)
    strokes = [as_array(f"input_uv[{i}]", s, shape=(None, 2)) for i, s in enumerate(input_uv)]
    if not strokes or any(len(s) == 0 for s in strokes):
        raise InputError("input_uv: got no stroke or an empty one, expected (V, 2) with V >= 1")
    ink_shape = shapely.union_all([_swept(*_merged(uv, w)) for uv, w in runs])
    input_shape = shapely.union_all([_stroke_shape(s, width) for s in strokes])
    to_input, to_ink = _two_sided([uv for uv, _ in runs], strokes)
    return InkFidelity(
        max_deviation_m=float(max(to_input.max(initial=0.0), to_ink.max(initial=0.0))),
        ink_to_input_max_m=float(to_input.max(initial=0.0)),
        input_to_ink_max_m=float(to_ink.max(initial=0.0)),
        mean_m=0.5 * (float(to_input.mean()) + float(to_ink.mean())) if runs else math.inf,
        ink_strokes=len(runs),
        input_strokes=len(strokes),
        iou=_iou(ink_shape, input_shape),
        width_m=width,
        ink_shape=ink_shape,
        input_shape=input_shape,
    )


def _ink_runs(
    ink_uv: Sequence[FloatArray], ink_width_m: Sequence[FloatArray]
) -> list[tuple[FloatArray, FloatArray]]:
    """The non-empty ink runs as checked ``(uv (K, 2), width (K,))`` pairs."""
    if len(ink_uv) != len(ink_width_m):
        raise InputError(
            f"ink_width_m: got {len(ink_width_m)} run(s), expected one per ink run ({len(ink_uv)})"
        )
    runs = []
    for i, (raw_uv, raw_width) in enumerate(zip(ink_uv, ink_width_m, strict=True)):
        uv = as_array(f"ink_uv[{i}]", raw_uv, shape=(None, 2))
        width = as_array(f"ink_width_m[{i}]", raw_width, shape=(len(uv),))
        if np.any(width < 0.0):
            raise InputError(f"ink_width_m[{i}]: got a negative width, expected >= 0")
        if len(uv):
            runs.append((uv, width))
    return runs


def _merged(uv: FloatArray, width: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``uv`` and ``width`` without the samples that barely change the swept shape.

    A sample is dropped when it is within :data:`MERGE_M` of the last one kept
    and about as wide (within :data:`MERGE_WIDTH_M`), so the outline moves by
    less than that; the last sample is always kept, so the run still ends where
    the brush lifted.
    """
    keep = [0]
    (last_u, last_v), last_w = uv[0].tolist(), float(width[0])
    rest = zip(uv[1:, 0].tolist(), uv[1:, 1].tolist(), width[1:].tolist(), strict=True)
    for k, (u, v, w) in enumerate(rest, start=1):
        if math.hypot(u - last_u, v - last_v) >= MERGE_M or abs(w - last_w) >= MERGE_WIDTH_M:
            keep.append(k)
            last_u, last_v, last_w = u, v, w
    if keep[-1] != len(uv) - 1:
        keep.append(len(uv) - 1)
    return uv[keep], width[keep]


def _swept(uv: FloatArray, width: FloatArray) -> BaseGeometry:
    """One ink run's mark: the union of the hulls of consecutive samples' discs."""
    if len(uv) == 1:  # a touch without sliding: one disc
        uv, width = np.vstack([uv, uv]), np.concatenate([width, width])
    radius = 0.5 * width
    wide = (radius[:-1] > 0.0) | (radius[1:] > 0.0)  # two zero discs sweep no area
    if not wide.any():
        return shapely.Polygon()
    circle = _unit_circle()
    ends = [uv[:-1][wide], uv[1:][wide]]
    radii = [radius[:-1][wide], radius[1:][wide]]
    discs = [
        p[:, None, :] + r[:, None, None] * circle[None] for p, r in zip(ends, radii, strict=True)
    ]
    hulls = shapely.convex_hull(shapely.linestrings(np.concatenate(discs, axis=1)))
    return shapely.union_all(hulls)


def _unit_circle() -> FloatArray:
    """The disc outline the strokes are swept with: (4 * QUAD_SEGS, 2)."""
    angle = np.linspace(0.0, 2.0 * np.pi, 4 * QUAD_SEGS, endpoint=False)
    return np.column_stack([np.cos(angle), np.sin(angle)])


def _stroke_shape(stroke: FloatArray, width: float) -> BaseGeometry:
    """An input stroke drawn at ``width`` (round caps and joins, like the brush)."""
    if width <= 0.0:
        return shapely.Polygon()
    line = shapely.Point(stroke[0]) if len(stroke) == 1 else shapely.LineString(stroke)
    return line.buffer(0.5 * width, quad_segs=QUAD_SEGS)


def _iou(a: BaseGeometry, b: BaseGeometry) -> float:
    union = float(shapely.union(a, b).area)
    return float(shapely.intersection(a, b).area) / union if union > 0.0 else 0.0


def _two_sided(ink: list[FloatArray], strokes: list[FloatArray]) -> tuple[FloatArray, FloatArray]:
    """Each ink sample's distance to the input, and each input point's to the ink, m."""
    if not ink:
        return np.zeros(0), np.full(1, np.inf)
    to_input = _nearest(np.vstack(ink), strokes)
    dense = np.vstack([_resampled(s) for s in strokes])
    return to_input, _nearest(dense, [_simplified(uv) for uv in ink])


def _nearest(points: FloatArray, polylines: list[FloatArray]) -> FloatArray:
    """Distance of each point (N, 2) to the nearest of ``polylines`` (each (V, 2), V >= 1).

    Exact, but pruned: the polylines are cut into pieces of :data:`_PIECE`
    segments, and a piece is measured (:func:`polyline_distance`) only for the
    points nearer to its bounding box than to any piece measured before, the
    nearest box first. A flight's ink is thousands of segments, each input
    point is near a few of them.
    """
    pieces = [piece for line in polylines for piece in _pieces(line)]
    lo = np.array([p.min(axis=0) for p in pieces])
    hi = np.array([p.max(axis=0) for p in pieces])
    outside = np.maximum(np.maximum(lo[None] - points[:, None], points[:, None] - hi[None]), 0.0)
    box_gap = np.hypot(outside[..., 0], outside[..., 1])  # (N, pieces), <= the true distance
    best = np.full(len(points), np.inf)
    first = box_gap.argmin(axis=1)
    for k, piece in enumerate(pieces):  # each point's nearest box: a good first bound
        near = first == k
        if near.any():
            best[near] = polyline_distance(points[near], piece)
    for k, piece in enumerate(pieces):
        near = (box_gap[:, k] < best) & (first != k)
        if near.any():
            best[near] = np.minimum(best[near], polyline_distance(points[near], piece))
    return best


def _pieces(vertices: FloatArray) -> list[FloatArray]:
    """A polyline (V, 2) as consecutive pieces of at most :data:`_PIECE` segments.

    A dot (V = 1) is one zero-length segment, which :func:`polyline_distance` takes.
    """
    if len(vertices) == 1:
        return [np.vstack([vertices, vertices])]
    return [vertices[i : i + _PIECE + 1] for i in range(0, len(vertices) - 1, _PIECE)]


def _simplified(uv: FloatArray) -> FloatArray:
    """The ink's centre line with the vertices that move it less than :data:`SIMPLIFY_M` dropped."""
    if len(uv) < 3:
        return uv
    line = shapely.simplify(shapely.LineString(uv), SIMPLIFY_M, preserve_topology=False)
    return np.asarray(shapely.get_coordinates(line), dtype=float)


def _resampled(stroke: FloatArray) -> FloatArray:
    """The stroke's vertices and points between them at most :data:`SAMPLE_M` apart."""
    if len(stroke) == 1:
        return stroke
    line = shapely.segmentize(shapely.LineString(stroke), SAMPLE_M)
    return np.asarray(shapely.get_coordinates(line), dtype=float)


def _finite_or_none(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None
