"""One studio plan, start to finish: request -> missions -> simulated flights -> files.

This is the work a job does off the event loop. The show is planned (and
flown) by :func:`skyquill.calligraphy.show.plan_show`, the planner of
``skyquill write``; what is the studio's own is around it: the request turned
into strokes, the drones planned one after the other in the job's process
(``workers=1``: the job's time limit kills that one process, and progress is
reported between drones), the JSON view of the result, and the exports
generated in a temporary directory and kept in memory, keyed by the job, never
at a path that came from a request.
"""

from __future__ import annotations

import contextlib
import io
import itertools
import json
import logging
import math
import tempfile
import zipfile
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.ink import flight_ink
from skyquill.calligraphy.mission import Mission, WritingOptions
from skyquill.calligraphy.show import Show, plan_show
from skyquill.errors import InfeasibleError, InputError, SolverError
from skyquill.export import EXPORTERS, ExportOptions
from skyquill.io.plan_dir import write_plan
from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.limits import VehicleLimits
from skyquill.strokes import Strokes
from skyquill.studio.models import DownloadFile, DronePlan, LimitReport, Limits, PlanRequest
from skyquill.studio.models import PlanResult as PlanResultModel
from skyquill.validation import FloatArray

if TYPE_CHECKING:
    from skyquill.sim import Flight

#: Smallest distance between two drones at any time, m (``skyquill write``'s default).
SEPARATION_M = 1.0
#: Rate of the setpoint CSVs, Hz (``skyquill write``'s default).
CSV_RATE_HZ = 100.0
#: The registry's formats the studio offers for download (besides the setpoints): the
#: name of each format's download.
STUDIO_FORMATS = {"crazyswarm": "crazyswarm", "skyc": "show"}
#: Content types of the downloads, by suffix.
CONTENT_TYPES = {".csv": "text/csv", ".skyc": "application/zip", ".json": "application/json"}
#: Rate of the curves sent to the page, Hz, and the most samples per drone.
VIEW_RATE_HZ = 50.0
MAX_VIEW_SAMPLES = 3_000
#: Most points of one simulated ink polyline sent to the page.
MAX_INK_POINTS = 600
#: Decimals of the numbers sent to the page (0.1 mm, 0.1 ms: far below what is drawn).
DECIMALS = 4

#: ``progress(fraction, stage)``; it may raise to stop the plan (time limit).
Progress = Callable[[float, str], None]

#: Share of the progress bar for planning one drone against flying it: the solves
#: (stretches, re-segmentation) take about three times the closed-loop flight.
PLAN_WEIGHT, FLY_WEIGHT = 3.0, 1.0
#: The bar's span for :func:`plan_show` (the rest: reading the input, writing files).
SHOW_START, SHOW_END = 0.05, 0.9
#: Each solve of a drone's route (the planning logs one per timing tried or re-segmentation)
#: moves the bar this fraction of the way to the end of the drone's share: how many
#: solves a drone takes is not known in advance, so the bar slows, never stops or jumps back.
SOLVE_STEP = 0.35


@dataclass(frozen=True)
class StudioFile:
    """A generated download, in memory."""

    name: str
    data: bytes
    media_type: str
    description: str


@dataclass(frozen=True)
class PlanOutput:
    """A finished plan: what the page shows, and the files it offers."""

    result: PlanResultModel
    files: dict[str, StudioFile]


def parts_of(request: PlanRequest) -> list[Strokes]:
    """What each drone writes: the drawing or the text, shared out in consecutive parts."""
    from skyquill.strokes import typed_parts

    if request.text is not None:
        return typed_parts(request.text, request.drones)  # one scale across drones
    assert request.strokes is not None  # the model guarantees exactly one input
    drawing = Strokes(
        paths=tuple(np.asarray(s, dtype=float) for s in request.strokes),
        times=None if request.t is None else tuple(np.asarray(t, float) for t in request.t),
        source="studio drawing",
    )
    return split_strokes(drawing, request.drones)


def split_strokes(drawing: Strokes, parts: int) -> list[Strokes]:
    """``drawing`` in ``parts`` consecutive groups of whole strokes (one per drone)."""
    n = drawing.n_strokes
    if n < parts:
        raise InputError(
            f"drones: got {parts} drones for {n} stroke(s), expected at most one drone per stroke"
        )
    bounds = np.linspace(0, n, parts + 1).round().astype(int)
    out = []
    for a, b in itertools.pairwise(bounds):
        times = None if drawing.times is None else drawing.times[a:b]
        out.append(Strokes(paths=drawing.paths[a:b], times=times, source=drawing.source))
    return out


def run_plan(
    request: PlanRequest, *, progress: Progress, file_url: Callable[[str], str], plan_id: str
) -> PlanOutput:
    """Plan, fly and export what ``request`` asks; report progress between the stages.

    Parameters
    ----------
    request
        The validated request.
    progress
        Called with the fraction done (0 to 1) and a stage name; may raise to stop.
    file_url
        The URL at which the page will find a generated file, from its name.
    plan_id
        The plan's identifier: in every file's name and in ``summary.json``.

    Raises
    ------
    InputError, InfeasibleError
        The request cannot be planned (the message is for the person).
    """
    progress(0.02, "reading the input")
    parts = parts_of(request)
    options = WritingOptions(
        size_m=request.size_m, limits=VehicleLimits(request.vmax, request.amax, request.jmax)
    )
    show = _plan_show(parts, options, request, progress)
    first_board = show.missions[0].board
    flights = show.flights or (None,) * len(parts)
    drones = [
        _drone_plan(mission, part, first_board, flight)
        for mission, part, flight in zip(show.missions, parts, flights, strict=True)
    ]
    flown = [_flight_record(d, request) for d in drones if d.flight]
    record = {"plan_id": plan_id, "request": request_record(request), "simulated_flight": flown}
    files, notes = _exports(show.missions, record, progress)
    named = {f"skyquill-{plan_id}-{kind}": (kind, f) for kind, f in files.items()}
    result = PlanResultModel(
        plan_id=plan_id,
        source="text" if request.text is not None else "strokes",
        board=request.board,
        size_m=request.size_m,
        limits=Limits(vmax=request.vmax, amax=request.amax, jmax=request.jmax),
        duration_s=max(m.trajectory.duration for m in show.missions),
        planning_time_s=sum(m.planning_time_s for m in show.missions),
        min_separation_m=show.min_separation_m if len(show.missions) > 1 else None,
        drones=drones,
        files=[
            DownloadFile(
                name=name,
                kind=kind,
                url=file_url(name),
                description=f.description,
                size_bytes=len(f.data),
            )
            for name, (kind, f) in named.items()
        ],
        notes=notes,
    )
    return PlanOutput(result, {name: f for name, (_, f) in named.items()})


def request_record(request: PlanRequest) -> dict[str, Any]:
    """What was asked, for ``summary.json``: the input's size, the board, the limits, options."""
    record: dict[str, Any] = request.model_dump(exclude={"strokes", "t", "text"})
    if request.text is not None:
        record["text"] = request.text
    else:
        assert request.strokes is not None
        record["strokes"] = len(request.strokes)
        record["points"] = sum(len(s) for s in request.strokes)
        record["timestamps"] = request.t is not None
    return record


def _flight_record(drone: DronePlan, request: PlanRequest) -> dict[str, Any]:
    """One drone's simulated flight as ``summary.json`` records it (SI units)."""
    excess = max((c.relative_excess for c in drone.checks), default=0.0)
    return {
        "duration_s": drone.duration_s,
        "path_rmse_m": drone.flight_rmse_m,
        "ink_max_deviation_m": drone.ink_max_deviation_m,
        "ink_iou": drone.ink_iou,
        "ink_width_m": drone.ink_width_m,
        "limit_excess": excess,
    }


def _plan_show(
    parts: list[Strokes], options: WritingOptions, request: PlanRequest, progress: Progress
) -> Show:
    """:func:`plan_show` in this process, its steps mapped to 5 % .. 90 % of the job.

    A drone's planning weighs :data:`PLAN_WEIGHT`, its flight :data:`FLY_WEIGHT`;
    the stage named is the one that starts (what the person waits for).
    """
    planned, n, solves = 0, len(parts), 0
    whole = PLAN_WEIGHT * n + (FLY_WEIGHT * n if request.fly else 0.0)

    def at(weight: float) -> float:
        return SHOW_START + (SHOW_END - SHOW_START) * weight / whole

    def report(done: int, total: int, stage: str) -> None:
        nonlocal planned, solves
        planned, solves = min(done, n), 0
        flown = max(0, done - n)
        progress(at(PLAN_WEIGHT * planned + FLY_WEIGHT * flown), _next_stage(done, n))

    def solving(step: str) -> None:
        nonlocal solves
        solves += 1
        share = PLAN_WEIGHT * (1.0 - (1.0 - SOLVE_STEP) ** solves)
        progress(at(PLAN_WEIGHT * planned + share), f"drone {planned + 1} of {n}: {step}")

    try:
        with _solves_reported(solving):
            return plan_show(
                parts,
                options,
                SEPARATION_M,
                workers=1,
                board_kind=request.board,
                fly=request.fly,
                progress=report,
            )
    except SolverError as exc:
        # Seen with tiny jerk limits: the QP backends hit their iteration limit
        # instead of proving infeasibility. To the person it is the same answer.
        # Drones are planned in order (workers=1): the one that failed is the next.
        raise InfeasibleError(
            f"limits: could not plan drone {planned + 1}'s flight within speed "
            f"{request.vmax:g} m/s, acceleration {request.amax:g} m/s^2 and jerk "
            f"{request.jmax:g} m/s^3 ({exc}); expected looser limits or a smaller drawing"
        ) from exc


class _SolveHandler(logging.Handler):
    """Passes each of the planning's per-solve DEBUG records to a callback, as its message."""

    def __init__(self, callback: Callable[[str], None]) -> None:
        super().__init__(logging.DEBUG)
        self.callback = callback

    def emit(self, record: logging.LogRecord) -> None:
        """Report the solve (a progress callback that raises stops the plan)."""
        # Not caught here (nor by logging): a callback that raises stops the plan.
        self.callback(record.getMessage())


@contextlib.contextmanager
def _solves_reported(callback: Callable[[str], None]) -> Iterator[None]:
    """While inside, each solve of a route (its stretches, its re-segmentation) calls ``callback``.

    The plan runs in the job's own process (one plan per process), so turning the
    mission logger's DEBUG records on there touches nothing else.
    """
    from skyquill.calligraphy import mission

    handler = _SolveHandler(callback)
    level = mission.logger.level
    mission.logger.addHandler(handler)
    mission.logger.setLevel(logging.DEBUG)
    try:
        yield
    finally:
        mission.logger.removeHandler(handler)
        mission.logger.setLevel(level)


def _next_stage(done: int, n: int) -> str:
    """What :func:`plan_show` does after ``done`` of its steps, for a person."""
    if done < n:
        return f"planning drone {done + 1} of {n} (solving the spline: the longest step)"
    if done < 2 * n:
        return f"flying drone {done - n + 1} of {n} in simulation"
    return "collecting the results"


def _round(a: FloatArray) -> Any:
    """``a`` as nested lists of floats rounded to :data:`DECIMALS` (smaller JSON)."""
    return np.round(np.asarray(a, dtype=float), DECIMALS).tolist()


def _view_times(duration: float) -> FloatArray:
    n = min(MAX_VIEW_SAMPLES, math.ceil(duration * VIEW_RATE_HZ) + 1)
    return np.linspace(0.0, duration, max(n, 2))


def _drone_plan(
    mission: Mission, part: Strokes, first_board: Board, flight: Flight | None
) -> DronePlan:
    """One drone's curves for the page, in its board's coordinates (and its flight's)."""
    traj, board = mission.trajectory, mission.board
    t = _view_times(traj.duration)
    v, a, j = (np.abs(traj.evaluate(t, n)).max(axis=1) for n in (1, 2, 3))
    lo, hi = part.bounds()
    check = mission.verification
    fields: dict[str, Any] = {
        "board_u0": float(board.origin[0] - first_board.origin[0]),
        "source_lo": (float(lo[0]), float(lo[1])),
        "source_scale": mission.options.size_m / float(np.max(hi - lo)),
        "input": [_round(board.to_board(s)[:, :2]) for s in mission.strokes_world],
        "t": _round(t),
        "path": _round(board.to_board(mission.tip(t))),
        "pen": mission.pen(t).astype(int).tolist(),
        "speed": _round(v),
        "acc": _round(a),
        "jerk": _round(j),
        "flight": [],
        "ink": [],
        "duration_s": traj.duration,
        "planning_time_s": mission.planning_time_s,
        "deviation_max_m": mission.deviation.max_m,
        "ink_width_m": mission.options.brush.stroke_width_m,
        "checks": [LimitReport.model_validate(c) for c in check.limits_report()],
    }
    if flight is not None:
        fields |= _flight_fields(mission, flight, t)
    return DronePlan.model_validate(fields)


def _flight_fields(mission: Mission, flight: Flight, t: FloatArray) -> dict[str, Any]:
    """The closed-loop flight (RPT) of the vehicle trajectory, as :class:`DronePlan` fields."""
    board = mission.board
    # The tip hangs the brush length below the vehicle (its swing with tilt is not drawn).
    tip = np.column_stack([np.interp(t, flight.t, flight.p[:, k]) for k in range(3)])
    tip = tip - mission.brush_offset
    ink = [s for s in flight.ink if len(s) >= 2]
    fidelity = flight_ink(flight, mission)
    numbers = {} if fidelity is None else fidelity.as_dict()
    return {
        "flight": _round(board.to_board(tip)),
        "ink": [_round(board.to_board(_decimate(s))[:, :2]) for s in ink],
        "flight_rmse_m": flight.rmse_m,
        "ink_max_deviation_m": numbers.get("max_deviation_m"),
        "ink_iou": numbers.get("iou"),
    }


def _decimate(points: FloatArray) -> FloatArray:
    """At most :data:`MAX_INK_POINTS` of ``points``, the last one kept."""
    step = max(1, math.ceil(len(points) / MAX_INK_POINTS))
    return np.vstack([points[::step], points[-1:]])


def _exports(
    missions: Sequence[Mission], record: dict[str, Any], progress: Progress
) -> tuple[dict[str, StudioFile], list[str]]:
    """The plan's setpoint CSV(s) and summary, and the studio's formats from the registry.

    Everything is written through the same writer and exporters as the command
    line (a plan directory in a temporary folder, then
    :data:`~skyquill.export.EXPORTERS`), kept in memory, and checked as written.
    ``record`` (the plan id, the request, the simulated flights) heads ``summary.json``.
    Files are keyed by their kind (``setpoints.csv``).
    """
    planned = [
        (
            f"drone_{i}",
            PlannedTrajectory(m.vehicle_trajectory(), tuple(m.pen_windows), m.limits),
        )
        for i, m in enumerate(missions, start=1)
    ]
    steps = 1 + len(STUDIO_FORMATS)
    with tempfile.TemporaryDirectory(prefix="skyquill-studio-") as tmp:
        out = Path(tmp)
        progress(SHOW_END, f"writing the setpoints (file 1 of {steps})")
        summary = write_plan(
            out / "plan",
            [p for _, p in planned],
            rate=CSV_RATE_HZ,
            guaranteed=True,
            summary=record | {"drones": [m.summary() for m in missions]},
        )
        setpoints = [
            (f"setpoints_{i}.csv", (out / "plan" / d["csv"]).read_bytes())
            for i, d in enumerate(summary["plan"]["drones"], start=1)
        ]
        files = [
            _bundle(
                setpoints,
                "setpoints",
                f"setpoints at {CSV_RATE_HZ:g} Hz: t, x, y, z, velocity, acceleration, jerk, "
                "yaw, pen (SI, z up)",
            )
        ]
        notes = []
        for k, (name, stem) in enumerate(STUDIO_FORMATS.items(), start=2):
            progress(SHOW_END + 0.09 * (k - 1) / steps, f"writing the {stem} (file {k} of {steps})")
            exporter = EXPORTERS[name]
            try:
                report = exporter(
                    planned, out / f"{name}{exporter.suffix}", ExportOptions(CSV_RATE_HZ)
                )
            except InputError as exc:
                # A plan the format cannot hold (a Crazyswarm export of a plan that does not
                # fit the Crazyflie's uploads) is a missing download, not a failed plan.
                notes.append(f"{stem}: download unavailable: {exc}")
                continue
            notes.append(report.message.replace(str(out) + "/", ""))
            parts = [(f.name, f.read_bytes()) for f in report.files]
            files.append(_bundle(parts, stem, exporter.help))
        data = json.dumps(summary, indent=2, allow_nan=False).encode()
    files.append(
        StudioFile("summary.json", data, "application/json", "what was planned and checked")
    )
    return {f.name: f for f in files}, notes


def _bundle(parts: Sequence[tuple[str, bytes]], stem: str, description: str) -> StudioFile:
    """One file as ``<stem><suffix>``, or several in ``<stem>.zip``."""
    if len(parts) == 1:
        name, data = parts[0]
        suffix = Path(name).suffix
        kind = {".csv": "text/csv", ".skyc": "application/zip"}.get(
            suffix, "application/octet-stream"
        )
        return StudioFile(f"{stem}{suffix}", data, kind, description)
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for name, data in parts:
            archive.writestr(name, data)
    note = " (one file per drone and upload, in a zip)"
    return StudioFile(f"{stem}.zip", buffer.getvalue(), "application/zip", description + note)
