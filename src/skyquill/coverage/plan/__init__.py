"""Coverage missions end to end: region -> covering path -> timed, verified trajectory.

Three patterns, compared on equal terms (paper ``001_61beb0e01a19013a`` §4):

* ``spiral`` -- the paper's spiral spline (§1): contours, spiral control
  points with corner points at ``delta``, a degree-4 B-spline with
  Hartley-Judd knots, timed by the jerk-limited speed LP (§2);
* ``zigzag`` -- the fair baseline: the boustrophedon's waypoints through the
  *same* corner points, spline and speed LP;
* ``zigzag-stop`` -- the paper's baseline: straight legs, rest at every
  corner, each leg time-optimal under the same limits (Ruckig).

Concave regions are split into convex parts whose spirals (or zigzags) are
joined into one path (:mod:`skyquill.coverage.joined`, the paper's Fig. 5).
Regions with holes (keep-out zones) or of several fields are cut into
hole-free pieces, each planned as above, flown in one mission with the spray
off on the transits between them (:mod:`skyquill.coverage.mission`).

Modules, one job each: :mod:`.options` (:class:`CoverageOptions`),
:mod:`.covering` (the pattern's waypoints, its dense path and what it
covers), :mod:`.checks` (what is refused before any work), :mod:`.timing`
(the speed plan on a ladder of grids, stop-and-go legs, the dense check),
:mod:`.result` (:class:`CoveragePlan`, the limits as the verifier states
them), :mod:`.jerk` (the jerk-zigzag's plan), :mod:`.refit` (a vehicle's
upload budget), :mod:`.pieces` (a mission of hole-free pieces),
:mod:`.planner` (:func:`plan_coverage`) and :mod:`.tuning` (:func:`plan_tuned`).
"""

from skyquill.coverage.plan.checks import MAX_REGION_SIZE_M, PLANNING_S_PER_M
from skyquill.coverage.plan.covering import (
    COVERAGE_SPACING_M,
    GRID_POINTS,
    GRID_SPACING_M,
    MERGE_FRACTION,
    SPLINE_DEGREE,
    covering_path,
    covering_waypoints,
    grid_points,
    is_convex,
)
from skyquill.coverage.plan.options import (
    CONTOUR_MODES,
    DRIFT_MODES,
    PATTERNS,
    CoverageOptions,
    Pattern,
)
from skyquill.coverage.plan.planner import plan_coverage
from skyquill.coverage.plan.result import CoveragePlan, coverage_limits, limits_report
from skyquill.coverage.plan.timing import MAX_EXCESS
from skyquill.coverage.plan.tuning import TUNING_DELTAS, TUNING_EPSILONS, plan_tuned, tune_coverage

__all__ = [
    "CONTOUR_MODES",
    "COVERAGE_SPACING_M",
    "DRIFT_MODES",
    "GRID_POINTS",
    "GRID_SPACING_M",
    "MAX_EXCESS",
    "MAX_REGION_SIZE_M",
    "MERGE_FRACTION",
    "PATTERNS",
    "PLANNING_S_PER_M",
    "SPLINE_DEGREE",
    "TUNING_DELTAS",
    "TUNING_EPSILONS",
    "CoverageOptions",
    "CoveragePlan",
    "Pattern",
    "coverage_limits",
    "covering_path",
    "covering_waypoints",
    "grid_points",
    "is_convex",
    "limits_report",
    "plan_coverage",
    "plan_tuned",
    "tune_coverage",
]
