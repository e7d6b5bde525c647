"""The planned coverage flight (:class:`CoveragePlan`), its limits as the verifier states them, and
its limits report.
"""

from __future__ import annotations

import functools
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from shapely.geometry.base import BaseGeometry

from skyquill.coverage.missed import Missed
from skyquill.coverage.mission import Mission
from skyquill.coverage.plan.covering import path_length
from skyquill.coverage.plan.options import CoverageOptions
from skyquill.coverage.regions import Region, swept
from skyquill.coverage.speed import SpeedPlan
from skyquill.coverage.target import DeliveredPath
from skyquill.limits import BoxLimit, CylinderLimit, DerivativeLimit
from skyquill.trajectory import Samples, Trajectory
from skyquill.verify import Verification

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class CoveragePlan:
    """A planned coverage flight.

    Attributes
    ----------
    region : shapely.Polygon
    options : CoverageOptions
    waypoints : ndarray, shape (K, 2)
        The control polygon (spline patterns) or the stop points (zigzag-stop), m.
    path : ndarray, shape (M, 2)
        The flown path, densely sampled (every ~2 cm), m (with a target: the
        delivered flight's).
    trajectory : Trajectory
        The flight at ``options.altitude``, 3-D: a retimed path (spline
        patterns), straight legs (stop-and-go) or parts at rest between them;
        with a target, ``delivered.trajectory``.
    coverage : float
        Covered fraction of the region's area (by ``path``).
    limits : dict
        The dense check of ``trajectory`` against :func:`coverage_limits`
        (see :func:`limits_report`) and ``joins``.
    planning_time : float
        Wall time of the whole planning, s: of :func:`plan_coverage`, or of
        :func:`plan_tuned` with every candidate and estimate it tried.
    speed_plan : SpeedPlan or None
        The LP's plan (spline patterns only; with a target, of the planned
        path before it was re-fitted).
    delivered : DeliveredPath or None
        With ``options.target``: the re-fit into the target's uploads.
    planned_coverage : float or None
        With a target: the coverage of the planned path before the re-fit.
    missed : Missed or None
        What ``path``'s swath misses of the region (area, share, the largest
        gaps; holes are not the region's); None only for plans built by hand.
    mission : Mission or None
        For a region with holes or several fields: the pieces' mission, with
        where the spray is on and the keep-out check (``path`` is then the
        whole flight, transits included, and ``coverage`` counts only what
        is sprayed); None for a simple polygon (the spray is on throughout).
    """

    region: Region
    options: CoverageOptions
    waypoints: FloatArray
    path: FloatArray
    trajectory: Trajectory
    coverage: float
    limits: dict[str, Any]
    planning_time: float
    speed_plan: SpeedPlan | None
    delivered: DeliveredPath | None = None
    planned_coverage: float | None = None
    missed: Missed | None = None
    mission: Mission | None = None

    @property
    def pen_windows_s(self) -> tuple[tuple[float, float], ...]:
        """When the spray is on, ``(start, end)`` in s: throughout, or the mission's windows."""
        if self.mission is None:
            return ((0.0, self.duration),)
        return self.mission.pen_windows_s

    @property
    def duration(self) -> float:
        """Flight time from rest to rest, s."""
        return self.trajectory.duration

    def samples(self) -> Samples:
        """The trajectory sampled at ``options.rate`` (the setpoints a controller gets)."""
        return self.trajectory.sample(self.options.rate)

    @property
    def path_length(self) -> float:
        """Length of the flown path, m."""
        return path_length(self.path)

    @functools.cached_property
    def sprayed(self) -> BaseGeometry:
        """The area the spray sweeps, m: the mission's (off on its transits and within half a
        swath of the holes), or the whole path's swath (a polygon is sprayed throughout).

        What ``coverage`` counts within the region; the GeoJSON's covered area and the
        figure draw the same. A polygon's is the planner's simplified sweep (the raw buffer
        of a 20 km path's million points takes a minute; this one 0.2 s for a 10 ha field's
        1.1 M points: computed once).
        """
        if self.mission is not None:
            return self.mission.swept
        return swept(self.path, self.options.width)

    def summary(self) -> dict[str, Any]:
        """What ``summary.json`` holds (JSON-ready)."""
        lp = self.speed_plan
        target = self.delivered
        return {
            "pattern": self.options.pattern,
            "duration_s": self.duration,
            "path_length_m": self.path_length,
            "coverage_fraction": self.coverage,
            **self.limits,
            "planning_time_s": self.planning_time,
            "region_area_m2": float(self.region.area),
            **({} if self.missed is None else self.missed.summary()),
            **({} if self.mission is None else self.mission.summary()),
            "options": asdict(self.options),
            "vehicle_limits": self.options.limits.as_dict(),
            "limits_held": "per axis"
            if self.options.per_axis
            else (f"norms (acceleration and jerk by an inscribed {self.options.norm_sides}-gon)"),
            "lp": None
            if lp is None
            else {
                "grid_points": int(lp.u.size),
                "iterations": lp.iterations,
                "solve_time_s": lp.solve_time,
            },
        } | (
            {}
            if target is None
            else {"target": target.summary(), "planned_coverage_fraction": self.planned_coverage}
        )


def coverage_limits(options: CoverageOptions) -> tuple[DerivativeLimit, ...]:
    """The limits of a coverage flight (3-D, at constant height), as the verifier states them.

    The speed is the norm; acceleration and jerk the horizontal norms, or per
    axis when the options say so (the flight is level: the horizontal norm is
    the norm). Checked by their true shapes, whatever polygon the LP used.
    """

    def norm(order: int, bound: float) -> CylinderLimit:
        return CylinderLimit(order, bound, z_lower=-bound, z_upper=bound)

    if not options.per_axis:
        return (norm(1, options.vmax), norm(2, options.amax), norm(3, options.jmax))
    return (
        norm(1, options.vmax),
        BoxLimit.symmetric(2, options.amax, 3),
        BoxLimit.symmetric(3, options.jmax, 3),
    )


def limits_report(check: Verification) -> dict[str, Any]:
    """Largest speed, per-axis |acceleration| and |jerk|, and the largest relative excess."""
    return {
        "max_speed": check.max_speed,
        "max_acc": list(check.max_acc),
        "max_jerk": list(check.max_jerk),
        "max_excess": check.max_excess,
        "limits": check.limits_report(),
    }
