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
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.ink import flight_ink
from skyquill.calligraphy.mission import Mission, WritingOptions
from skyquill.calligraphy.show import Show, plan_show
from skyquill.errors import InfeasibleError, InputError, SolverError
from skyquill.export import EXPORTERS, ExportOptions, ExportReport
from skyquill.export.base import EXACT_TOLERANCE, ORDER_NAMES
from skyquill.io.plan_dir import write_plan
from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.limits import VehicleLimits
from skyquill.phases import flight_phases
from skyquill.strokes import Strokes
from skyquill.strokes.hanzi import bundled_hanzi, missing_hanzi
from skyquill.strokes.hershey import missing_glyphs
from skyquill.strokes.text import is_cjk
from skyquill.studio.messages import StudioInputError, too_many_drones, unwritable_text
from skyquill.studio.models import (
    Delivered,
    DownloadFile,
    DronePlan,
    LimitReport,
    Limits,
    PlanRequest,
    Target,
)
from skyquill.studio.models import PlanResult as PlanResultModel
from skyquill.targets import CRAZYFLIE
from skyquill.validation import FloatArray

if TYPE_CHECKING:
    from skyquill.sim import Flight

logger = logging.getLogger(__name__)

#: Smallest distance between two drones at any time, m (``skyquill write``'s default).
SEPARATION_M = 1.0
#: Rate of the setpoint CSVs, Hz (``skyquill write``'s default).
CSV_RATE_HZ = 100.0
#: The registry's formats the studio offers for download besides the setpoints and the
#: summary, per vehicle (the page's Vehicle choice): the name of each format's download.
STUDIO_FORMATS: dict[Target, dict[str, str]] = {
    "generic": {},
    "crazyflie": {"crazyswarm": "crazyswarm"},
    "skybrush": {"skyc": "show"},
}
#: What each download is, in the page's words.
DESCRIPTIONS = {
    "setpoints": "where the drone should be 100 times a second: position (m), velocity, "
    "acceleration, jerk, yaw and pen up or down, z up",
    "crazyswarm": "the Crazyflie's uploads as Crazyswarm2 / cflib polynomial files, and a "
    "Python script that flies them with cflib",
    "skyc": "the show for Skybrush Live and Studio, the light on while the pen is down",
    "summary": "what was asked, planned and checked, as JSON",
}
#: Who plays each download, for the notes under the downloads.
CONSUMERS = {"crazyswarm": "a Crazyflie plays it", "skyc": "Skybrush plays it"}
#: Content types of the downloads, by suffix.
CONTENT_TYPES = {".csv": "text/csv", ".skyc": "application/zip", ".json": "application/json"}
#: Rate of the curves sent to the page, Hz, and the most samples per drone.
VIEW_RATE_HZ = 50.0
MAX_VIEW_SAMPLES = 3_000
#: Most points of one simulated ink polyline sent to the page.
MAX_INK_POINTS = 600
#: How near the untilted tip passes an ink run's first point when it lays it, m (the
#: brush's swing is millimetres), and the steps after that approach searched for it.
INK_MATCH_M = 0.02
INK_MATCH_STEPS = 200
#: Decimals of the numbers sent to the page (0.1 mm, 0.1 ms: far below what is drawn).
DECIMALS = 4


class Progress(Protocol):
    """``progress(fraction, stage, known)``; it may raise to stop the plan (time limit).

    ``known`` is False while the stage's length cannot be known in advance (a
    drone's solves: how many a drawing needs shows only as they happen).
    """

    def __call__(self, fraction: float, stage: str, known: bool = True) -> None:
        """Report ``fraction`` (0 to 1) done, now in ``stage``."""


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
    """What each drone writes: the drawing or the text, shared out in consecutive parts.

    Raises
    ------
    StudioInputError
        Text the studio cannot write, or more drones than strokes, characters or words.
    """
    from skyquill.strokes import typed_parts

    if request.text is not None:
        check_text(request.text)
        chinese = is_cjk(request.text)
        units = len(
            [c for c in request.text if not c.isspace()] if chinese else request.text.split()
        )
        if units < request.drones:
            raise too_many_drones(request.drones, units, text=True)
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
        raise too_many_drones(parts, n, text=False)
    bounds = np.linspace(0, n, parts + 1).round().astype(int)
    out = []
    for a, b in itertools.pairwise(bounds):
        times = None if drawing.times is None else drawing.times[a:b]
        out.append(Strokes(paths=drawing.paths[a:b], times=times, source=drawing.source))
    return out


def check_text(text: str) -> None:
    """Refuse text with a character the studio cannot write, naming it (:class:`StudioInputError`).

    Chinese characters are written from the bundled hanzi medians, anything else
    with the Hershey font (:func:`~skyquill.strokes.typed_strokes`); mixed, the
    Latin characters are not in the hanzi set and are named.
    """
    if is_cjk(text):
        missing = missing_hanzi(text)
        if missing:
            raise unwritable_text(text, missing, chinese=True, bundled=len(bundled_hanzi()))
        return
    missing = missing_glyphs(text)
    if missing:
        raise unwritable_text(text, missing, chinese=False, bundled=0)


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
    options = writing_options(request)
    show = _plan_show(parts, options, request, progress)
    first_board = show.missions[0].board
    flights = show.flights or (None,) * len(parts)
    drones = [
        _drone_plan(mission, part, first_board, flight)
        for mission, part, flight in zip(show.missions, parts, flights, strict=True)
    ]
    flown = [_flight_record(d, request) for d in drones if d.flight]
    record = {"plan_id": plan_id, "request": request_record(request), "simulated_flight": flown}
    files, notes, delivered = _exports(
        show.missions, record, progress, STUDIO_FORMATS[request.target], request.min_altitude_m
    )
    named = {f"skyquill-{plan_id}-{kind}": (kind, f) for kind, f in files.items()}
    result = PlanResultModel(
        plan_id=plan_id,
        source="text" if request.text is not None else "strokes",
        board=request.board,
        target=request.target,
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
        delivered=delivered,
        notes=notes,
    )
    return PlanOutput(result, {name: f for name, (_, f) in named.items()})


def writing_options(request: PlanRequest) -> WritingOptions:
    """The mission's options: the size and limits asked for, planned for the chosen vehicle.

    A Crazyflie's flight is planned to fit its trajectory memory (the uploads of
    ``skyquill write --target crazyflie``), so its Crazyswarm download exists.
    """
    return WritingOptions(
        size_m=request.size_m,
        limits=VehicleLimits(request.vmax, request.amax, request.jmax),
        target=CRAZYFLIE if request.target == "crazyflie" else None,
    )


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
        stage = f"drone {planned + 1} of {n}: {_solve_stage(step, solves)}"
        progress(at(PLAN_WEIGHT * planned + share), stage, False)

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
                home_altitude_m=request.min_altitude_m,
            )
    except (SolverError, InfeasibleError) as exc:
        # SolverError: seen with tiny jerk limits, the QP backends hit their iteration
        # limit instead of proving infeasibility. To the person it is the same answer.
        # Drones are planned in order (workers=1): the one that failed is the next.
        raise _unplannable(request, planned + 1, exc) from exc


def _unplannable(request: PlanRequest, drone: int, exc: Exception) -> StudioInputError:
    """A drone's flight that no timing made fit: the limits, or the drawing's fidelity."""
    which = f"drone {drone}'s flight" if request.drones > 1 else "the flight"
    limits = (
        f"Speed {request.vmax:g} m/s, Acceleration {request.amax:g} m/s² and Jerk "
        f"{request.jmax:g} m/s³"
    )
    detail = (
        f"limits: could not plan drone {drone}'s flight within speed {request.vmax:g} m/s, "
        f"acceleration {request.amax:g} m/s^2 and jerk {request.jmax:g} m/s^3 ({exc}); "
        "expected looser limits or a smaller drawing"
    )
    if request.target == "crazyflie" and "upload" in str(exc):
        person = (
            f"Vehicle: {which} does not fit a Crazyflie's memory ({CRAZYFLIE.max_pieces} "
            "pieces per upload, a stroke never split between uploads) and stay within 1 % of "
            "the size of the strokes. Draw long strokes as several shorter ones, raise Size of "
            "the writing, or choose another Vehicle"
        )
        return StudioInputError(detail, "target", person)
    if "fidelity" in getattr(exc, "families", ()):
        person = (
            f"Limits: {which} could not follow the strokes closely enough (within 1 % of the "
            f"size) at {limits}, even slowed down. Raise Size of the writing, or draw fewer, "
            "larger strokes"
        )
    else:
        person = (
            f"Limits: {which} cannot be planned within {limits}. Raise the Jerk or the "
            "Acceleration, or draw less"
        )
    return StudioInputError(detail, "limits", person)


def _solve_stage(step: str, solves: int) -> str:
    """One of the planning's per-solve records in plain words, with the try's number.

    The time allocation tries its fastest timing first, then slower ones
    (:mod:`~skyquill.calligraphy.allocation`); re-segmentation comes last.
    """
    if step.startswith("re-segmenting"):
        what = "giving each part of the route the time it needs"
    elif solves == 1:
        what = "fitting the flight to the limits"
    else:
        what = "fitting again, slower"
    return f"{what} (solve {solves})"


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
        return f"planning drone {done + 1} of {n}"
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
    # The norms: the limits are norms (the page plots them against the limit lines).
    v, a, j = (np.linalg.norm(traj.evaluate(t, n), axis=1) for n in (1, 2, 3))
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
    laid = _ink_times(flight, mission, ink)
    fidelity = flight_ink(flight, mission)
    numbers = {} if fidelity is None else fidelity.as_dict()
    return {
        "flight": _round(board.to_board(tip)),
        "ink": [_round(board.to_board(_decimate(s))[:, :2]) for s in ink],
        "ink_t": [_round(_decimate(t[:, None])[:, 0]) for t in laid],
        "flight_rmse_m": flight.rmse_m,
        "ink_max_deviation_m": numbers.get("max_deviation_m"),
        "ink_iou": numbers.get("iou"),
    }


def _ink_times(flight: Flight, mission: Mission, ink: Sequence[FloatArray]) -> list[FloatArray]:
    """When each point of each ink run was laid, s (N,) per run.

    The simulator appends one ink point per step while the brush touches, so a
    run is consecutive steps: its first step is the one, after the previous
    run, where the untilted tip (vehicle minus brush) is nearest the run's first
    point in 3-D (a transit passes over a point a lift higher, so it is not taken).
    """
    tip = flight.p - mission.brush_offset
    out, start = [], 0
    for run in ink:
        gaps = np.linalg.norm(tip[start:] - run[0], axis=1)
        # The first approach (a later stroke may cross this point), then its closest step.
        near = np.flatnonzero(gaps < INK_MATCH_M)
        lo = int(near[0]) if near.size else 0
        hi = lo + INK_MATCH_STEPS if near.size else len(gaps)
        first = start + lo + int(np.argmin(gaps[lo:hi]))
        steps = np.minimum(first + np.arange(len(run)), len(flight.t) - 1)
        out.append(np.asarray(flight.t[steps], dtype=float))
        start = min(first + len(run), len(flight.t) - 1)
    return out


def _decimate(points: FloatArray) -> FloatArray:
    """At most :data:`MAX_INK_POINTS` of ``points``, the last one kept."""
    step = max(1, math.ceil(len(points) / MAX_INK_POINTS))
    return np.vstack([points[::step], points[-1:]])


def _exports(
    missions: Sequence[Mission],
    record: dict[str, Any],
    progress: Progress,
    formats: dict[str, str],
    min_altitude_m: float,
) -> tuple[dict[str, StudioFile], list[str], list[Delivered]]:
    """The plan's setpoint CSV(s) and summary, and the chosen vehicle's ``formats``.

    Everything is written through the same writer and exporters as the command
    line (a plan directory in a temporary folder, then
    :data:`~skyquill.export.EXPORTERS`), kept in memory, and checked as written.
    ``record`` (the plan id, the request, the simulated flights) heads ``summary.json``,
    which also gets each export's report under ``exports.<kind>`` (its ``as_played`` the
    verdict the page words). Files are keyed by their kind (``setpoints.csv``).
    """
    planned = [
        (
            f"drone_{i}",
            PlannedTrajectory(
                m.vehicle_trajectory(),
                tuple(m.pen_windows),
                m.limits,
                phases=flight_phases(m.vehicle_trajectory(), min_altitude_m),
            ),
        )
        for i, m in enumerate(missions, start=1)
    ]
    steps = 1 + len(formats)
    with tempfile.TemporaryDirectory(prefix="skyquill-studio-") as tmp:
        out = Path(tmp)
        progress(SHOW_END, f"writing the setpoints (file 1 of {steps})")
        summary = write_plan(
            out / "plan",
            [p for _, p in planned],
            rate=CSV_RATE_HZ,
            guaranteed=True,
            summary=record | {"drones": [m.summary() for m in missions]},
            min_altitude_m=min_altitude_m,
        )
        setpoints = [
            (f"setpoints_{i}.csv", (out / "plan" / d["csv"]).read_bytes())
            for i, d in enumerate(summary["plan"]["drones"], start=1)
        ]
        files = [
            _bundle(
                setpoints,
                "setpoints",
                DESCRIPTIONS["setpoints"],
            )
        ]
        notes = []
        delivered: list[Delivered] = []
        summary["exports"] = {}
        for k, (name, stem) in enumerate(formats.items(), start=2):
            progress(SHOW_END + 0.09 * (k - 1) / steps, f"writing the {stem} (file {k} of {steps})")
            exporter = EXPORTERS[name]
            try:
                report = exporter(
                    planned, out / f"{name}{exporter.suffix}", ExportOptions(CSV_RATE_HZ)
                )
            except InputError as exc:
                # A plan the format cannot hold is a missing download, not a failed plan.
                logger.warning("studio: %s export refused: %s", name, exc)
                notes.append(f"The {stem} file could not be made for this flight ({exc})")
                continue
            except InfeasibleError as exc:
                # A format that cannot play the plan inside its limits (a .skyc whose grid
                # cannot): no download, and the verdict says so.
                logger.warning("studio: %s export refused: %s", name, exc)
                notes.append(
                    f"The {stem} file was not made: as its player would fly it, it would go "
                    f"over the limits ({exc})"
                )
                summary["exports"][stem] = {"format": name, "refused": str(exc)}
                delivered.append(Delivered(kind=stem, verdict="refused"))
                continue
            played = report.as_played.as_dict()
            summary["exports"][stem] = {
                "format": name,
                "message": report.message.replace(str(out) + "/", ""),
                "as_played": played,
            }
            delivered.append(Delivered.model_validate({"kind": stem} | played))
            notes.append(_export_note(name, stem, report))
            parts = [(f.name, f.read_bytes()) for f in report.files]
            files.append(_bundle(parts, stem, DESCRIPTIONS.get(name, exporter.help)))
        data = json.dumps(summary, indent=2, allow_nan=False).encode()
    files.append(StudioFile("summary.json", data, "application/json", DESCRIPTIONS["summary"]))
    return {f.name: f for f in files}, notes, delivered


def _export_note(name: str, stem: str, report: ExportReport) -> str:
    """What the export was checked against, in plain words."""
    mm = 1e3 * report.max_error_m
    within = "less than 0.01 mm" if mm < 0.01 else f"{mm:.2g} mm"
    uploads = report.details.get("drone_uploads")
    extra = ""
    if uploads:
        counts = [len(d.get("uploads", ())) for d in uploads]
        extra = f"; {max(counts)} upload{'' if max(counts) == 1 else 's'} per drone at most"
    played = report.as_played
    if played.exact:
        limits = "and within every limit"
    else:
        over = ", ".join(
            f"{ORDER_NAMES[n]} {100 * e:.2f} %"
            for n, e in enumerate(played.excess, start=1)
            if e > EXACT_TOLERANCE
        )
        limits = f"but over the limits by {over} (summary.json: exports.{stem}.as_played)"
    return (
        f"The {stem} file, read back as {CONSUMERS.get(name, 'its player reads it')}, stays "
        f"within {within} of the planned flight{extra}, {limits}"
    )


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
    note = " (several files, in a zip)"
    return StudioFile(f"{stem}.zip", buffer.getvalue(), "application/zip", description + note)
