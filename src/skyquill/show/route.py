"""How the drones get from where they are to a set of places: the fastest route proven apart.

The routes, each assigned and planned before any is proven:

* **straight**: the minimum-squared-distance assignment and one wave of
  synchronised straight moves (:func:`skyquill.show.capt.straight`), when no two
  paths come too close: as fast as the longest move;
* **layers**: out of a tight formation's plane into depth layers, across in one
  wave, back into the goals' plane (:func:`skyquill.show.capt.through_layers`): the
  longest move plus two steps of a few metres;
* **waves** (:func:`skyquill.show.transition.plan_transition`: delayed starts, or
  depth layers coloured by conflict) and the **curtain**: a vertical grid on the
  formation's plane above the pads' columns, spaced at least ``sqrt(2)`` times the
  safety distance (on one plane any formation reaches any other, and such a grid
  reaches an air grid as far apart in one wave). These take many waves at scale;
  they are planned for small shows (:data:`SMALL_SHOW` drones) or when neither route
  above exists (formations off any plane).

:func:`route_to` proves the fastest (:func:`skyquill.show.transition.prove`) and
flies it; one the proof refuses gives way to the next.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import InfeasibleError, InputError
from skyquill.optimize.legs import LegLimits
from skyquill.show.capt import lower_bound_s, matchings, straight, straight_to, through_layers
from skyquill.show.formation import grid_formation
from skyquill.show.script import ShowScript
from skyquill.show.transition import Transition, assign, plan_transition, prove
from skyquill.validation import FloatArray

#: Spread of y within which points count as one vertical plane, m.
PLANE_TOLERANCE_M = 1e-6
#: Shows of at most this many drones also try waves and the curtain (each is planned
#: and proven in well under a second there; at a thousand drones, many waves).
SMALL_SHOW = 100

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
    how
        ``"straight"``, ``"layers"``, ``"waves"`` or ``"curtain"``.
    lower_bound_s
        The shortest any transition to the targets can last (the bottleneck move at
        the limits, :func:`skyquill.show.capt.lower_bound_s`), s.
    """

    legs: tuple[Transition, ...]
    chosen: IntArray
    how: str = "straight"
    lower_bound_s: float = 0.0

    @property
    def via_curtain(self) -> bool:
        """Whether the drones went through the curtain."""
        return self.how == "curtain"

    @property
    def duration(self) -> float:
        """Length of the route, s."""
        return sum(t.duration for t in self.legs)


#: The moves are planned this fraction inside the limits: a time-optimal profile touches
#: them, and the scaled, composed polynomials then exceed them by a rounding error
#: (2 + 4.4e-16 m/s^2), which ``skyquill check`` at the script's exact limits refuses.
INSIDE = 1e-9


def leg_limits(script: ShowScript) -> LegLimits:
    """The moves' limits: the show's speed, acceleration and jerk norms (:data:`INSIDE` them)."""
    lim = script.limits
    if lim.vmax is None or lim.amax is None or lim.jmax is None:
        raise InputError("[limits]: got a missing limit, expected vmax, amax and jmax")
    inside = 1.0 - INSIDE
    return LegLimits(lim.vmax * inside, lim.amax * inside, lim.jmax * inside)


def plan_moves(starts: FloatArray, goals: FloatArray, script: ShowScript) -> Transition:
    """Each drone to its own goal: one wave if no paths come too close, else waves or layers.

    Proven apart (:func:`~skyquill.show.transition.plan_transition` for the waves).
    """
    names = [f"drone {i}" for i in range(len(goals))]
    limits, d = leg_limits(script), script.safety_m
    direct = straight(starts, goals, limits, d)
    if direct is not None:
        try:
            return prove(direct, d, names)
        except InfeasibleError:
            pass  # the waves below
    return plan_transition(starts, goals, limits, d, names)


#: A route planned but not yet proven: its duration and how to prove it.
_Option = tuple[float, Callable[[], Route]]


def route_to(start: FloatArray, targets: FloatArray, script: ShowScript) -> Route:
    """From ``start`` (N, 3) to ``targets`` (N, 3), each drone to the place assigned to it.

    Raises
    ------
    InfeasibleError
        No route can be kept apart: the error of the waves' straight transition.
    """
    limits, d = leg_limits(script), script.safety_m
    names = [f"drone {i}" for i in range(len(targets))]
    matching = matchings(start, targets)
    bound = lower_bound_s(matching.bottleneck_m, limits)
    options: list[_Option] = []
    direct = straight_to(start, targets, limits, d, matching)
    if direct is not None:
        route = Route((direct[0],), direct[1], "straight", bound)
        options.append((route.duration, _proving(route, d, names)))
    else:
        layered = through_layers(start, targets, limits, d)
        if layered is not None:
            route = Route((layered[0],), layered[1], "layers", bound)
            options.append((route.duration, _proving(route, d, names)))
    error: InfeasibleError | None = None
    if not options or len(start) <= SMALL_SHOW:
        try:
            proven = _waves_or_curtain(start, targets, script, bound)
            options.append((proven.duration, lambda: proven))
        except InfeasibleError as exc:
            error = exc
    for _, prove_it in sorted(options, key=lambda o: o[0]):
        try:
            return prove_it()
        except InfeasibleError as exc:
            error = error or exc
    assert error is not None
    raise error


def _proving(route: Route, d: float, names: list[str]) -> Callable[[], Route]:
    """A route's proof, to run if it is the fastest left."""

    def proven() -> Route:
        legs = tuple(prove(leg, d, names) for leg in route.legs)
        return Route(legs, route.chosen, route.how, route.lower_bound_s)

    return proven


def _waves_or_curtain(
    start: FloatArray, targets: FloatArray, script: ShowScript, bound: float
) -> Route:
    """The faster of straight moves in waves and the curtain (each proven), as before 1,000 drones.

    Raises
    ------
    InfeasibleError
        Neither can be kept apart: the straight transition's error.
    """
    routes: list[Route] = []
    error: InfeasibleError | None = None
    try:
        chosen = assign(start, targets)
        routes.append(Route((_legacy(start, targets[chosen], script),), chosen, "waves", bound))
    except InfeasibleError as exc:
        error = exc
    plane = plane_y(start)
    plane = plane_y(targets) if plane is None else plane
    if plane is not None:
        bottom = float(min(start[:, 2].min(), targets[:, 2].min()))
        stage = curtain(script, plane, bottom)
        try:
            staged = stage[assign(start, stage)]
            first = _legacy(start, staged, script)
            chosen = assign(staged, targets)
            second = _legacy(staged, targets[chosen], script)
            routes.append(Route((first, second), chosen, "curtain", bound))
        except InfeasibleError:
            pass  # the straight route's error (or success) stands
    if not routes:
        assert error is not None
        raise error
    return min(routes, key=lambda r: r.duration)


def _legacy(starts: FloatArray, goals: FloatArray, script: ShowScript) -> Transition:
    names = [f"drone {i}" for i in range(len(goals))]
    return plan_transition(starts, goals, leg_limits(script), script.safety_m, names)


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
