"""A delivered flight's phases: take-off, mission, landing, above a minimum flight altitude.

A plan is a trajectory; a *flight* takes off before it and lands after it. Every plan is
split on its own clock into

* **take-off** ``[0, t_mission_start]``: from the start until the first instant at which
  the plan is at rest at or above the minimum altitude (empty when it starts so: then the
  consumer takes off to the plan's first point by its own means, a Crazyflie's ``takeoff``
  command, PX4's ``takeoff`` action, a climb the Skybrush export adds);
* **mission** ``[t_mission_start, t_mission_end]``: nothing in it is below the minimum
  altitude, except on a *ground stop* (a landing to change batteries, paint's): the plan
  comes to rest below the minimum altitude between two rests above it;
* **landing** ``[t_mission_end, duration]``: from the last rest at or above the minimum
  altitude to the end.

The minimum altitude is above the ground (``z = ground_m``, 0: skyquill's world frame has
z up from the ground). A plan whose mission goes below it elsewhere, or that never rests
above it, cannot be delivered: :func:`flight_phases` refuses it with the time and height.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from skyquill.errors import InfeasibleError, InputError
from skyquill.limits import DerivativeLimit, limit_bounds
from skyquill.trajectory import (
    PiecewisePolynomial,
    RestToRestSequence,
    Trajectory,
    dense_times,
)
from skyquill.validation import FloatArray, as_float

#: Default minimum flight altitude above the ground, m (the ground effect below it).
MIN_ALTITUDE_M = 0.3
#: Highest minimum altitude accepted, m (a stated ceiling: the show's 120 m less room).
MAX_MIN_ALTITUDE_M = 100.0
#: Default altitude a 2-D plan is flown at, m.
DEFAULT_ALTITUDE_M = 1.0
#: Highest altitude accepted for a 2-D plan, m (a common legal ceiling for drones).
MAX_ALTITUDE_M = 120.0
#: Largest speed (m/s) and acceleration (m/s^2) that count as rest.
REST_TOLERANCE = 1e-6
#: A sampled speed below which a local minimum is refined to see whether it is a rest, m/s.
SLOW_MPS = 0.05
#: How far below the minimum altitude the plan may touch it (round-off), m.
ALTITUDE_TOLERANCE_M = 1e-6
#: Limits of a take-off or landing leg added to a plan that states none.
DEFAULT_LEG_LIMITS = {1: 1.0, 2: 2.0, 3: 10.0}


@dataclass(frozen=True)
class FlightPhases:
    """When a plan takes off, flies its mission and lands, on its own clock.

    Attributes
    ----------
    takeoff_s, mission_s, landing_s
        ``(start, end)`` of each phase, s; the take-off and landing may be empty.
    min_altitude_m
        Nothing in the mission is below it (above the ground), m.
    ground_m
        Height of the ground (the pads) in the plan's frame, m.
    first_point_m, last_point_m
        Where the mission starts and ends (x, y, z), m: the first airborne point a
        consumer takes off to, the last one it lands from.
    lowest_m
        The lowest altitude above the ground in the mission (ground stops aside), m.
    ground_stops_s
        Landings inside the mission: ``(start, end)`` from the last rest above the minimum
        altitude before each to the first one after, s.
    """

    takeoff_s: tuple[float, float]
    mission_s: tuple[float, float]
    landing_s: tuple[float, float]
    min_altitude_m: float
    ground_m: float
    first_point_m: tuple[float, float, float]
    last_point_m: tuple[float, float, float]
    lowest_m: float
    ground_stops_s: tuple[tuple[float, float], ...] = ()

    @property
    def starts_airborne(self) -> bool:
        """Whether the plan's take-off is empty (the consumer must take off to it)."""
        return self.takeoff_s[1] <= self.takeoff_s[0]

    @property
    def ends_airborne(self) -> bool:
        """Whether the plan's landing is empty (the consumer must land from it)."""
        return self.landing_s[1] <= self.landing_s[0]

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: ``trajectory.json``'s and ``summary.json``'s ``phases``."""
        return {
            "takeoff_s": list(self.takeoff_s),
            "mission_s": list(self.mission_s),
            "landing_s": list(self.landing_s),
            "min_altitude_m": self.min_altitude_m,
            "ground_m": self.ground_m,
            "first_point_m": list(self.first_point_m),
            "last_point_m": list(self.last_point_m),
            "lowest_m": self.lowest_m,
            "ground_stops_s": [list(s) for s in self.ground_stops_s],
        }

    @classmethod
    def from_dict(cls, data: object) -> FlightPhases:
        """The record :meth:`as_dict` wrote; :class:`InputError` naming a bad field."""
        if not isinstance(data, dict):
            raise InputError(f"phases: got {type(data).__name__}, expected an object")
        try:
            return cls(
                _pair(data["takeoff_s"]),
                _pair(data["mission_s"]),
                _pair(data["landing_s"]),
                float(data["min_altitude_m"]),
                float(data["ground_m"]),
                _point(data["first_point_m"]),
                _point(data["last_point_m"]),
                float(data["lowest_m"]),
                tuple(_pair(s) for s in data.get("ground_stops_s", [])),
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(
                f"phases: got {sorted(data)} ({exc}), expected takeoff_s, mission_s, "
                "landing_s, min_altitude_m, ground_m, first_point_m, last_point_m, lowest_m"
            ) from None


def _pair(value: Any) -> tuple[float, float]:
    a, b = value
    return float(a), float(b)


def _point(value: Any) -> tuple[float, float, float]:
    x, y, z = value
    return float(x), float(y), float(z)


def check_min_altitude(name: str, value: float) -> float:
    """A minimum altitude (the argument ``name``), m: from 0 to :data:`MAX_MIN_ALTITUDE_M`."""
    value = as_float(name, value)
    if not 0.0 <= value <= MAX_MIN_ALTITUDE_M:
        raise InputError(
            f"{name}: got {value:g} m, expected 0 to {MAX_MIN_ALTITUDE_M:g} m above the ground"
        )
    return value


def check_altitude(name: str, value: float, min_altitude_m: float) -> float:
    """The altitude a 2-D plan is flown at (the argument ``name``), m: from the minimum
    altitude to :data:`MAX_ALTITUDE_M`."""
    value = as_float(name, value)
    if not min_altitude_m <= value <= MAX_ALTITUDE_M:
        raise InputError(
            f"{name}: got {value:g} m, expected {min_altitude_m:g} (the minimum altitude) to "
            f"{MAX_ALTITUDE_M:g} m"
        )
    return value


def rest_times(traj: Trajectory) -> FloatArray:
    """Where ``traj`` is at rest (speed and acceleration within :data:`REST_TOLERANCE`), s.

    Candidates are its ends, its breakpoints (where rest-to-rest pieces meet) and every local
    minimum of the speed between dense samples, refined (a waypoint a fit stops at lies
    between knots).
    """
    t = dense_times(np.asarray(traj.breakpoints, dtype=float))
    speed = np.linalg.norm(traj.evaluate(t, 1), axis=1)
    dips = np.flatnonzero((speed[1:-1] <= speed[:-2]) & (speed[1:-1] <= speed[2:])) + 1
    still = t[speed <= REST_TOLERANCE]  # at rest already (a hold): no need to refine
    dips = dips[(speed[dips] > REST_TOLERANCE) & (speed[dips] <= SLOW_MPS)]
    refined = [_slowest(traj, float(t[i - 1]), float(t[i + 1])) for i in dips]
    candidates = np.unique(
        np.concatenate([[0.0, traj.duration], np.asarray(traj.breakpoints, float), still, refined])
    )
    candidates = candidates[(candidates >= 0.0) & (candidates <= traj.duration)]
    v = np.linalg.norm(traj.evaluate(candidates, 1), axis=1)
    a = np.linalg.norm(traj.evaluate(candidates, 2), axis=1)
    return np.asarray(candidates[(v <= REST_TOLERANCE) & (a <= REST_TOLERANCE)])


def _slowest(traj: Trajectory, lo: float, hi: float) -> float:
    """The time of the least speed in ``[lo, hi]`` (bounded scalar minimisation), s."""
    from scipy.optimize import minimize_scalar

    def speed2(t: float) -> float:
        return float(np.sum(traj.evaluate(np.array([t]), 1) ** 2))

    result = minimize_scalar(speed2, bounds=(lo, hi), method="bounded", options={"xatol": 1e-10})
    return float(result.x)


def flight_phases(
    traj: Trajectory, min_altitude_m: float = MIN_ALTITUDE_M, ground_m: float = 0.0
) -> FlightPhases:
    """The phases of ``traj`` (module docstring).

    Parameters
    ----------
    traj
        A 3-D plan, z up, m, s.
    min_altitude_m
        Lowest altitude of the mission above the ground, m (:func:`check_min_altitude`).
    ground_m
        The ground's z, m.

    Raises
    ------
    InputError
        A bad ``min_altitude_m`` or a plan that is not 3-D.
    InfeasibleError
        A plan that never rests at or above the minimum altitude, or whose mission goes
        below it other than on a ground stop.
    """
    min_altitude_m = check_min_altitude("min_altitude_m", min_altitude_m)
    if traj.dim != 3:
        raise InputError(f"traj: got {traj.dim} axes, expected 3 (x, y, z up)")
    floor = ground_m + min_altitude_m - ALTITUDE_TOLERANCE_M
    rests = rest_times(traj)
    z_rest = traj.evaluate(rests)[:, 2] if rests.size else np.zeros(0)
    airborne = rests[z_rest >= floor]
    if airborne.size == 0:
        t = dense_times(np.asarray(traj.breakpoints, float))
        top = float(traj.evaluate(t)[:, 2].max()) - ground_m
        raise InfeasibleError(
            f"min_altitude_m: got a plan that never rests at or above {min_altitude_m:g} m "
            f"above the ground (it reaches {top:.3f} m), expected a mission that starts and "
            "ends at rest in the air: plan it higher or lower the minimum altitude",
            ("altitude",),
        )
    start, end = float(airborne[0]), float(airborne[-1])
    stops, lowest = _ground_stops(traj, (start, end), floor, rests, airborne, ground_m=ground_m)
    first, last = (tuple(float(v) for v in traj.evaluate(np.array([x]))[0]) for x in (start, end))
    return FlightPhases(
        (0.0, start),
        (start, end),
        (end, traj.duration),
        min_altitude_m,
        ground_m,
        (first[0], first[1], first[2]),
        (last[0], last[1], last[2]),
        lowest,
        stops,
    )


def _ground_stops(
    traj: Trajectory,
    mission: tuple[float, float],
    floor: float,
    rests: FloatArray,
    airborne: FloatArray,
    *,
    ground_m: float,
) -> tuple[tuple[tuple[float, float], ...], float]:
    """The mission's landings and its lowest altitude elsewhere; refuses any other dip."""
    start, end = mission
    if end <= start:
        return (), float(traj.evaluate(np.array([start]))[0, 2]) - ground_m
    t = dense_times(np.asarray(traj.breakpoints, float))
    t = np.unique(np.concatenate([t[(t >= start) & (t <= end)], [start, end]]))
    z = traj.evaluate(t)[:, 2]
    low = z < floor
    stops: list[tuple[float, float]] = []
    ok = np.ones(t.size, dtype=bool)
    for k in np.flatnonzero(low):
        before = airborne[airborne <= t[k]]
        after = airborne[airborne >= t[k]]
        a, b = float(before[-1]), float(after[0])
        landed = rests[(rests > a) & (rests < b)]
        if landed.size == 0:  # it dips below the floor in flight
            ok[k] = False
            continue
        if not stops or stops[-1] != (a, b):
            stops.append((a, b))
    if not ok.all():
        worst = int(np.flatnonzero(~ok)[np.argmin(z[~ok])])
        raise InfeasibleError(
            f"min_altitude_m: got a plan that flies at {z[worst] - ground_m:.3f} m above the "
            f"ground at t = {t[worst]:.2f} s, in its mission ({start:.2f} to {end:.2f} s), "
            f"expected at least {floor - ground_m + ALTITUDE_TOLERANCE_M:g} m: plan it higher "
            "or lower the minimum altitude",
            ("altitude",),
        )
    in_stop = np.zeros(t.size, dtype=bool)
    for a, b in stops:
        in_stop |= (t > a) & (t < b)
    lowest = float(z[~in_stop].min()) - ground_m if (~in_stop).any() else float(z.min())
    return tuple(stops), lowest


def leg_limits(limits: Sequence[DerivativeLimit]) -> tuple[float, float, float]:
    """Speed, acceleration and jerk a straight take-off or landing leg keeps, SI units.

    The smallest bound each order's limits state in any direction
    (:func:`~skyquill.limits.limit_bounds`), :data:`DEFAULT_LEG_LIMITS` for one they leave
    out.
    """
    bounds = limit_bounds(limits)
    v, a, j = (bounds.get(n, DEFAULT_LEG_LIMITS[n]) for n in (1, 2, 3))
    return v, a, j


def vertical_leg(
    start: FloatArray, end_z: float, limits: Sequence[DerivativeLimit]
) -> PiecewisePolynomial:
    """The time-optimal straight vertical move from ``start`` (3,) to height ``end_z``, rest
    to rest, within ``limits`` (:func:`leg_limits`), as cubic pieces (Ruckig)."""
    from skyquill.optimize.legs import LegLimits, leg_pieces

    v, a, j = leg_limits(limits)
    target = np.array([start[0], start[1], end_z], dtype=float)
    durations, coeffs = leg_pieces(np.asarray(start, dtype=float), target, LegLimits(v, a, j))
    return PiecewisePolynomial(np.concatenate([[0.0], np.cumsum(durations)]), coeffs)


def grounded(
    traj: Trajectory, phases: FlightPhases, limits: Sequence[DerivativeLimit]
) -> tuple[Trajectory, float]:
    """``traj`` starting and ending on the ground: a climb from the ground below its first
    point if it starts in the air, a descent after its last if it ends in the air.

    Returns the trajectory and how much later the plan's clock starts in it (the climb), s.
    Legs are straight, vertical and time-optimal within ``limits`` (:func:`vertical_leg`).
    """
    pieces: list[Trajectory] = []
    shift = 0.0
    first = np.array(phases.first_point_m)
    last = np.array(phases.last_point_m)
    if phases.starts_airborne and first[2] > phases.ground_m:
        climb = vertical_leg(np.array([first[0], first[1], phases.ground_m]), first[2], limits)
        pieces.append(climb)
        shift = climb.duration
    pieces.append(traj)
    if phases.ends_airborne and last[2] > phases.ground_m:
        pieces.append(vertical_leg(last, phases.ground_m, limits))
    if len(pieces) == 1:
        return traj, 0.0
    return RestToRestSequence(tuple(pieces)), shift
