"""A coverage flight sized for a vehicle's trajectory memory (``--target``).

The speed LP's :class:`~skyquill.trajectory.RetimedPath` is not made of
polynomial pieces, and a coverage path is far longer than one Crazyflie
upload. With a target the planned path (its dense samples, every ~2 cm) is
re-fitted by the engine -- point deviation, rest at both ends, the vehicle's
limits held through the convex hull -- in degree-7 pieces, one upload if the
path tolerance allows, else chunks flown rest to rest with a hover between
uploads (:mod:`skyquill.optimize.budget`, shared with ``fit``).

The path tolerance, :data:`PATH_TOLERANCE_FRACTION` of the swath, bounds how
far the flight strays from the planned path (measured at every sample's
time, an upper bound of the distance between the paths), so the swath's
edge moves by at most that much; the coverage is measured again on the
delivered flight.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from shapely.geometry import Polygon

from skyquill.coverage.regions import estimate_path_length, what_fits
from skyquill.errors import InputError
from skyquill.limits import VehicleLimits
from skyquill.optimize.budget import MAX_UPLOADS, BudgetPlan, lifted
from skyquill.optimize.fit import FitOptions, fit_points
from skyquill.targets import UploadTarget
from skyquill.trajectory import Trajectory
from skyquill.validation import FloatArray

#: Largest distance of the delivered flight from the planned path, as a fraction
#: of the swath width (5 %: 10 cm of a 2 m swath). Neighbouring passes overlap
#: by a few % of the swath at corners anyway, and the coverage is measured on
#: the delivered flight. On the bundled regions the planned paths fit in one or
#: two Crazyflie uploads at this tolerance (at 2.5 % in one or two as well, but
#: up to 23 % slower).
PATH_TOLERANCE_FRACTION = 0.05
#: Longest planned path flown with a target, m: the bundled regions' paths fit
#: 20-50 m per upload, so :data:`~skyquill.optimize.budget.MAX_UPLOADS` uploads
#: hold about a kilometre at best (checked from the area before any path is built).
MAX_TARGET_PATH_M = 1000.0
#: Spacing of the delivered flight's samples that coverage is measured on, m.
SAMPLE_SPACING_M = 0.02


@dataclass(frozen=True, eq=False)
class DeliveredPath:
    """The planned path re-fitted into a target's uploads.

    Attributes
    ----------
    budget
        The uploads (strategy, pieces, times) of the 2-D fit.
    trajectory
        The flight at the coverage altitude, 3-D: a spline, or splines and
        hovers flown rest to rest.
    path
        The delivered flight's horizontal path, shape (M, 2), m, sampled about
        every :data:`SAMPLE_SPACING_M`.
    tolerance_m
        The path tolerance held, m.
    max_deviation_m, rms_deviation_m
        Distance of the flight from the planned path's samples at their times, m.
    """

    budget: BudgetPlan
    trajectory: Trajectory
    path: FloatArray
    tolerance_m: float
    max_deviation_m: float
    rms_deviation_m: float

    def summary(self) -> dict[str, Any]:
        """The ``"target"`` section of ``summary.json`` (SI units)."""
        return self.budget.summary() | {
            "path_tolerance_m": self.tolerance_m,
            "path_tolerance": f"{100 * PATH_TOLERANCE_FRACTION:g} % of the swath width",
            "max_path_deviation_m": self.max_deviation_m,
            "rms_path_deviation_m": self.rms_deviation_m,
        }


def check_target_path(region: Polygon, width: float, epsilon: float, target: UploadTarget) -> None:
    """Refuse, before any path is built, a path too long for :data:`MAX_TARGET_PATH_M`."""
    length = estimate_path_length(region, epsilon * width)
    if length > MAX_TARGET_PATH_M:
        raise InputError(
            f"target: got a path of about {length:.4g} m (width {width:g} m), expected at most "
            f"{MAX_TARGET_PATH_M:g} m for a {target.name} (at most {MAX_UPLOADS} uploads; "
            f"{what_fits(region, epsilon, MAX_TARGET_PATH_M)})"
        )


def deliver(
    path: FloatArray,
    limits: VehicleLimits,
    width: float,
    altitude: float,
    target: UploadTarget,
) -> DeliveredPath:
    """Re-fit the planned ``path`` (M, 2), m, into ``target``'s uploads at ``altitude``, m.

    Raises
    ------
    InfeasibleError
        The path needs more than :data:`~skyquill.optimize.budget.MAX_UPLOADS`
        uploads within the tolerance, or the limits cannot be met.
    """
    tolerance = PATH_TOLERANCE_FRACTION * width
    # Exact norms (cones): the refit holds the limits the LP only approximated.
    options = FitOptions(limits=limits, tolerance_m=tolerance, target=target)
    fit = fit_points(path, None, options)
    assert fit.budget is not None  # a target always gives a budget plan
    return DeliveredPath(
        budget=fit.budget,
        trajectory=lifted(fit.trajectory, altitude),
        path=_sampled(fit.trajectory, limits.timing_bounds()[0]),
        tolerance_m=tolerance,
        max_deviation_m=fit.max_deviation_m,
        rms_deviation_m=fit.rms_deviation_m,
    )


def _sampled(traj: Trajectory, vmax: float) -> FloatArray:
    """Positions of ``traj`` at most :data:`SAMPLE_SPACING_M` apart (at speeds up to ``vmax``)."""
    n = max(2, math.ceil(traj.duration * vmax / SAMPLE_SPACING_M) + 1)
    return np.asarray(traj.evaluate(np.linspace(0.0, traj.duration, n))[:, :2])
