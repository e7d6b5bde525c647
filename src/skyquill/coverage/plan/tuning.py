"""``plan_tuned``: the fastest plan whose path covers a goal, over spacings and corners."""

from __future__ import annotations

import functools
import math
import time
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray
from shapely.geometry import Polygon

from skyquill.coverage import DEFAULT_MIN_COVERAGE
from skyquill.coverage.cells import too_long_for_one_plan
from skyquill.coverage.deadline import (
    Deadline,
    Progress,
    is_time_limit,
)
from skyquill.coverage.paths import spiral_curve
from skyquill.coverage.plan.checks import check_region
from skyquill.coverage.plan.covering import covering_path
from skyquill.coverage.plan.jerk import plan_jerk
from skyquill.coverage.plan.options import CoverageOptions
from skyquill.coverage.plan.pieces import in_pieces, plan_mission
from skyquill.coverage.plan.planner import plan_within, zigzag_piece
from skyquill.coverage.plan.refit import for_target
from skyquill.coverage.plan.result import CoveragePlan
from skyquill.coverage.regions import (
    Region,
    coverage_fraction,
)
from skyquill.coverage.speed import plan_speed
from skyquill.errors import InfeasibleError, InputError
from skyquill.parallel import HERE, Where
from skyquill.validation import as_float

FloatArray = NDArray[np.float64]


#: Candidates of :func:`tune_coverage`.
TUNING_EPSILONS = (1.0, 0.9, 0.8, 0.7)


TUNING_DELTAS = (2.0, 1.5, 1.0, 0.6, 0.3, 0.15)


#: Share of the allowed miss a mission's pieces are tuned to (the rest is the holes').
MISSION_MISS_SHARE = 0.5


#: Tuning candidates planned in full (best estimated first; see :func:`_estimated_duration`),
#: and how far above the best estimate a second one may be (the estimate's ranking erred
#: by 2 % on the held-out regions).
TUNED_FULL_PLANS = 2


ESTIMATE_MARGIN = 1.05


#: The estimate's speed-LP grid points and pseudo-jerk iterations.
ESTIMATE_GRID = 300


ESTIMATE_JERK_ITERATIONS = 3


def tune_coverage(
    region: Polygon, options: CoverageOptions, target: float
) -> tuple[CoverageOptions, float]:
    """The fastest options whose path covers ``target`` of the region, and their coverage.

    See :func:`plan_tuned`, which also returns the plan.
    """
    plan = plan_tuned(region, options, target)
    return plan.options, plan.coverage


def plan_tuned(
    region: Region,
    options: CoverageOptions,
    target: float = DEFAULT_MIN_COVERAGE,
    *,
    progress: Progress | None = None,
    where: Where = HERE,
) -> CoveragePlan:
    """The fastest plan whose path covers ``target`` of the region.

    For every ``epsilon`` in :data:`TUNING_EPSILONS` and, for zigzags, without
    and with a perimeter lap, the roundest corners that still reach
    ``target`` are found by geometry alone: ``delta`` in :data:`TUNING_DELTAS`
    from the largest down (at one spacing a larger ``delta`` is shorter and
    faster; the stop-and-go zigzag has no ``delta``). The candidates are
    ranked by a coarse speed LP (:func:`_estimated_duration`; path length
    alone misjudges them: a denser spacing with rounder corners can fly
    faster than a wider one with sharp corners), the best
    :data:`TUNED_FULL_PLANS` are planned in full and the shortest flight wins.

    All trials share one ``options.time_limit``; ``progress`` is told every
    step (see :class:`~skyquill.coverage.deadline.Deadline`). ``where``: where a
    mission's pieces are tuned (see :func:`~skyquill.coverage.plan.plan_coverage`).

    Raises
    ------
    InfeasibleError
        No candidate reaches ``target``, or none that does can be timed; the
        time limit is spent (family ``"time_limit"``).
    """
    start = time.perf_counter()
    goal = as_float("min_coverage", target, positive=True)
    if goal > 1.0:
        raise InputError(f"min_coverage: got {goal:g}, expected a fraction in (0, 1]")
    check_tuned_region(region, options)
    deadline = Deadline(options.time_limit, progress)
    if options.target is not None:
        # Trials are compared as planned; only the winner is re-fitted for the target.
        untargeted = _tuned(region, replace(options, target=None), goal, deadline, where)
        plan = for_target(untargeted, replace(untargeted.options, target=options.target), deadline)
    else:
        plan = _tuned(region, options, goal, deadline, where)
    # The whole planning: every candidate and estimate, not only the winner's own plan.
    return replace(plan, planning_time=time.perf_counter() - start)


def check_tuned_region(region: Region, options: CoverageOptions) -> None:
    """Refuse what :func:`plan_tuned` refuses before any work (a region too large, a path too
    long, a budget too short): the sparsest spacing it tries must fit the path-length cap
    and the budget; denser ones that do not are skipped (a 10 ha field at a 5 m swath)."""
    check_region(region, replace(options, epsilon=max(TUNING_EPSILONS)))


def _tuned(
    region: Region,
    options: CoverageOptions,
    goal: float,
    deadline: Deadline,
    where: Where = HERE,
) -> CoveragePlan:
    """:func:`plan_tuned` after its checks, within ``deadline``."""
    if in_pieces(region, options):
        return _tuned_mission(region, options, goal, deadline, where)
    if options.pattern == "zigzag-jerk":
        return plan_jerk(region, options, deadline, goal)
    deltas = (options.delta,) if options.pattern == "zigzag-stop" else TUNING_DELTAS
    laps = (False,) if options.pattern == "spiral" else (False, True)
    candidates: list[tuple[CoverageOptions, FloatArray]] = []
    best = 0.0
    roundest = max(deltas)
    for lap in laps:
        # Spacings from the widest: once one reaches the goal with the roundest
        # corners, a denser one (more and longer lanes, corners no rounder)
        # cannot fly faster, and is not tried.
        for eps in _fitting_epsilons(region, options):
            found = _roundest_reaching(region, replace(options, epsilon=eps, perimeter=lap),
                                       deltas, goal, deadline)  # fmt: skip
            best = max(best, found[2])
            if found[0] is not None:
                candidates.append((found[0], found[1]))
                if found[0].delta == roundest:
                    break
    if not candidates:
        raise InfeasibleError(
            f"min_coverage: got {goal:g}, but the best {options.pattern} path covers only "
            f"{best:.4f} of the region (tried epsilon {TUNING_EPSILONS}, delta {deltas})",
            ("coverage",),
        )
    plans = _best_planned(region, candidates, deadline)
    if not plans:
        raise InfeasibleError(
            f"min_coverage: {len(candidates)} {options.pattern} path(s) cover {goal:g} of the "
            "region, but none of them could be timed within the limits",
            ("coverage", "speed_lp"),
        )
    return min(plans, key=lambda plan: plan.duration)


def _roundest_reaching(
    region: Polygon,
    options: CoverageOptions,
    deltas: tuple[float, ...],
    goal: float,
    deadline: Deadline,
) -> tuple[CoverageOptions | None, FloatArray, float]:
    """The roundest corners (largest ``delta``) whose path covers ``goal``: the options (None
    if none does), their waypoints and the best coverage seen."""
    best = 0.0
    for delta in sorted(deltas, reverse=True):
        trial = replace(options, delta=delta)
        deadline.check(f"the tuning trial epsilon={trial.epsilon:g}, delta={delta:g}")
        waypoints, path = covering_path(region, trial)
        covered = coverage_fraction(region, path, trial.width)
        best = max(best, covered)
        if covered >= goal:
            return trial, waypoints, best
    return None, np.zeros((0, 2)), best


def _fitting_epsilons(region: Polygon, options: CoverageOptions) -> list[float]:
    """The tuning's spacings whose estimated path fits one plan's length cap and the budget."""
    fitting = []
    for eps in TUNING_EPSILONS:
        if too_long_for_one_plan(region, eps * options.width):
            continue
        try:
            check_region(region, replace(options, epsilon=eps))
        except InputError:
            continue
        fitting.append(eps)
    return fitting


def _tuned_mission(
    region: Region, options: CoverageOptions, goal: float, deadline: Deadline, where: Where
) -> CoveragePlan:
    """The mission with each hole-free piece tuned to leave :data:`MISSION_MISS_SHARE` of
    the miss ``goal`` allows.

    A mission covers less than its pieces do: the spray closes where a
    piece's path comes within half a swath of a hole (the headland laps
    round the holes sweep most of that band back), and what the planning
    obstacles add to the holes is missed.

    Raises
    ------
    InfeasibleError
        The mission does not reach ``goal`` (family ``"coverage"``; the
        message says how close it came), or the time limit is spent.
    """
    piece_goal = 1.0 - MISSION_MISS_SHARE * (1.0 - goal)
    tune = functools.partial(_tuned_piece, options=options, goal=piece_goal)
    plan = plan_mission(
        region,
        options,
        deadline,
        tune,
        zigzag=functools.partial(_tuned_zigzag_piece, options=options, goal=piece_goal),
        where=where,
    )
    if plan.coverage < goal:
        raise InfeasibleError(
            f"min_coverage: got {goal:g}, but the {options.pattern} mission covers "
            f"{plan.coverage:.4f} of the region with its pieces at {piece_goal:g} (the spray "
            "closes within half a swath of the holes); ask for less coverage or try the "
            "zigzag pattern",
            ("coverage",),
        )
    return plan


def _tuned_piece(
    piece: Polygon, deadline: Deadline, *, options: CoverageOptions, goal: float
) -> CoveragePlan:
    return _tuned(piece, options, goal, deadline)


def _tuned_zigzag_piece(
    piece: Polygon, deadline: Deadline, *, options: CoverageOptions, goal: float
) -> CoveragePlan:
    """A spiral piece's fallback in a tuned mission: the zigzag tuned to the pieces' ``goal``.

    The plain zigzag (one swath apart, no perimeter lap) leaves a strip along
    the piece's sides: a 1.2 ha part of the 10 ha field whose spiral could not
    be timed was flown at 97.3 % and the mission refused at 98.95 %; tuned
    (a perimeter lap) it covers 99.5 % in 2.6 s of planning. Where no zigzag
    reaches the goal (a 108 m² right triangle left by an octagonal obstacle:
    96 % at best, its 45° corners out of the swath's reach; the headland lap
    round the hole sweeps most of it), the plain zigzag is flown: the
    mission's coverage, measured on the flown path, decides.
    """
    zigzag = replace(options, pattern="zigzag")
    try:
        return _tuned(piece, zigzag, goal, deadline)
    except InfeasibleError as exc:
        if is_time_limit(exc):
            raise
        return zigzag_piece(piece, deadline, options=options)


def _best_planned(
    region: Polygon, candidates: list[tuple[CoverageOptions, FloatArray]], deadline: Deadline
) -> list[CoveragePlan]:
    """The candidates planned in full: the best estimated that plans, and the next ones
    estimated within :data:`ESTIMATE_MARGIN` of it, at most :data:`TUNED_FULL_PLANS`."""
    if candidates[0][0].pattern == "zigzag-stop":  # no LP: planning it is the estimate
        return [p for trial, _ in candidates if (p := _plan_or_none(region, trial, deadline))]
    estimates = []
    for trial, waypoints in candidates:
        deadline.check(f"the estimate of epsilon={trial.epsilon:g}, delta={trial.delta:g}")
        estimates.append(_estimated_duration(waypoints, trial, deadline))
    plans: list[CoveragePlan] = []
    for k in np.argsort(estimates, kind="stable"):
        if plans and estimates[k] > ESTIMATE_MARGIN * min(estimates):
            break
        if (plan := _plan_or_none(region, candidates[k][0], deadline)) is not None:
            plans.append(plan)
        if len(plans) == TUNED_FULL_PLANS:
            break
    return plans


def _estimated_duration(
    waypoints: FloatArray, options: CoverageOptions, deadline: Deadline
) -> float:
    """The flight time of ``waypoints``' spline by a coarse speed LP, s (inf: not timed).

    :data:`ESTIMATE_GRID` points, :data:`ESTIMATE_JERK_ITERATIONS` pseudo-jerk
    solves, no refinement: ~0.1 s where the full plan takes 1-7 s. On the held-out
    regions (a 47 x 30 m concave hexagon, a triangle, a star, the paper's square;
    spiral and zigzag at 99 %) it came out 2-25 % above the full plan's time but
    ranked the candidates so that the best of the first two planned in full was the
    fastest of all, or within 1 % of it.
    """
    try:
        speed = plan_speed(
            spiral_curve(waypoints), options.vmax, options.amax, options.jmax,
            n=ESTIMATE_GRID, jerk_iterations=ESTIMATE_JERK_ITERATIONS, refine_rounds=0,
            max_excess=None, norm_sides=options.limit_norm_sides, deadline=deadline,
        )  # fmt: skip
    except InfeasibleError as exc:
        if is_time_limit(exc):
            raise
        return math.inf
    return float(speed.duration)


def _plan_or_none(
    region: Polygon, options: CoverageOptions, deadline: Deadline
) -> CoveragePlan | None:
    """The plan, or ``None`` where the path cannot be timed within the limits.

    A spent budget is not such a path: it is raised.
    """
    try:
        return plan_within(region, options, deadline)
    except InfeasibleError as exc:
        if is_time_limit(exc):
            raise
        return None
