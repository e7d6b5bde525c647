"""The trajectory of a painting mission's flight, for the plan directory.

The mission model (:mod:`skyquill.painting.mission`) advances clocks; the path
it records (home, hover points, contacts, returns, landings) is flown here as
straight rest-to-rest legs, each time-optimal at its own speed (transit,
approach, retreat) within the configured acceleration and jerk norms
(:func:`skyquill.optimize.legs.stop_and_go`). The pen (the brush) is down at
the end of every approach that reached the wall. The hover before each
approach (``settle_s``) and the time on the ground between batteries are not
in it: the mission's ``flight_time_s`` counts them, this trajectory does not.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from skyquill.limits import DerivativeLimit, VehicleLimits
from skyquill.optimize.double_s import rest_to_rest
from skyquill.optimize.legs import LegLimits, stop_and_go
from skyquill.painting.mission import MissionConfig, MissionResult
from skyquill.trajectory import PiecewisePolynomial
from skyquill.validation import FloatArray


@dataclass(frozen=True)
class PaintingFlight:
    """The flown path as a trajectory.

    Attributes
    ----------
    trajectory
        Straight legs, at rest at every recorded point, world frame (x along the
        wall, y towards it, z up), m.
    pen_windows_s
        When the brush touches the wall (each a single instant: the end of an
        approach that touched), s.
    limits
        The norm limits it keeps (speed: the fastest leg).
    """

    trajectory: PiecewisePolynomial
    pen_windows_s: tuple[tuple[float, float], ...]
    limits: tuple[DerivativeLimit, ...]


def painting_flight(result: MissionResult, config: MissionConfig | None = None) -> PaintingFlight:
    """The trajectory of ``result``'s recorded path under ``config``'s speeds and limits."""
    cfg = config or MissionConfig()
    speeds = _speeds(cfg)
    legs = [
        LegLimits(speeds[kind], cfg.max_acceleration_mps2, cfg.max_jerk_mps3)
        for kind in result.leg_kinds
    ]
    flown = stop_and_go(result.path_w, legs)
    touched = _touched(result)
    windows = tuple(
        (float(flown.arrivals[k + 1]),) * 2
        for k, kind in enumerate(result.leg_kinds)
        if kind == "approach" and touched[k]
    )
    # Straight legs: the speed, acceleration and jerk along each are the norms.
    vehicle = VehicleLimits(max(speeds.values()), cfg.max_acceleration_mps2, cfg.max_jerk_mps3)
    limits = vehicle.derivative_limits(3)
    return PaintingFlight(flown.trajectory, windows, limits)


def _speeds(cfg: MissionConfig) -> dict[str, float]:
    """The speed of each kind of leg, m/s."""
    return {
        "transit": cfg.transit_speed_mps,
        "approach": cfg.approach_speed_mps,
        "retreat": cfg.retreat_speed_mps,
    }


#: Legs at least this long (m) count in :class:`FlightClock`: far above the repeats that
#: :func:`~skyquill.optimize.legs.stop_and_go` skips, so every leg counted is flown.
COUNTED_LEG_M = 1e-3


class FlightClock:
    """How long the flight's trajectory lasts at least, kept as the mission records its legs.

    :func:`painting_flight` times the recorded path as rest-to-rest legs; each leg of at
    least :data:`COUNTED_LEG_M` is timed here the same way (the closed-form profile at its
    kind's speed), so :attr:`at_least_s` is a lower bound of the trajectory's duration at
    every moment of the mission: a file too long for its readers can be refused while the
    mission is simulated, not after (10,000 dots at 100 Hz: 93 s of simulation before).

    Parameters
    ----------
    limit
        Told :attr:`at_least_s` after each :meth:`add`; raises to stop the mission.
    config
        The mission's speeds and limits.
    """

    def __init__(self, limit: Callable[[float], None], config: MissionConfig | None = None) -> None:
        cfg = config or MissionConfig()
        self._limit = limit
        self._speeds = _speeds(cfg)
        self._amax, self._jmax = cfg.max_acceleration_mps2, cfg.max_jerk_mps3
        self.at_least_s = 0.0

    def add(self, points_w: FloatArray, kinds: Sequence[str]) -> None:
        """Count the legs between ``points_w`` (K + 1, 3), m, of ``kinds`` (K,), then tell the
        limit."""
        if kinds:
            lengths = np.linalg.norm(np.diff(points_w, axis=0), axis=1)
            speeds = np.array([self._speeds[kind] for kind in kinds])
            counted = lengths >= COUNTED_LEG_M
            if counted.any():
                phases = rest_to_rest(lengths[counted], speeds[counted], self._amax, self._jmax)
                self.at_least_s += float(phases.sum())
        self._limit(self.at_least_s)


def _touched(result: MissionResult) -> list[bool]:
    """Per leg: whether it ends at a contact with the wall (a painted or measured point)."""
    marks = np.vstack([result.contacts_w, result.painted_w[np.isfinite(result.painted_w[:, 0])]])
    ends = result.path_w[1:]
    if marks.size == 0:
        return [False] * len(ends)
    # The nearest mark by a k-d tree: memory linear in legs and marks (the table of every
    # leg end against every mark took 13.5 GiB at the 10,000-dot ceiling).
    gap, _ = cKDTree(marks).query(ends, k=1)
    return [bool(g < 1e-9) for g in np.atleast_1d(gap)]
