"""Writing plans that fit a vehicle's trajectory memory (``WritingOptions.target``).

A Crazyflie holds 31 polynomial pieces per upload (:mod:`skyquill.targets`);
the default mission spline has a knot span every 0.05 s, i.e. hundreds of
pieces. The ways to fit, tried in this order (cheapest flight first):

* ``"one-upload"``: the whole route as one spline of the target's degree with
  at most ``max_pieces`` knot spans, so the knot interval is the flight time
  over the spans (a degree-7 span carries far more than 0.05 s of writing);
  timing stretched like any mission when the limits cannot be met.
* ``"split"``: the route cut at the pen-up points above the board (where the
  brush has lifted after a stroke; the timing is at rest there, a corner) into
  legs, consecutive legs grouped greedily into the largest group whose own
  rest-to-rest spline of at most ``max_pieces`` spans stays within the limits
  and the tolerance, and the groups flown one after another with a hover of
  ``hover_s`` between them (the next upload is written while hovering).

Non-uniform knots (placed where the path needs them) would be a third way;
the engine's B-spline is clamped uniform, so it is not built here.

Every result is cut into uploads by :func:`skyquill.targets.plan_uploads`, the
same cut the Crazyswarm exporter writes.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from skyquill.calligraphy.allocation import plan_route
from skyquill.calligraphy.board import Board
from skyquill.calligraphy.mission import Mission
from skyquill.calligraphy.options import WritingOptions
from skyquill.calligraphy.planning import RoutePlan, fidelity, resegmented
from skyquill.calligraphy.route import RouteSamples
from skyquill.errors import InfeasibleError
from skyquill.targets import (
    Strategy,
    Upload,
    UploadTarget,
    hover,
    plan_uploads,
    uploads_summary,
)
from skyquill.trajectory import RestToRestSequence, Trajectory

#: How far a pen-up point may lie from the lifted stroke end it is found by, m.
LIFT_MATCH_M = 1e-9


@dataclass(frozen=True)
class TargetPlan:
    """How a mission fits its target.

    Attributes
    ----------
    target
        The vehicle's budget.
    strategy
        The first of ``options.target_strategies`` that fitted (or, with
        ``best_effort``, the last tried).
    uploads
        The uploads, in flight order, as :func:`~skyquill.targets.plan_uploads` cuts
        the tip trajectory (the vehicle's is the same, offset).
    """

    target: UploadTarget
    strategy: Strategy
    uploads: tuple[Upload, ...]

    def as_dict(self) -> dict[str, Any]:
        """``summary.json`` form (s, pieces, B)."""
        return uploads_summary(self.target, self.strategy, self.uploads)


@dataclass(frozen=True)
class _Group:
    """Legs ``[first, stop)`` of the route planned as one spline (``None``: infeasible)."""

    first: int
    stop: int
    plan: RoutePlan | None


def plan_for_target(
    samples: RouteSamples, board: Board, opts: WritingOptions, start: float
) -> Mission:
    """The mission along ``samples`` that fits ``opts.target`` (see the module docstring).

    Parameters
    ----------
    samples
        The whole route (built by :func:`~skyquill.calligraphy.mission.plan_writing`).
    board
        Where it writes.
    opts
        The options; ``opts.target`` is not ``None``.
    start
        ``time.perf_counter()`` when planning began.

    Raises
    ------
    InfeasibleError
        Neither strategy fits within the limits and the tolerance (and not
        ``best_effort``); the message gives what was measured and what would fit.
    """
    target = opts.target
    assert target is not None
    inner = replace(opts, degree=target.max_degree)
    budget = replace(samples, max_spans=target.max_pieces)
    whole: RoutePlan | None = None
    groups: list[_Group] | None = None
    fallback: Mission | None = None  # the last strategy's plan beyond the tolerance
    if "one-upload" in opts.target_strategies:
        whole = _attempt(budget, board, inner)
        if whole is not None:
            plan = _refined(budget, whole, board, inner)
            trajectory: Trajectory = plan.fit.trajectory
            fallback = _mission((plan,), (trajectory, plan.windows), samples, board, opts)
            if whole.faithful(inner):
                return _timed(fallback, start)
    if "split" in opts.target_strategies:
        cuts = _cuts(budget, board)
        groups = _groups(budget, cuts, board, inner)
        if all(g.plan is not None for g in groups):
            plans = tuple(
                _refined(_sub(budget, cuts, g.first, g.stop), g.plan, board, inner)
                for g in groups
                if g.plan is not None
            )
            fallback = _mission(plans, _joined(plans, target), samples, board, opts)
            if all(g.plan is not None and g.plan.faithful(inner) for g in groups):
                return _timed(fallback, start)
    if opts.best_effort and fallback is not None:
        return _timed(fallback, start)
    raise _no_fit(whole, groups, inner)


def _timed(mission: Mission, start: float) -> Mission:
    """``mission`` with its planning time: from ``start`` (``time.perf_counter()``) to now."""
    return replace(mission, planning_time_s=time.perf_counter() - start)


def _attempt(samples: RouteSamples, board: Board, opts: WritingOptions) -> RoutePlan | None:
    """:func:`plan_route` without re-segmentation; ``None`` if the limits cannot be met."""
    try:
        return plan_route(samples, board, opts)
    except InfeasibleError:
        return None


def _refined(
    samples: RouteSamples, plan: RoutePlan, board: Board, opts: WritingOptions
) -> RoutePlan:
    """``plan`` re-segmented as :func:`plan_writing` does (kept only if still faithful)."""
    if opts.resegment == "off" or opts.resegment_iterations == 0:
        return plan
    return resegmented(samples, plan, board, opts)


def _cuts(samples: RouteSamples, board: Board) -> list[int]:
    """Route indices where the legs meet: the start, the end of the lift after every
    stroke but the last (``mission._route`` lifts the brush straight up there), the end."""
    lift = board.lift_m * board.normal
    cuts = [0]
    for i, stroke in enumerate(samples.strokes_world[:-1]):
        last = int(np.flatnonzero(samples.roles == i)[-1])
        gaps = np.linalg.norm(samples.points[last:] - (stroke[-1] + lift), axis=1)
        cuts.append(last + int(np.flatnonzero(gaps <= LIFT_MATCH_M)[0]))
    return [*cuts, len(samples.points) - 1]


def _sub(samples: RouteSamples, cuts: list[int], first: int, stop: int) -> RouteSamples:
    """The route of legs ``[first, stop)``: its samples, strokes renumbered from 0."""
    lo, hi = cuts[first], cuts[stop]
    roles = samples.roles[lo : hi + 1].copy()
    roles[roles >= 0] -= first
    corners = samples.corners[(samples.corners >= lo) & (samples.corners <= hi)] - lo
    return RouteSamples(
        samples.points[lo : hi + 1],
        roles,
        corners,
        samples.strokes_world[first:stop],
        samples.max_spans,
    )


def _plan_legs(
    samples: RouteSamples,
    cuts: list[int],
    span: tuple[int, int],
    board: Board,
    opts: WritingOptions,
) -> _Group:
    """Legs ``span = (first, stop)`` planned as one rest-to-rest spline."""
    return _Group(*span, _attempt(_sub(samples, cuts, *span), board, opts))


def _groups(
    samples: RouteSamples, cuts: list[int], board: Board, opts: WritingOptions
) -> list[_Group]:
    """Consecutive legs grouped greedily: each group the longest that still fits.

    A leg that does not fit on its own is kept as its own group (its plan
    unfaithful or ``None``), so the caller can say how far it strays.
    """
    n = len(samples.strokes_world)
    groups: list[_Group] = []
    first = 0
    while first < n:
        best = _plan_legs(samples, cuts, (first, first + 1), board, opts)
        while best.stop < n and best.plan is not None and best.plan.faithful(opts):
            longer = _plan_legs(samples, cuts, (first, best.stop + 1), board, opts)
            if longer.plan is None or not longer.plan.faithful(opts):
                break
            best = longer
        groups.append(best)
        first = best.stop
    return groups


def _joined(
    plans: tuple[RoutePlan, ...], target: UploadTarget
) -> tuple[Trajectory, tuple[tuple[float, float], ...]]:
    """The groups flown in order with hovers between, and their pen windows on its clock."""
    pieces: list[Trajectory] = []
    windows: list[tuple[float, float]] = []
    clock = 0.0
    for i, plan in enumerate(plans):
        spline = plan.fit.trajectory
        if i:
            rest = spline.evaluate(np.array([0.0]))[0]
            pieces.append(hover(rest, target.hover_s))
            clock += target.hover_s
        pieces.append(spline)
        windows.extend((clock + a, clock + b) for a, b in plan.windows)
        clock += spline.duration
    return RestToRestSequence(tuple(pieces)), tuple(windows)


def _mission(
    plans: tuple[RoutePlan, ...],
    planned: tuple[Trajectory, tuple[tuple[float, float], ...]],
    samples: RouteSamples,
    board: Board,
    opts: WritingOptions,
) -> Mission:
    """The mission of ``plans`` (one: one upload, several: split); ``planned``: tip, pen windows."""
    assert opts.target is not None
    trajectory, windows = planned
    uploads = plan_uploads(trajectory, opts.target)  # the contract: raises if it does not fit
    strokes = samples.strokes_world
    # A split into one group would be the whole route again: it is tried as one upload.
    strategy: Strategy = "one-upload" if len(plans) == 1 else "split"
    deviation, contact = fidelity(trajectory, windows, strokes, board, opts)
    return Mission(
        tuple(p.fit for p in plans),
        trajectory,
        board,
        strokes,
        windows,
        deviation,
        max(p.scale for p in plans),
        0.0,  # set when it is returned (_timed)
        opts,
        TargetPlan(opts.target, strategy, uploads),
        contact,
    )


def _no_fit(
    whole: RoutePlan | None, groups: list[_Group] | None, opts: WritingOptions
) -> InfeasibleError:
    """What was measured, and the tolerances that would fit with it."""
    target = opts.target
    assert target is not None
    tol = opts.tolerance
    fits: list[str] = []
    tried: list[str] = []
    if "one-upload" in opts.target_strategies:
        if whole is None:
            tried.append(f"one upload of {target.max_pieces} pieces cannot meet the limits")
        else:
            stray = f"{1e3 * whole.deviation.max_m:.3g} mm"
            tried.append(
                f"one upload of {target.max_pieces} pieces strays {stray} "
                f"({whole.scale:.3g}x slower)"
            )
            fits.append(f"{stray} in one upload")
    if groups is not None:
        tried.append(_split_measured(groups, opts, fits))
    would = f"a tolerance of {' or '.join(fits)}, " if fits else ""
    return InfeasibleError(
        f"strokes: no plan for a {target.name} ({target.max_pieces} pieces of degree "
        f"{target.max_degree} per upload) within {opts.limits.describe()} and the tolerance "
        f"of {1e3 * tol:.3g} mm: {'; '.join(tried)}; expected within {1e3 * tol:.3g} mm; "
        f"{would}a larger size or best_effort would fit",
        ("fidelity", "target"),
    )


def _split_measured(groups: list[_Group], opts: WritingOptions, fits: list[str]) -> str:
    """The split's account; appends the tolerance that would fit it to ``fits``."""
    target = opts.target
    assert target is not None
    failing = [g for g in groups if g.plan is None or not g.plan.faithful(opts)]
    strokes = ", ".join(str(g.first) for g in failing)
    split = f"split at the pen-up points into {len(groups)} uploads, {target.hover_s:g} s hovers"
    if any(g.plan is None for g in failing):
        return f"{split}, stroke(s) {strokes} alone cannot meet the limits"
    worst = max(g.plan.deviation.max_m for g in failing if g.plan is not None)
    fits.append(f"{1e3 * worst:.3g} mm with {len(groups)} uploads")
    return f"{split}, stroke(s) {strokes} alone stray up to {1e3 * worst:.3g} mm"
