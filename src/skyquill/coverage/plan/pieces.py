"""A region with holes or of several fields: a mission of hole-free pieces, each planned on its
own.
"""

from __future__ import annotations

import functools
import logging
import time
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray
from shapely.geometry import Polygon

from skyquill.coverage.cells import too_long_for_one_plan
from skyquill.coverage.congruent import Motions
from skyquill.coverage.deadline import Deadline
from skyquill.coverage.missed import missed_area
from skyquill.coverage.mission import fly_mission
from skyquill.coverage.plan.covering import is_convex
from skyquill.coverage.plan.options import CoverageOptions
from skyquill.coverage.plan.result import CoveragePlan, limits_report
from skyquill.coverage.plan.timing import within_limits
from skyquill.coverage.regions import (
    Region,
    has_keepouts,
)
from skyquill.errors import InfeasibleError
from skyquill.optimize.legs import LegLimits
from skyquill.parallel import HERE, Where
from skyquill.trajectory import Trajectory

FloatArray = NDArray[np.float64]
_log = logging.getLogger(__name__)
#: Plans one hole-free piece of a mission within a deadline.
PlanPiece = Callable[[Polygon, Deadline], CoveragePlan]


def in_pieces(region: Region, options: CoverageOptions) -> bool:
    """Whether ``region`` is flown as a mission of pieces: holes, several fields, a path
    too long to plan as one (pieces within the cap, cells where needed:
    :mod:`skyquill.coverage.cells`), or a concave field for the jerk-zigzag (whose lanes
    need a convex region)."""
    if has_keepouts(region) or not isinstance(region, Polygon):
        return True
    if too_long_for_one_plan(region, options.epsilon * options.width):
        return True
    return options.pattern == "zigzag-jerk" and not is_convex(region)


def plan_mission(
    region: Region,
    opts: CoverageOptions,
    deadline: Deadline,
    plan_piece: PlanPiece,
    *,
    zigzag: PlanPiece,
    where: Where = HERE,
) -> CoveragePlan:
    """The mission over ``region``'s hole-free pieces, each planned by ``plan_piece``.

    A spiral piece that cannot be timed within its share of the budget is
    planned by ``zigzag`` instead (see :func:`spiral_or_zigzag`). A piece that is a
    copy of another is not planned: the other's plan is moved onto it (see
    :func:`copy_motions` and :func:`~skyquill.coverage.mission.fly_mission`). ``where``: the
    pieces one after the other here, or at once in a pool or on a dask cluster (then
    ``plan_piece`` and ``zigzag`` must pickle: module-level functions or their partials).
    """
    start = time.perf_counter()
    legs = LegLimits(opts.vmax, opts.amax, opts.jmax, per_axis=opts.per_axis)
    planner = (
        plan_piece
        if opts.pattern != "spiral"
        else functools.partial(
            spiral_or_zigzag, spiral=plan_piece, zigzag=zigzag, field_area=region.area
        )
    )
    mission = fly_mission(
        region,
        opts.width,
        legs=legs,
        altitude=opts.altitude,
        deadline=deadline,
        plan_piece=functools.partial(_flight, plan_piece=planner),
        convex=opts.pattern in {"spiral", "zigzag-jerk"},
        where=where,
        copies=copy_motions(opts),
    )
    check = within_limits(mission.trajectory, opts, "mission", deadline)
    return CoveragePlan(
        region=region,
        options=opts,
        waypoints=mission.waypoints,
        path=mission.path,
        trajectory=mission.trajectory,
        coverage=mission.coverage,
        limits=limits_report(check) | {"joins": "stop"},
        planning_time=time.perf_counter() - start,
        speed_plan=None,
        missed=missed_area(region, mission.swept),
        mission=mission,
    )


def copy_motions(opts: CoverageOptions) -> Motions:
    """The motions by which a piece's plan is moved onto its copies in a mission.

    A shift keeps every planner's flight (to round-off) and every limit. A turn
    or mirror keeps norm limits but not per-axis ones, and not every planner's
    choices: fresh plans of mirrored pieces differ from the moved plan. Measured
    on 12 random mirror-symmetric fields with a hole in the middle (planned with
    and without moving): the spiral's convex parts -1.4 % to +0.3 % of flight
    (median -0.4 %), planning 0.66x; the zigzag-stop's concave pieces +2.3 % to
    +9.4 % (median +5.6 %: a mirrored zigzag starts at the far side), so only
    spirals under norm limits are moved by turns and mirrors.
    """
    return "rigid" if opts.pattern == "spiral" and not opts.per_axis else "translations"


#: Share of the remaining budget any spiral piece of a mission may spend before it is zigzagged.
SPIRAL_SHARE = 0.25


#: A large piece may spend this many times its fraction of the field's area (of the
#: remaining budget), up to :data:`MAX_SPIRAL_SHARE`: planning time per m² varies by piece
#: (the 10 ha field without holes: 0.4 ms/m²; its 2.2 ha part next to the holes: 2.5 ms/m²,
#: 54 s, of which one speed LP 43 s).
AREA_SHARE_FACTOR = 2.0


#: The largest share, leaving the rest of the budget to the zigzag and the other pieces.
MAX_SPIRAL_SHARE = 0.5


def spiral_share(piece_area: float, field_area: float) -> float:
    """The share of the remaining budget a spiral piece of ``piece_area`` (m²) may spend.

    :data:`SPIRAL_SHARE` for small pieces, :data:`AREA_SHARE_FACTOR` times the
    piece's fraction of ``field_area`` (m², holes excluded) for large ones, at most
    :data:`MAX_SPIRAL_SHARE`. A flat quarter starved the largest piece: the 2.2 ha
    part of the 10 ha field needs 54 s on a free core, 77 s with its neighbour
    planned at once on the other, and was zigzagged at 75 s.
    """
    by_area = AREA_SHARE_FACTOR * piece_area / field_area
    return min(MAX_SPIRAL_SHARE, max(SPIRAL_SHARE, by_area))


def spiral_or_zigzag(
    piece: Polygon,
    deadline: Deadline,
    *,
    spiral: PlanPiece,
    zigzag: PlanPiece,
    field_area: float,
) -> CoveragePlan:
    """``piece`` planned by ``spiral``, or by ``zigzag`` where its spiral takes over its
    share of the remaining budget (:func:`spiral_share`; ``field_area``: the mission's, m²)
    or cannot be timed.

    The speed LP of some convex parts stalls (a pentagon of 114 m² next to a
    round hole: no plan in 60 s, its mirror image in 3 s); one such part must
    not spend the whole mission's budget.
    """
    share = Deadline(spiral_share(piece.area, field_area) * deadline.remaining())
    try:
        return spiral(piece, share)
    except InfeasibleError as exc:
        deadline.check("a zigzag for a piece whose spiral failed")
        # (Not a warning: the mission still meets its coverage and limits, or is refused.)
        _log.info("piece of %.3g m²: spiral failed (%s), zigzag instead", piece.area, exc)
        return zigzag(piece, deadline)


def _flight(
    piece: Polygon, deadline: Deadline, *, plan_piece: PlanPiece
) -> tuple[Trajectory, FloatArray]:
    """For :func:`fly_mission`: the piece's planned trajectory and waypoints."""
    plan = plan_piece(piece, deadline)
    return plan.trajectory, plan.waypoints
