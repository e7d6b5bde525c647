"""How the drones get from where they are to a set of places: straight, or through a curtain.

Straight means one transition (:func:`skyquill.show.transition.plan_transition`:
assigned, in waves or depth layers, proven apart). Between a formation on a
vertical plane and the air above the pads, straight moves converge and may
need many waves, or none may keep the drones apart; then the drones can go
through a *curtain*: a vertical grid on the formation's plane above the pads'
columns, spaced at least ``sqrt(2)`` times the safety distance. On one plane
any formation reaches any other (delays or depth layers: its drones are the
safety distance apart in x and z, so stepping out along y keeps them apart),
and a grid at that spacing reaches an air grid as far apart in one wave
(CAPT). :func:`route_to` flies the shorter of the routes that can be kept apart.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import InfeasibleError, InputError
from skyquill.optimize.legs import LegLimits
from skyquill.show.formation import grid_formation
from skyquill.show.script import ShowScript
from skyquill.show.transition import Transition, assign, plan_transition
from skyquill.validation import FloatArray

#: Spread of y within which points count as one vertical plane, m.
PLANE_TOLERANCE_M = 1e-6

IntArray = NDArray[np.intp]


@dataclass(frozen=True)
class Route:
    """Transitions flown one after another to a set of places.

    Attributes
    ----------
    legs
        One transition, or two through the curtain.
    chosen
        Each drone's place: an index into the targets (N,).
    """

    legs: tuple[Transition, ...]
    chosen: IntArray

    @property
    def via_curtain(self) -> bool:
        """Whether the drones went through the curtain."""
        return len(self.legs) > 1

    @property
    def duration(self) -> float:
        """Length of the route, s."""
        return sum(t.duration for t in self.legs)


def leg_limits(script: ShowScript) -> LegLimits:
    """The moves' limits: the show's speed, acceleration and jerk norms."""
    lim = script.limits
    if lim.vmax is None or lim.amax is None or lim.jmax is None:
        raise InputError("[limits]: got a missing limit, expected vmax, amax and jmax")
    return LegLimits(lim.vmax, lim.amax, lim.jmax)


def plan_moves(starts: FloatArray, goals: FloatArray, script: ShowScript) -> Transition:
    """:func:`~skyquill.show.transition.plan_transition` with the show's limits and distance."""
    names = [f"drone {i}" for i in range(len(goals))]
    return plan_transition(starts, goals, leg_limits(script), script.safety_m, names)


def route_to(start: FloatArray, targets: FloatArray, script: ShowScript) -> Route:
    """From ``start`` (N, 3) to ``targets`` (N, 3), each drone to the place assigned to it.

    Raises
    ------
    InfeasibleError
        Neither straight nor through the curtain (when either set lies on one
        vertical plane) can be kept apart: the straight transition's error.
    """
    routes: list[Route] = []
    error: InfeasibleError | None = None
    try:
        chosen = assign(start, targets)
        routes.append(Route((plan_moves(start, targets[chosen], script),), chosen))
    except InfeasibleError as exc:
        error = exc
    plane = plane_y(start)
    plane = plane_y(targets) if plane is None else plane
    if plane is not None:
        bottom = float(min(start[:, 2].min(), targets[:, 2].min()))
        stage = curtain(script, plane, bottom)
        try:
            staged = stage[assign(start, stage)]
            first = plan_moves(start, staged, script)
            chosen = assign(staged, targets)
            routes.append(Route((first, plan_moves(staged, targets[chosen], script)), chosen))
        except InfeasibleError:
            pass  # the straight route's error (or success) stands
    if not routes:
        assert error is not None
        raise error
    return min(routes, key=lambda r: r.duration)


def plane_y(points: FloatArray) -> float | None:
    """The y of the vertical plane facing -y that holds ``points``, if one does."""
    return float(points[0, 1]) if np.ptp(points[:, 1]) <= PLANE_TOLERANCE_M else None


def curtain(script: ShowScript, plane: float, bottom_m: float) -> FloatArray:
    """A vertical grid on ``y = plane`` above the pads' columns, from ``bottom_m`` up, (N, 3)."""
    spacing = max(script.home_spacing_m, math.sqrt(2.0) * script.safety_m)
    origin = np.array([script.home_origin[0], plane, bottom_m])
    columns = math.ceil(math.sqrt(script.drones))  # as many as the pads have (home_grid)
    return grid_formation(
        script.drones,
        origin=origin,
        columns=columns,
        spacing_m=spacing,
        safety_m=script.safety_m,
    ).points
