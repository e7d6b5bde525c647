"""``skyquill check``'s verdict on a show: guaranteed separation, then every drone's limits."""

from __future__ import annotations

from collections.abc import Sequence

from skyquill.errors import InfeasibleError, InputError
from skyquill.show.limits import ShowLimits, check_limits, check_start
from skyquill.show.load import ShowDrone
from skyquill.show.motion import motion_of
from skyquill.show.report import ShowReport, Violation
from skyquill.show.separation import TOLERANCE_M, Separation, guaranteed_separation
from skyquill.validation import as_float

#: Skybrush's default distance between drones outdoors, m.
MIN_DISTANCE_M = 3.0


def separation_of(
    drones: Sequence[ShowDrone], min_distance_m: float, tolerance_m: float = TOLERANCE_M
) -> Separation:
    """The guaranteed closest approach of ``drones`` on the show clock.

    Drones wait at their start before their ``start_s`` and hold their last
    position after they finish, until the last one has finished. The bound is
    refined to within ``tolerance_m`` of the closest distance seen (m).
    """
    horizon = max(d.end_s for d in drones)
    motions = [motion_of(d.name, d.trajectory, horizon, d.start_s) for d in drones]
    return guaranteed_separation(motions, min_distance_m, tolerance_m=tolerance_m)


def require_separation(
    drones: Sequence[ShowDrone], minimum_m: float, what: str, hint: str = ""
) -> Separation:
    """:func:`separation_of`, refused below ``minimum_m``.

    Raises
    ------
    InfeasibleError
        Naming ``what`` (the stage: ``"transition"``, ``"write"``...), the closest pair
        by their names, how close and when, and ``hint`` (what to change), if any.
    """
    result = separation_of(drones, minimum_m)
    if not result.passed:
        e = result.encounters[0]
        first, second = (drones[k].name for k in e.drones)
        raise InfeasibleError(
            f"{what}: {first} and {second} come within {e.closest_m:.3f} m at "
            f"t = {e.closest_time_s:.2f} s, expected at least {minimum_m:g} m{hint}",
            ("separation",),
        )
    return result


def check_show(
    drones: Sequence[ShowDrone],
    min_distance_m: float = MIN_DISTANCE_M,
    limits: ShowLimits | None = None,
) -> ShowReport:
    """Check a show: pairwise distance (guaranteed), speeds, acceleration, altitude, geofence.

    Parameters
    ----------
    drones
        The show (:func:`skyquill.show.load_show`).
    min_distance_m
        Distance two drones must keep, m, >= 0.
    limits
        Per-drone limits; Skybrush's defaults (:class:`ShowLimits`) when ``None``.

    Raises
    ------
    InputError
        No drone, a negative distance, or a geofence that excludes a drone's start.
    """
    if not drones:
        raise InputError("drones: got none, expected at least one")
    minimum = as_float("min_distance_m", min_distance_m, nonneg=True)
    limits = limits or ShowLimits()
    if limits.geofence is not None:
        check_start(drones, limits.geofence)
    separation = separation_of(drones, minimum)
    names = tuple(d.name for d in drones)
    close = [
        Violation(
            check="separation",
            drones=(names[e.drones[0]], names[e.drones[1]]),
            first_time_s=e.first_time_s,
            worst=e.closest_m,
            limit=minimum,
            margin=e.margin_m,
        )
        for e in separation.encounters
    ]
    broken, measured = check_limits(drones, limits)
    return ShowReport(
        drones=names,
        duration_s=max(d.end_s for d in drones),
        separation=separation,
        violations=(*close, *sorted(broken, key=lambda v: (v.first_time_s, v.check))),
        measured=measured,
    )
