"""The route of a writing flight: every sample the flight is fitted to, and its role.

Take-off from a home (or a hover above the first stroke), every stroke with the
brush's lifts onto and off the board, the transits between strokes, and the
landing: one polyline (paper 000 §4: strokes sampled densely, turning points
by split-and-merge), each sample tagged with the stroke it belongs to or
:data:`LIFT` / :data:`TRANSIT`. The route is estimated and refused above
:data:`MAX_ROUTE_SAMPLES` before it is built.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from skyquill.calligraphy.board import Board
from skyquill.errors import InputError
from skyquill.optimize.workspace import Workspace
from skyquill.strokes import turning_points
from skyquill.validation import FloatArray

#: Spacing of the samples that hold lifts and transits near their straight lines, m.
TRANSIT_SPACING_M = 0.01
#: Up to this many sample-corner pairs a stroke's corners are found by a table of
#: every pair (a bundled character's strokes: a few thousand), above it by a k-d tree
#: (memory linear in the samples: one 19,000-point SVG path).
NEAREST_TABLE_PAIRS = 32_768
#: Route roles of the samples that are not on a stroke (those carry the stroke's
#: index): the brush going straight down to a stroke or up from it, and the
#: moves between, above the board.
LIFT, TRANSIT = -2, -1
#: Route role of the samples of a continuing flight braking from its motion
#: (:func:`skyquill.calligraphy.incremental.braking`): held like the lifts.
BRAKE = -3
#: Most route samples (stroke points plus lifts and transits every
#: TRANSIT_SPACING_M), estimated from the route's length before it is built:
#: each is a row of the QP's deviation block (~1 kB with its factors).
MAX_ROUTE_SAMPLES = 400_000


@dataclass(frozen=True)
class RouteSamples:
    """A route to fly: samples (N, 3), roles (N,), corner indices, the input strokes.

    ``roles[i]`` is the index into ``strokes_world`` of the stroke sample ``i``
    belongs to, or :data:`LIFT` / :data:`TRANSIT`; ``max_spans`` caps the knot spans
    of its spline (``None``: as many as ``knot_interval`` asks). ``workspace``
    carries the assembly and the QP setup from one solve of the route to the
    next (stretches, re-segmentation steps): only the times change between them.

    ``start``: a route that continues a flight (:mod:`skyquill.calligraphy.incremental`)
    starts in motion -- the position, velocity, acceleration and jerk (each (3,))
    the flight has there; ``None``: at rest. ``lead_in``: the times of its first
    samples, fixed (the flight braking from that motion). ``legs``: the samples
    ``(first, last)`` between which it writes, before and after them the legs
    from and to home (:func:`~skyquill.calligraphy.timing.route_times`);
    ``None``: found from the roles.
    """

    points: FloatArray
    roles: FloatArray
    corners: FloatArray
    strokes_world: tuple[FloatArray, ...]
    max_spans: int | None = None
    workspace: Workspace = field(default_factory=Workspace, compare=False, repr=False)
    start: tuple[FloatArray, ...] | None = None
    legs: tuple[int, int] | None = None
    lead_in: FloatArray | None = None


def build_route(
    strokes_world: tuple[FloatArray, ...],
    board: Board,
    home: FloatArray | None,
    turning_threshold_m: float,
    start: FloatArray | None = None,
) -> RouteSamples:
    """The route of ``strokes_world`` (each (K, 3), m) on ``board`` from ``home`` (3,) or a hover.

    Refused before it is built when it would exceed :data:`MAX_ROUTE_SAMPLES`;
    the turning points are found by split-and-merge at ``turning_threshold_m``.
    ``start`` (3,): the route continues a flight from there instead of taking
    off; it writes from its first sample, and ends at ``home`` if one is given.
    """
    check_route_size(strokes_world, board, home)
    points, roles = route_points(strokes_world, board, home, start=start)
    corners = _turning_samples(strokes_world, board, points, roles, turning_threshold_m)
    if start is None:
        return RouteSamples(points, roles, corners, strokes_world)
    legs = (0, writing_end(roles) if home is not None else len(points) - 1)
    return RouteSamples(points, roles, corners, strokes_world, legs=legs)


def _segment(a: FloatArray, b: FloatArray) -> FloatArray:
    """Samples of the straight line from ``a`` to ``b`` (excluding ``a``), every 1 cm."""
    n = max(1, math.ceil(float(np.linalg.norm(b - a)) / TRANSIT_SPACING_M))
    return np.asarray(a + np.outer(np.arange(1, n + 1) / n, b - a))


def densify(polyline: FloatArray, spacing: float = TRANSIT_SPACING_M) -> FloatArray:
    """``polyline`` (K, 3) with points inserted so no gap exceeds ``spacing``; vertices kept.

    Sparse input (a straight stroke given by its two ends) would leave the
    spline free between samples; dense samples hold it to the line.
    """
    a, b = polyline[:-1], polyline[1:]
    step = b - a
    length = np.sqrt(np.einsum("sd,sd->s", step, step))
    long = length > spacing
    # Every segment at once, as _segment samples one: a + (j / n) (b - a), j = 1 .. n;
    # a segment no longer than the spacing contributes its end b itself.
    n = np.where(long, np.ceil(length / spacing), 1.0).astype(np.intp)
    segment = np.repeat(np.arange(n.size), n)
    j = np.arange(1, segment.size + 1) - np.repeat(np.cumsum(n) - n, n)
    inserted = a[segment] + (j / n[segment])[:, None] * step[segment]
    ends = np.cumsum(n) - 1
    inserted[ends[~long]] = b[~long]
    return np.vstack([polyline[:1], inserted])


@dataclass
class _Route:
    """The mission polyline with a role per sample: stroke index, ``TRANSIT`` or ``LIFT``."""

    points: list[FloatArray] = field(default_factory=list)
    role: list[FloatArray] = field(default_factory=list)

    def add(self, points: FloatArray, role: int) -> None:
        self.points.append(points)
        self.role.append(np.full(len(points), role))

    def add_stroke(self, points: FloatArray, role: int) -> None:
        """Add a stroke's samples; with no lift (a sky board) the transit ends on its
        first point, and that sample becomes the stroke's (times must increase)."""
        if np.linalg.norm(points[0] - self.points[-1][-1]) < 1e-9:
            self.points[-1], self.role[-1] = self.points[-1][:-1], self.role[-1][:-1]
        self.add(points, role)

    def go_to(self, target: FloatArray, include_target: bool = True, role: int = -1) -> None:
        if np.linalg.norm(target - self.points[-1][-1]) < 1e-9:
            return  # already there: no repeated sample (times must increase)
        line = _segment(self.points[-1][-1], target)
        self.add(line if include_target else line[:-1], role)


def route_points(
    strokes_world: tuple[FloatArray, ...],
    board: Board,
    home: FloatArray | None,
    start: FloatArray | None = None,
) -> tuple[FloatArray, FloatArray]:
    """All samples (N, 3) and their roles (N,): take-off, strokes with lifts, landing.

    ``start`` (3,): the route begins there instead (where an earlier flight's
    writing ended: :mod:`skyquill.calligraphy.incremental`), then goes to the
    first stroke as between strokes; it ends at ``home`` if one is given.
    """
    lift = board.lift_m * board.normal
    route = _Route()
    first = strokes_world[0][0] + lift
    if start is not None:
        route.add(np.asarray(start, dtype=float)[None, :], TRANSIT)
    elif home is not None:
        route.add(home[None, :], -1)
        route.go_to(np.array([home[0], home[1], first[2]]))  # climb straight up
        route.go_to(first)
    else:
        route.add(first[None, :], -1)
    for i, stroke in enumerate(strokes_world):
        route.go_to(stroke[0] + lift)
        # Touch down on the stroke's first point, lift straight up from its last.
        route.go_to(stroke[0], include_target=False, role=LIFT)
        route.add_stroke(densify(stroke), i)
        route.go_to(stroke[-1] + lift, role=LIFT)
    if home is not None:
        route.go_to(np.array([home[0], home[1], route.points[-1][-1][2]]))
        route.go_to(home)
    return np.vstack(route.points), np.concatenate(route.role)


def route_length(
    strokes_world: tuple[FloatArray, ...], board: Board, home: FloatArray | None
) -> float:
    """An upper estimate of the route's length, m, without building it.

    Strokes, two lifts per stroke, the transits between strokes and, with a
    ``home`` (3,), the legs to and from it (taxicab: climb, then fly).
    """
    ends = [(s[0], s[-1]) for s in strokes_world]
    drawn = sum(float(np.linalg.norm(np.diff(s, axis=0), axis=1).sum()) for s in strokes_world)
    moves = sum(float(np.linalg.norm(b[0] - a[1])) for a, b in itertools.pairwise(ends))
    legs = 0.0
    if home is not None:
        legs = float(np.abs(ends[0][0] - home).sum() + np.abs(ends[-1][1] - home).sum())
    return drawn + moves + legs + 2.0 * len(strokes_world) * board.lift_m


def check_route_size(
    strokes_world: tuple[FloatArray, ...], board: Board, home: FloatArray | None
) -> None:
    """Refuse a route of more than :data:`MAX_ROUTE_SAMPLES` samples before building it."""
    length = route_length(strokes_world, board, home)
    n_points = sum(len(s) for s in strokes_world)
    samples = length / TRANSIT_SPACING_M + n_points
    if samples > MAX_ROUTE_SAMPLES:
        raise InputError(
            f"strokes: got a route of about {length:.4g} m ({samples:.3g} samples, one every "
            f"{100 * TRANSIT_SPACING_M:g} cm), expected at most {MAX_ROUTE_SAMPLES:,} samples, "
            f"i.e. about {MAX_ROUTE_SAMPLES * TRANSIT_SPACING_M / 1e3:g} km (a smaller size_m, "
            "lift_m, a home nearer the board or fewer strokes)"
        )


def _turning_samples(
    strokes_world: tuple[FloatArray, ...],
    board: Board,
    points: FloatArray,
    roles: FloatArray,
    threshold: float,
) -> FloatArray:
    """Indices into the route of every stroke's turning points (paper 000 §4).

    Densifying keeps the vertices: each corner is found among its stroke's samples
    as the nearest one (the first of equally near ones) -- by a table of every
    pair up to :data:`NEAREST_TABLE_PAIRS` (a character's strokes: building a
    k-d tree per stroke cost more than its few hundred samples' table), else by
    a k-d tree, in memory linear in the samples: a table of every sample against
    every corner took samples x corners x 3 floats, 8 GiB for one 19,000-point SVG
    path.
    """
    from scipy.spatial import cKDTree

    picked = []
    for i, stroke in enumerate(strokes_world):
        corners = stroke[turning_points(board.to_board(stroke)[:, :2], threshold)]
        where = np.flatnonzero(roles == i)
        if where.size * corners.shape[0] <= NEAREST_TABLE_PAIRS:
            picked.append(where[_nearest_by_table(points[where], corners)])
            continue
        tree = cKDTree(points[where])
        distance, nearest = tree.query(corners)
        ties = tree.query_ball_point(corners, distance * (1.0 + 1e-12) + 1e-300)
        nearest = np.atleast_1d(nearest)
        first = np.array([min(t) if len(t) else k for t, k in zip(ties, nearest, strict=True)])
        picked.append(where[first.astype(np.intp)])
    return np.concatenate(picked)


def _nearest_by_table(samples: FloatArray, corners: FloatArray) -> NDArray[np.intp]:
    """For each corner (K, 3), the first of the samples (S, 3) nearest to it (as the
    k-d tree's query with its ties), from the table of every pair (S, K)."""
    gap = samples[:, None, :] - corners[None, :, :]
    distance = np.sqrt(np.einsum("skd,skd->sk", gap, gap))
    tied = distance <= distance.min(axis=0) * (1.0 + 1e-12) + 1e-300
    return np.asarray(np.argmax(tied, axis=0), dtype=np.intp)


def writing_end(roles: FloatArray) -> int:
    """Index of the sample where the writing ends: the top of the lift off the last
    stroke (the last stroke sample on a board without lifts); after it, the leg home."""
    lifts = np.flatnonzero(roles == LIFT)
    if lifts.size:
        return int(lifts[-1])
    return int(np.flatnonzero(roles >= 0)[-1])
