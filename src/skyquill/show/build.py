"""A show script planned: every drone's flight on one clock, with its lights.

Scenes are flown one after another, all drones together: each scene starts
when the slowest drone has finished the one before. Between scenes that
place drones somewhere else, a transition (:mod:`skyquill.show.transition`),
or two through a curtain (:mod:`skyquill.show.route`), takes them there. Every drone's flight is one
:class:`~skyquill.trajectory.RestToRestSequence` (straight moves and holds as
cubic pieces, writing flights as splines), at rest where the pieces meet.

Lights: on while a drone holds a formation (the scene's colour), while it
writes (the pen windows of its writing flight), and in a ``hold`` that names a
colour; off otherwise. Each drone's ``pen_rgb`` holds one RGB per window of
``pen_windows_s`` (what the ``.skyc`` lights show).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment
from scipy.spatial.distance import cdist

from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.show.capt import CAPT_SPREAD
from skyquill.show.check import require_separation
from skyquill.show.formation import (
    Formation,
    circle_formation,
    grid_formation,
    home_grid,
    shape_formation,
)
from skyquill.show.layers import step_out
from skyquill.show.limits import check_inside
from skyquill.show.load import ShowDrone
from skyquill.show.moves import hold, staggered
from skyquill.show.route import Route, leg_limits, plan_moves, route_to
from skyquill.show.script import (
    RGB,
    FormationScene,
    Hold,
    Land,
    Scene,
    ShowScript,
    Takeoff,
    WriteScene,
)
from skyquill.show.transition import PLAN_MARGIN, Transition
from skyquill.show.writing import plan_writing_scene
from skyquill.trajectory import PiecewisePolynomial, Trajectory, concatenate
from skyquill.validation import FloatArray

#: Holds shorter than this are left out, s.
MIN_HOLD_S = 1e-9

IntArray = NDArray[np.intp]

#: ``progress(done, total, stage)`` after each scene (``done = 0`` before the first).
Progress = Callable[[int, int, str], None]


@dataclass(frozen=True)
class ShowPlan:
    """A planned show.

    Attributes
    ----------
    drones
        One per drone.
    homes
        The pads (N, 3), m: drone ``i`` takes off from ``homes[i]``.
    scenes
        ``{"type", "start_s", "end_s", ...}`` of every scene, in order.
    stage_times_s
        Planning time per kind of stage, s.
    min_separation_m
        Smallest guaranteed distance over the transitions and writing, m.
    """

    drones: tuple[PlannedTrajectory, ...]
    homes: FloatArray
    scenes: tuple[dict[str, Any], ...]
    stage_times_s: dict[str, float]
    min_separation_m: float

    @property
    def duration_s(self) -> float:
        """Length of the show, s."""
        return max(d.trajectory.duration for d in self.drones)


@dataclass
class _Drone:
    pieces: list[Trajectory] = field(default_factory=list)
    windows: list[tuple[float, float]] = field(default_factory=list)
    colors: list[RGB] = field(default_factory=list)


class _Timeline:
    """Every drone's pieces on the show clock, and where each one is now."""

    def __init__(self, positions: FloatArray) -> None:
        self.now = 0.0
        self.positions = positions.copy()
        self.drones = [_Drone() for _ in range(len(positions))]
        self.closest = math.inf

    def append(self, flights: list[Trajectory], duration: float) -> None:
        """One flight per drone, each padded with a hold to ``duration``."""
        for i, flight in enumerate(flights):
            self.drones[i].pieces.append(flight)
            end = flight.evaluate(np.array([flight.duration]))[0]
            if duration - flight.duration > MIN_HOLD_S:
                self.drones[i].pieces.append(_hold(end, duration - flight.duration))
            self.positions[i] = end
        self.now += duration

    def hold(self, duration: float, color: RGB | None) -> None:
        """Everyone holds ``duration`` s, lit in ``color`` if one is given."""
        if duration <= MIN_HOLD_S:
            return
        if color is not None:
            for i in range(len(self.drones)):
                self.light(i, self.now, self.now + duration, color)
        self.append([_hold(p, duration) for p in self.positions], duration)

    def light(self, i: int, start: float, end: float, color: RGB) -> None:
        """Drone ``i``'s light on in ``color`` from ``start`` to ``end`` (show clock, s)."""
        self.drones[i].windows.append((start, end))
        self.drones[i].colors.append(color)


def _hold(p: FloatArray, duration: float) -> PiecewisePolynomial:
    return PiecewisePolynomial(np.array([0.0, duration]), hold(p, duration)[1])


def build_show(
    script: ShowScript,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Progress | None = None,
) -> ShowPlan:
    """Plan every scene of ``script`` and compose each drone's flight.

    Parameters
    ----------
    script
        The show (:func:`skyquill.show.script.load_script`).
    workers, scheduler
        Where writing flights are planned (:func:`skyquill.calligraphy.show.plan_jobs`).
    progress
        Called after each scene.

    Raises
    ------
    InputError
        A formation that cannot hold the drones, more writers than drones.
    InfeasibleError
        A transition or a writing scene that cannot keep the drones apart,
        naming the pair and the time; a flight that cannot be planned.
    """
    homes = home_grid(
        script.drones,
        origin=script.home_origin,
        spacing_m=script.home_spacing_m,
        safety_m=script.safety_m,
    )
    _check_pads(homes, script)
    line = _Timeline(homes)
    times: dict[str, float] = {}
    records: list[dict[str, Any]] = []
    total = len(script.scenes)
    if progress is not None:
        progress(0, total, "planning the show")
    for k, scene in enumerate(script.scenes):
        start, clock = line.now, time.perf_counter()
        where = _Where(workers, scheduler, _writing_progress(progress, k, total))
        kind, detail = _fly(scene, script, line, homes, where)
        times[kind] = times.get(kind, 0.0) + time.perf_counter() - clock
        records.append({"type": kind, "start_s": start, "end_s": line.now} | detail)
        if progress is not None:
            progress(k + 1, total, f"planned scene {k + 1} of {total} ({kind})")
    drones = tuple(_compose(d, script) for d in line.drones)
    return ShowPlan(drones, homes, tuple(records), times, line.closest)


@dataclass(frozen=True)
class _Where:
    """Where writing flights are planned, and whom to tell (:func:`plan_jobs`)."""

    workers: int | None
    scheduler: str | None
    progress: Progress | None


def _writing_progress(progress: Progress | None, scene: int, total: int) -> Progress | None:
    """Each writing flight planned, reported as part of scene ``scene``."""
    if progress is None:
        return None
    outer = progress

    def report(done: int, count: int, stage: str) -> None:
        outer(scene, total, f"scene {scene + 1} of {total} (write): {stage}")

    return report


def _fly(
    scene: Scene, script: ShowScript, line: _Timeline, homes: FloatArray, where: _Where
) -> tuple[str, dict[str, Any]]:
    if isinstance(scene, Takeoff):
        _climb(line, homes, _air(homes, scene.altitude_m, script), scene.stagger_s, script)
        return "takeoff", {"altitude_m": scene.altitude_m}
    if isinstance(scene, FormationScene):
        formation = make_formation(scene, script)
        route = _reform(line, formation.points, script)
        line.hold(scene.hold_s, scene.color)
        return "formation", {
            "shape": formation.name,
            "spacing_m": formation.spacing_m,
            "via_curtain": route.via_curtain,
            "transition": _described(route),
        }
    if isinstance(scene, WriteScene):
        return "write", _write(scene, script, line, where)
    if isinstance(scene, Hold):
        line.hold(scene.duration_s, scene.color)
        return "hold", {}
    assert isinstance(scene, Land)
    air = _air(homes, scene.altitude_m, script)
    route = _reform(line, air, script)
    pads = route.chosen
    _climb(line, air[pads], homes[pads], scene.stagger_s, script)
    return "land", {
        "altitude_m": scene.altitude_m,
        "via_curtain": route.via_curtain,
        "transition": _described(route),
    }


def make_formation(scene: FormationScene, script: ShowScript) -> Formation:
    """The points of a formation scene, one per drone."""
    from skyquill.strokes import load_svg, typed_strokes

    n, safety = script.drones, script.safety_m
    if scene.shape == "grid":
        # CAPT (transition module): sqrt(2) x the safety distance needs no delays.
        spacing = scene.spacing_m or math.sqrt(2.0) * safety
        return grid_formation(
            n, origin=scene.origin, columns=scene.columns, spacing_m=spacing, safety_m=safety
        )
    if scene.shape == "circle":
        return circle_formation(n, center=scene.origin, radius_m=scene.radius_m, spacing_m=safety)
    strokes = typed_strokes(scene.text, scene.font) if scene.shape == "text" else None
    if strokes is None:
        assert scene.svg is not None
        strokes = load_svg(scene.svg)
    spacing = scene.spacing_m or safety
    return shape_formation(strokes, n, origin=scene.origin, size_m=scene.size_m, spacing_m=spacing)


def _air(homes: FloatArray, altitude_m: float, script: ShowScript) -> FloatArray:
    """Where the drones climb to above the pads (N, 3): ``altitude_m`` up, in layers if tight.

    Pads closer than ``sqrt(2)`` times the safety distance would need a step out of
    the air grid's plane before every transition (:mod:`skyquill.show.capt`); the
    climb takes every other drone a layer higher instead (:func:`~skyquill.show.layers.step_out`).
    """
    air = homes + np.array([0.0, 0.0, altitude_m])
    layers = step_out(air, CAPT_SPREAD * script.safety_m * (1.0 + PLAN_MARGIN))
    return air if layers is None else layers.points


def _climb(
    line: _Timeline, starts: FloatArray, goals: FloatArray, stagger_s: float, script: ShowScript
) -> None:
    """Vertical moves above the pads, one row of pads (along +x) after the other."""
    row = (goals[:, 1] - script.home_origin[1]) / script.home_spacing_m
    flights, duration = staggered(starts, goals, stagger_s * np.round(row), leg_limits(script))
    line.append(list(flights), duration)


def _reform(line: _Timeline, targets: FloatArray, script: ShowScript) -> Route:
    """Fly to ``targets`` (:func:`~skyquill.show.route.route_to`): the route flown."""
    route = route_to(line.positions, targets, script)
    for moves in route.legs:
        _append(line, moves)
    return route


def _described(route: Route) -> dict[str, Any]:
    """A transition for ``summary.json``: how, how long, and against its lower bound."""
    bound = route.lower_bound_s
    return {
        "route": route.how,
        "duration_s": route.duration,
        "lower_bound_s": bound,
        "over_lower_bound": route.duration / bound if bound > 0.0 else 1.0,
    }


def _append(line: _Timeline, moves: Transition) -> None:
    if moves.duration <= 0.0:
        return
    line.closest = min(line.closest, moves.closest_m)
    line.append([moves.trajectory(i) for i in range(len(moves.starts))], moves.duration)


def _transition(line: _Timeline, goals: FloatArray, script: ShowScript) -> None:
    _append(line, plan_moves(line.positions, goals, script))


def _write(scene: WriteScene, script: ShowScript, line: _Timeline, where: _Where) -> dict[str, Any]:
    writing = plan_writing_scene(
        scene, script, workers=where.workers, scheduler=where.scheduler, progress=where.progress
    )
    # The drones nearest the boards write (rectangular assignment); the others stay.
    who, board = linear_sum_assignment(cdist(line.positions, writing.starts, "sqeuclidean"))
    places = line.positions.copy()
    goals = line.positions.copy()
    goals[who] = writing.starts[board]
    _transition(line, goals, script)
    begin, duration = line.now, writing.duration_s
    flights: list[Trajectory] = [_hold(p, duration) for p in line.positions]
    for i, k in zip(who, board, strict=True):
        flights[i] = writing.flights[k]
        for a, b in writing.pen_windows[k]:
            line.light(int(i), begin + a, begin + b, scene.color)
    line.closest = min(line.closest, _prove(flights, script.safety_m))
    line.append(flights, duration)
    # Back to their places: the formation is whole again, and the next transition
    # starts from it (formations on one plane always transition: delays or layers).
    _transition(line, places, script)
    return {"text": scene.text, "writers": len(writing.flights), "duration_s": duration}


def _check_pads(homes: FloatArray, script: ShowScript) -> None:
    """Refuse, before planning, a geofence that leaves a take-off pad outside (bad input)."""
    if script.geofence is not None:
        labels = [f"the take-off pad of drone {i} at" for i in range(len(homes))]
        hint = " (move [show].home_origin or the fence)"
        check_inside(homes, labels, script.geofence, "[show].geofence", hint)


def _prove(flights: list[Trajectory], safety: float) -> float:
    """The guaranteed closest approach of ``flights`` (all from 0); refused below ``safety``."""
    drones = [ShowDrone(f, f"drone {i}") for i, f in enumerate(flights)]
    hint = " (move the boards away from the drones that hold)"
    return require_separation(drones, safety, "write", hint).lower_bound_m


def _compose(drone: _Drone, script: ShowScript) -> PlannedTrajectory:
    """One trajectory of the drone's pieces: runs of polynomials merged, splines kept."""
    runs: list[Trajectory] = []
    batch: list[PiecewisePolynomial] = []
    for piece in drone.pieces:
        if isinstance(piece, PiecewisePolynomial):
            batch.append(piece)
            continue
        if batch:
            runs.append(_merged(batch))
            batch = []
        runs.append(piece)
    if batch:
        runs.append(_merged(batch))
    return PlannedTrajectory(
        concatenate(runs),
        tuple(drone.windows),
        script.limits.derivative_limits(3),
        tuple(drone.colors),
    )


def _merged(pieces: list[PiecewisePolynomial]) -> PiecewisePolynomial:
    order = max(p.coeffs.shape[1] for p in pieces)
    coeffs = [np.pad(p.coeffs, ((0, 0), (0, order - p.coeffs.shape[1]), (0, 0))) for p in pieces]
    durations = np.concatenate([np.diff(p.breaks) for p in pieces])
    return PiecewisePolynomial(
        np.concatenate([[0.0], np.cumsum(durations)]), np.concatenate(coeffs)
    )
