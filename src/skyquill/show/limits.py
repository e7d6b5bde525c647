"""Per-drone limits of a show: speeds, acceleration, altitude, geofence, sampled densely.

Each drone is sampled at the dense times of ``docs/architecture.md`` (at least
20 samples per piece and never fewer than 10,000), which is what "verified"
means for a single trajectory; unlike the separation these are measured, not
bounded between samples. The defaults are Skybrush's (Skybrush Studio's export
falls back to 8 m/s horizontally, 2 m/s vertically, 4 m/s^2 and 150 m).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from skyquill.errors import InputError
from skyquill.show.geofence import Geofence
from skyquill.show.load import ShowDrone
from skyquill.show.report import Measured, Violation
from skyquill.trajectory import dense_times, derivatives
from skyquill.validation import FloatArray, as_float

#: Largest relative excess over the speed and acceleration limits a check may allow.
MAX_TOLERANCE = 0.05


@dataclass(frozen=True)
class ShowLimits:
    """What every drone must keep; ``None`` leaves a limit unchecked.

    Attributes
    ----------
    max_speed_xy
        Horizontal speed, m/s.
    max_speed_up, max_speed_down
        Vertical speed upwards and downwards, m/s.
    max_acceleration
        Norm of the acceleration, m/s^2.
    min_altitude, max_altitude
        Altitude range (z), m.
    geofence
        Where the drones may fly (x, y) and its ceiling.
    tolerance
        Relative excess allowed over the speed and acceleration limits, in [0, 0.05]: a show
        as Skybrush plays it may be up to 1 % over its plan's limits (what its millimetre
        grid cannot avoid, ``skyquill.export.base.ALLOWED_EXCESS``); 0 holds them exactly.
    """

    max_speed_xy: float | None = 8.0
    max_speed_up: float | None = 2.0
    max_speed_down: float | None = 2.0
    max_acceleration: float | None = 4.0
    min_altitude: float | None = None
    max_altitude: float | None = 150.0
    geofence: Geofence | None = None
    tolerance: float = 0.0

    def __post_init__(self) -> None:
        tol = as_float("tolerance", self.tolerance, nonneg=True)
        if tol > MAX_TOLERANCE:
            raise InputError(f"tolerance: got {tol:g}, expected 0 to {MAX_TOLERANCE:g}")
        for name in ("max_speed_xy", "max_speed_up", "max_speed_down", "max_acceleration"):
            value = getattr(self, name)
            if value is not None:
                as_float(name, value, nonneg=True)
        for name in ("min_altitude", "max_altitude"):
            value = getattr(self, name)
            if value is not None:
                as_float(name, value)
        low, high = self.min_altitude, self.max_altitude
        if low is not None and high is not None and low > high:
            raise InputError(
                f"min_altitude: got {low:g} m above max_altitude {high:g} m, expected at most it"
            )


@dataclass(frozen=True)
class _Series:
    """One drone's dense samples on the show clock."""

    name: str
    t: FloatArray
    p: FloatArray
    v: FloatArray
    a: FloatArray


_ValueOf = Callable[[_Series], FloatArray]


def check_start(drones: Sequence[ShowDrone], geofence: Geofence) -> None:
    """Refuse a geofence that excludes a drone's start (bad input, not a failed show).

    Raises
    ------
    InputError
        Naming ``--geofence``, the drone and its start.
    """
    starts = np.array([d.trajectory.evaluate(np.zeros(1))[0] for d in drones])
    check_inside(starts, [f"{d.name}'s start" for d in drones], geofence, "--geofence")


def check_inside(
    points: FloatArray, labels: Sequence[str], geofence: Geofence, key: str, hint: str = ""
) -> None:
    """Refuse a geofence that leaves one of ``points`` (N, 3), m, outside or above it.

    Raises
    ------
    InputError
        Naming ``key`` (the option or script key that gave the fence), the first
        point outside by its label, how many are, and ``hint`` (what to change).
    """
    margin = geofence.margin(points[:, :2])
    ceiling = geofence.ceiling_m
    above = points[:, 2] > ceiling if ceiling is not None else np.zeros(len(points), bool)
    outside = np.flatnonzero((margin < 0.0) | above)
    if outside.size:
        k = int(outside[0])
        x, y, z = points[k]
        raise InputError(
            f"{key}: got a fence that excludes {labels[k]} ({x:.3f}, {y:.3f}, {z:.3f}) m "
            f"({outside.size} point(s) outside), expected one around every start{hint}"
        )


def check_limits(
    drones: Sequence[ShowDrone], limits: ShowLimits
) -> tuple[tuple[Violation, ...], tuple[Measured, ...]]:
    """Every limit of ``limits`` on every drone: the violations, and the worst value of each."""
    series = [_sampled(d) for d in drones]
    violations: list[Violation] = []
    measured: list[Measured] = []
    for check, limit, value_of, sense, slack in _checks(limits):
        worst: Measured | None = None
        for s in series:
            values = value_of(s)
            k = int(np.argmax(values * sense))
            if worst is None or values[k] * sense > worst.value * sense:
                worst = Measured(check, float(values[k]) + 0.0, limit, s.name, float(s.t[k]))
            if limit is not None:
                bad = np.flatnonzero(values * sense > limit * sense + slack)
                if bad.size:
                    violations.append(
                        Violation(
                            check=check,
                            drones=(s.name,),
                            first_time_s=float(s.t[bad[0]]),
                            worst=float(values[k]),
                            limit=limit,
                            margin=float((limit - values[k]) * sense),
                        )
                    )
        if worst is not None:
            measured.append(worst)
    return tuple(violations), tuple(measured)


def _sampled(drone: ShowDrone) -> _Series:
    traj = drone.trajectory
    t = dense_times(np.asarray(traj.breakpoints, dtype=float))
    d = derivatives(traj, t, (0, 1, 2))
    return _Series(drone.name, t + drone.start_s, d[0], d[1], d[2])


def _checks(limits: ShowLimits) -> list[tuple[str, float | None, _ValueOf, float, float]]:
    """``(name, limit, values of a drone, +1 for an upper / -1 for a lower bound, slack)``:
    the speeds and the acceleration may pass their limit by ``tolerance`` of it."""

    def slack(limit: float | None) -> float:
        return 0.0 if limit is None else limits.tolerance * abs(limit)

    checks: list[tuple[str, float | None, _ValueOf, float, float]] = [
        ("speed_xy", limits.max_speed_xy, _speed_xy, 1.0, slack(limits.max_speed_xy)),
        ("speed_up", limits.max_speed_up, _speed_up, 1.0, slack(limits.max_speed_up)),
        ("speed_down", limits.max_speed_down, _speed_down, 1.0, slack(limits.max_speed_down)),
        (
            "acceleration",
            limits.max_acceleration,
            _acceleration,
            1.0,
            slack(limits.max_acceleration),
        ),
        ("max_altitude", limits.max_altitude, _altitude, 1.0, 0.0),
        ("min_altitude", limits.min_altitude, _altitude, -1.0, 0.0),
    ]
    fence = limits.geofence
    if fence is not None:
        checks.append(("geofence", 0.0, lambda s: fence.margin(s.p[:, :2]), -1.0, 0.0))
        if fence.ceiling_m is not None:
            checks.append(("geofence_ceiling", fence.ceiling_m, _altitude, 1.0, 0.0))
    return checks


def _speed_xy(s: _Series) -> FloatArray:
    return np.asarray(np.hypot(s.v[:, 0], s.v[:, 1]))


def _speed_up(s: _Series) -> FloatArray:
    return s.v[:, 2]


def _speed_down(s: _Series) -> FloatArray:
    return np.asarray(-s.v[:, 2])


def _acceleration(s: _Series) -> FloatArray:
    return np.asarray(np.linalg.norm(s.a, axis=1))


def _altitude(s: _Series) -> FloatArray:
    return s.p[:, 2]
