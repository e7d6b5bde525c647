"""The smoothing problem of a writing route (paper 003's B-spline QP, paper 000 §5).

One problem for the whole flight: the stroke samples held with a high
weight, their turning points with a higher one, lifts and transits with lower
ones, the jerk cost, rest at both ends, the vehicle's limits on the hull; on a
sky board also paper 003 §5.3's plane deviation. Fitting the swung brush tip,
the point deviations carry its first-order acceleration term (``gain``).
"""

from __future__ import annotations

import math

import numpy as np

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.options import WritingOptions
from skyquill.calligraphy.route import BRAKE, LIFT, TRANSIT, RouteSamples
from skyquill.errors import InputError
from skyquill.optimize import Boundary, PlaneDeviation, PointDeviation, SmoothingProblem
from skyquill.validation import FloatArray, as_array

#: Most knot spans of one solve, checked before each assembly: 3 x (spans + 5)
#: unknowns and a hull block per span and limit; 20 000 spans is 1000 s of
#: flight at the default 0.05 s, and ~1 GB of KKT factors.
MAX_SPANS = 20_000


def route_problem(
    samples: RouteSamples,
    targets: FloatArray,
    times: FloatArray,
    opts: WritingOptions,
    *,
    gain: FloatArray | None = None,
    n_ctrl: int | None = None,
    board: Board | None = None,
) -> SmoothingProblem:
    """The smoothing problem of ``samples`` fitted to ``targets`` (N, 3) at ``times`` (N,).

    ``gain``: the deviation is of ``p + gain * a`` (the swung tip's first-order
    model) instead of ``p``; ``n_ctrl``: the control points (re-segmentation
    keeps them), else from ``opts.knot_interval`` up to ``samples.max_spans``;
    ``board``: a sky board adds its plane's deviation cost (:func:`plane_terms`).
    """
    duration = float(times[-1])
    spans = n_ctrl - opts.degree if n_ctrl else max(1, math.ceil(duration / opts.knot_interval))
    if samples.max_spans is not None:
        spans = min(spans, samples.max_spans)
    if spans > MAX_SPANS:
        raise InputError(
            f"knot_interval: got {opts.knot_interval:g} s for a {duration:.4g} s flight, i.e. "
            f"{spans:,} knot spans, expected at most {MAX_SPANS:,} (a longer knot_interval, "
            "a smaller size_m or fewer strokes)"
        )
    stroke, lift = samples.roles >= 0, samples.roles == LIFT
    # Fitting the tip, the lifts are held (lift_weight): a lift the smoothing
    # cuts short leaves the brush on the board between strokes, and the ink
    # joins them. Fitting the path (paper 000) they are transits.
    transit = (~stroke & (samples.roles != BRAKE)) if gain is None else samples.roles == TRANSIT
    terms = [
        (stroke, opts.data_weight),
        (samples.corners, opts.turning_weight),
        (transit, opts.transit_weight),
        (lift if gain is not None else np.zeros_like(lift), opts.lift_weight),
        (samples.roles == BRAKE, opts.lift_weight),  # a continuing flight's braking
    ]
    # Checked once here; each term is a selection of these (re-segmentation builds a
    # problem per descent step: five terms each, no need to scan them again).
    t = as_array("times", times, shape=(None,))
    p = as_array("targets", targets, shape=(t.size, 3))
    g = None if gain is None else as_array("gain", gain, shape=(3,))
    deviations = tuple(
        PointDeviation.of_checked(t[which], p[which], weight, g)
        for which, weight in terms
        if weight > 0 and np.any(which)
    )
    return SmoothingProblem(
        dim=3,
        degree=opts.degree,
        n_ctrl=spans + opts.degree,
        duration=duration,
        smoothness={3: 1.0},
        deviations=deviations + plane_terms(samples.roles, times, board, opts),
        # The same objects for every solve of the route (re-segmentation, the ladder):
        # built and checked once, and the engine's caches know them by identity.
        boundary=samples.workspace.memo(
            "boundary", (targets,), lambda: _boundary(samples, targets, opts.degree)
        ),
        limits=samples.workspace.memo("limits", (opts,), opts.derivative_limits),
    )


def _boundary(samples: RouteSamples, targets: FloatArray, degree: int) -> tuple[Boundary, ...]:
    """At rest at both ends (paper 003 eqs. 40-42), or, continuing a flight
    (``samples.start``), in its motion at the start: position to jerk (to the
    acceleration on a cubic, whose jerk jumps at every knot anyway)."""
    if samples.start is None:
        return Boundary.rest(targets[0], targets[-1], 3)
    rest = Boundary.rest(samples.start[0], targets[-1], 3)
    moving = tuple(Boundary(b.order, samples.start[b.order], b.end) if b.order else b for b in rest)
    return (*moving, Boundary(3, samples.start[3], None)) if degree > 3 else moving


def plane_terms(
    roles: FloatArray, times: FloatArray, board: Board | None, opts: WritingOptions
) -> tuple[PlaneDeviation, ...]:
    """Paper 003 §5.3 on a sky board: the plane's deviation from the first stroke's
    start to the last one's end, transits included (they stay in the plane, lift 0).
    Off the board (take-off, landing) the flight leaves the plane on purpose."""
    if board is None or board.has_contact or opts.plane_weight == 0:
        return ()
    pen = np.flatnonzero(roles >= 0)
    if pen.size == 0 or times[pen[-1]] <= times[pen[0]]:
        return ()
    t0, t1 = float(times[pen[0]]), float(times[pen[-1]])
    return (PlaneDeviation(board.normal, board.origin, t0, t1, opts.plane_weight),)
