"""The ``settings.validation`` of a Skybrush show, filled from the plan.

Skybrush Live warns when a show leaves these bounds (skybrush-io/live
``src/features/validation/selectors.ts``: ``maxAltitude``, ``maxVelocityXY``,
``maxVelocityZ`` downwards and ``maxVelocityZUp`` upwards, the same three for the
acceleration, ``minDistance``; the types in skybrush-io/skybrush.js
``packages/show-format/src/types.ts``). The speeds and accelerations come from the plan's
limits, stated as Skybrush states them (horizontal norm, vertical up and down), raised where
the played curves go beyond them (within the excess an export allows over a limit, a
millimetre grid's rounding: :data:`~skyquill.export.base.ALLOWED_EXCESS`): the settings
written are ones the played curves meet. The altitude and the distance between drones are
measured on the trajectories; every measured value is rounded outwards to the millimetre
(per second, per second squared), so that the show passes its own validation.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from skyquill.limits import BoxLimit, CylinderLimit, DerivativeLimit, NormLimit
from skyquill.trajectory import Trajectory, dense_times, derivatives

#: How close to the true closest approach ``minDistance`` is proven, m.
MIN_DISTANCE_TOLERANCE_M = 1e-3
#: Names of the bounds per derivative order: (horizontal, down, up).
KEYS = {
    1: ("maxVelocityXY", "maxVelocityZ", "maxVelocityZUp"),
    2: ("maxAccelerationXY", "maxAccelerationZ", "maxAccelerationZUp"),
}


def _bounds(limit: DerivativeLimit) -> tuple[float, float, float] | None:
    """(horizontal, down, up) bounds a 3-D limit implies, or ``None`` for another dimension."""
    if isinstance(limit, NormLimit):
        return (limit.radius,) * 3 if limit.dim == 3 else None
    if isinstance(limit, CylinderLimit):
        if limit.z_lower is None or limit.z_upper is None:
            return None
        return limit.radius, -limit.z_lower, limit.z_upper
    if isinstance(limit, BoxLimit) and limit.dim == 3:
        reach = np.maximum(np.abs(limit.lower), np.abs(limit.upper))
        return float(np.hypot(reach[0], reach[1])), float(-limit.lower[2]), float(limit.upper[2])
    return None


def _positions(trajectory: Trajectory, t: np.ndarray) -> np.ndarray:
    # A drone that has finished holds its last position.
    return trajectory.evaluate(np.minimum(t, trajectory.duration))


def validation_settings(
    limits: Sequence[Sequence[DerivativeLimit]], trajectories: Sequence[Trajectory]
) -> dict[str, float]:
    """Skybrush's validation settings for a show.

    Parameters
    ----------
    limits
        Each drone's limits.
    trajectories
        Each drone's trajectory as it will fly, z up, m, on the show clock.

    Returns
    -------
    dict
        ``maxAltitude`` (m), the speed and acceleration bounds that the limits imply (the
        tightest over all drones; a bound no limit implies is left out), each raised to what
        the trajectories reach where they go beyond it, and ``minDistance`` (m) when there
        are two drones or more.
    """
    settings: dict[str, float] = {}
    played = _played_maxima(trajectories)
    for order, keys in KEYS.items():
        found = [_bounds(lim) for lims in limits for lim in lims if lim.order == order]
        implied = [b for b in found if b is not None]
        for i, key in enumerate(keys):
            if implied:
                bound = min(b[i] for b in implied)
                settings[key] = max(bound, math.ceil(played[order][i] * 1000) / 1000)
    top = max(float(_positions(t, dense_times(t.breakpoints))[:, 2].max()) for t in trajectories)
    settings["maxAltitude"] = math.ceil(top * 1000) / 1000
    if len(trajectories) > 1:
        settings["minDistance"] = math.floor(_closest(trajectories) * 1000) / 1000
    return settings


def _played_maxima(trajectories: Sequence[Trajectory]) -> dict[int, tuple[float, float, float]]:
    """Per order (1, 2): the largest (horizontal, down, up) value over every drone, sampled
    densely (both orders from one lookup of each drone's pieces)."""
    worst = {order: np.zeros(3) for order in KEYS}
    for traj in trajectories:
        for order, d in derivatives(traj, dense_times(traj.breakpoints), tuple(KEYS)).items():
            here = [
                float(np.hypot(d[:, 0], d[:, 1]).max()),
                float(-d[:, 2].min()),
                float(d[:, 2].max()),
            ]
            worst[order] = np.maximum(worst[order], here)
    return {order: (float(w[0]), float(w[1]), float(w[2])) for order, w in worst.items()}


def _closest(trajectories: Sequence[Trajectory]) -> float:
    """The closest two drones come, m: guaranteed (:mod:`skyquill.show.separation`, bounded
    between samples, to within :data:`MIN_DISTANCE_TOLERANCE_M`), so the show passes Skybrush's
    check of it however densely Skybrush samples."""
    from skyquill.show import ShowDrone, separation_of

    drones = [ShowDrone(traj, f"drone {i}") for i, traj in enumerate(trajectories)]
    # A bound between samples may dip below 0 where two drones meet: a distance is >= 0.
    return max(0.0, separation_of(drones, 0.0, MIN_DISTANCE_TOLERANCE_M).lower_bound_m)
