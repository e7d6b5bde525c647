"""What is refused before any path is built: a region too large, a path too long, a budget too
short.
"""

from __future__ import annotations

from shapely.geometry import MultiPolygon, Polygon

from skyquill.coverage.cells import path_cap, too_long_for_one_plan
from skyquill.coverage.plan.options import CoverageOptions
from skyquill.coverage.plan.timing import MAX_EXCESS
from skyquill.coverage.regions import (
    Region,
    check_width,
    estimate_path_length,
    has_keepouts,
)
from skyquill.coverage.target import check_target_path
from skyquill.errors import InputError

#: Largest region side accepted, m (beyond it the LP grid would be too coarse).
MAX_REGION_SIZE_M = 1000.0


#: Planning time per metre of estimated path assumed before any work, s/m: measured
#: 0.7 ms/m (a 316 m square at a 5 m swath, 19.8 km, in 14.5 s on 2 shared cores),
#: rounded up. A budget below the estimate is refused at once rather than spent.
PLANNING_S_PER_M = 1e-3
#: The same for a region too long to plan as one, planned as a mission of pieces within
#: the cap (:func:`~skyquill.coverage.cells.too_long_for_one_plan`), s/m: measured 0.33 ms/m
#: on one worker (the 100 ha field at a 10 m swath, about 102 km: 15 pieces in 34 s, 20 s
#: on two), rounded up.
MISSION_PLANNING_S_PER_M = 5e-4


def check_region(region: Region, options: CoverageOptions) -> None:
    """Refuse a region too large, a path too long or a budget too short, before any path is
    built."""
    if not isinstance(region, Polygon | MultiPolygon):
        raise InputError(
            f"region: got {type(region).__name__}, expected a shapely Polygon or MultiPolygon"
        )
    minx, miny, maxx, maxy = region.bounds
    if max(maxx - minx, maxy - miny) > MAX_REGION_SIZE_M:
        raise InputError(
            f"region: got a region {maxx - minx:.4g} x {maxy - miny:.4g} m, expected at most "
            f"{MAX_REGION_SIZE_M:g} m across (split it into several missions)"
        )
    # A path too long for one plan is planned as pieces within its cap, up to the mission's.
    spacing = options.epsilon * options.width
    check_width(region, options.width, options.epsilon, path_cap(region, spacing))
    _check_budget(region, options)
    if options.target is not None:
        if has_keepouts(region) or too_long_for_one_plan(region, spacing):
            raise InputError(
                "target: got an upload target for a region with holes, several fields or "
                "a path too long for one plan, expected none (the re-fit would not keep the "
                "spray off over the transits)"
            )
        assert isinstance(region, Polygon)  # no keep-outs: one field
        check_target_path(region, options.width, options.epsilon, options.target)


def _check_budget(region: Region, options: CoverageOptions) -> None:
    """Refuse a time limit shorter than the estimated planning time (nothing is built)."""
    spacing = options.epsilon * options.width
    length = estimate_path_length(region, spacing)
    rate = MISSION_PLANNING_S_PER_M if too_long_for_one_plan(region, spacing) else PLANNING_S_PER_M
    need = rate * length
    if need > options.time_limit:
        raise InputError(
            f"time_limit: got {options.time_limit:g} s, expected at least {need:.3g} s for a "
            f"path of about {length / 1e3:.3g} km ({1e3 * rate:g} ms per metre "
            "estimated): allow more time, widen the swath or split the region"
        )


def least_flight_s(region: Region, options: CoverageOptions, coverage: float) -> float:
    """A lower bound on the flight that sprays ``coverage`` of ``region``, s.

    The swath sweeps at most ``width * speed`` m² a second, and a plan's speed is within
    :data:`~skyquill.coverage.plan.timing.MAX_EXCESS` of ``vmax``: what the outputs of a
    plan can be checked against before it is made (a 100 ha field at a 10 m swath and
    3 m/s: at least 9 h of flight).
    """
    sweep = options.width * options.vmax * (1.0 + MAX_EXCESS)
    return coverage * float(region.area) / sweep
