"""``skyquill write``: text, strokes or an SVG to writing flights, one or several drones."""

from __future__ import annotations

import dataclasses
import inspect
import math
import re
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import numpy as np
import typer

from skyquill.cli.main import (
    Amax,
    AmaxAxis,
    Force,
    Jmax,
    JmaxAxis,
    MinAltitude,
    NormSides,
    OutDir,
    Target,
    Vmax,
    VmaxAxis,
    app,
    check_out,
    console,
    in_range,
    min_altitude,
    parse_color,
    positive_rate,
    say_done,
    scheduler_address,
    stage_progress,
    upload_target,
    user_errors,
)
from skyquill.cli.pictures import NoPictures, Pictures
from skyquill.colors import RGB
from skyquill.errors import InputError
from skyquill.io.atomic import atomic_path, write_json
from skyquill.io.outputs import staged_output
from skyquill.io.plan_dir import trajectory_names, write_plan
from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.limits import VehicleLimits
from skyquill.phases import MIN_ALTITUDE_M
from skyquill.show.lights import COLOR_BY, window_palette
from skyquill.viz.sampled import sample_missions
from skyquill.viz.worker import Drawing

#: ``--separation`` between drones, m: more than 100 m apart is no show of one drawing.
SEPARATION_RANGE_M = (0.0, 100.0)

if TYPE_CHECKING:
    from skyquill.calligraphy.board import BoardKind
    from skyquill.calligraphy.ink import InkFidelity
    from skyquill.calligraphy.mission import WritingOptions


def load_parts(
    text: str | None,
    strokes: Path | None,
    svg: Path | None,
    hanzi: Path | None,
    font: str,
    *,
    true_size: bool = False,
    layers: str = "merge",
) -> list[Any]:
    """The input as one :class:`~skyquill.strokes.Strokes` per drone (one, or an SVG's layers)."""
    from skyquill.strokes import (
        hanzi_file,
        load_stroke_json,
        load_svg,
        load_svg_layers,
        typed_strokes,
    )

    given = [
        name
        for name, v in (("TEXT", text), ("--strokes", strokes), ("--svg", svg))
        if v is not None
    ]
    if hanzi is not None and not given:
        given = ["--hanzi"]  # one character's hanzi-writer-data file, named after it
    if len(given) != 1:
        raise InputError(
            f"input: got {', '.join(given) or 'nothing'}, expected exactly one of TEXT, "
            "--strokes FILE or --svg FILE (or --hanzi CHAR.json alone)"
        )
    if hanzi is not None and given[0] not in ("TEXT", "--hanzi"):
        raise InputError(f"--hanzi: got it with {given[0]}, expected TEXT or no other input")
    if layers not in ("merge", "keep"):
        raise InputError(f"--layers: got {layers!r}, expected merge or keep")
    if svg is None and (true_size or layers != "merge"):
        flag = "--true-size" if true_size else "--layers"
        raise InputError(f"{flag}: got it with {given[0]}, expected --svg FILE")
    if svg is not None:
        if layers == "keep":
            return load_svg_layers(svg, true_size=true_size)
        return [load_svg(svg, true_size=true_size)]
    if strokes is not None:
        return [load_stroke_json(strokes)]
    if text is None:
        assert hanzi is not None
        return [hanzi_file(hanzi)]
    return [typed_strokes(text, font, hanzi)]


def true_size_m(parts: Sequence[Any]) -> float:
    """The larger side of the drawing in metres (``--true-size``), checked against the range."""
    from skyquill.calligraphy.mission import SIZE_RANGE_M

    extent = max(float(np.max(hi - lo)) for lo, hi in (p.bounds() for p in parts))
    low, high = SIZE_RANGE_M
    if not low <= extent <= high:
        raise InputError(
            f"--true-size: got a drawing of {extent:g} m, expected {low:g} to {high:g} m "
            "(check the SVG's width and height)"
        )
    return extent


@app.command()
def write(
    out: OutDir,
    text: Annotated[str | None, typer.Argument(help="Text to write (Latin or Chinese).")] = None,
    strokes: Annotated[Path | None, typer.Option(help='Stroke JSON {"strokes": [...]}')] = None,
    svg: Annotated[Path | None, typer.Option(help="SVG file: every path is a stroke.")] = None,
    true_size: Annotated[
        bool, typer.Option(help="SVG: its width/height on paper, not --size.")
    ] = False,
    layers: Annotated[
        str, typer.Option(help="SVG layers: merge (one drawing) or keep (a drone each).")
    ] = "merge",
    hanzi: Annotated[
        Path | None,
        typer.Option(help="hanzi-writer-data JSON file or directory; CHAR.json alone writes CHAR."),
    ] = None,
    font: Annotated[str, typer.Option(help="Hershey font for Latin text.")] = "futural",
    size: Annotated[float, typer.Option(help="Larger side of each drone's writing, m.")] = 0.5,
    vmax: Vmax = 1.0,
    amax: Amax = 2.0,
    jmax: Jmax = 10.0,
    vmax_axis: VmaxAxis = None,
    amax_axis: AmaxAxis = None,
    jmax_axis: JmaxAxis = None,
    norm_sides: NormSides = None,
    best_effort: Annotated[
        bool,
        typer.Option(help="Write the plan even if the path is beyond the 1 % tolerance."),
    ] = False,
    drones: Annotated[
        int,
        typer.Option(
            help="Drones writing at once: boards side by side (a grid in the sky with "
            "--board sky), or one drawing shared with --split strokes."
        ),
    ] = 1,
    rate: Annotated[float, typer.Option(help="Sample rate of the CSVs, Hz.")] = 100.0,
    fly: Annotated[bool, typer.Option(help="Also fly each drone in simulation (RPT).")] = False,
    board: Annotated[
        str,
        typer.Option(
            help="horizontal (the paper's), wall, or sky (light painting on a plane in the "
            "air, no contact: the pen is the drone's light)."
        ),
    ] = "horizontal",
    board_height: Annotated[
        float,
        typer.Option(help="Height of the board (a wall or sky board: of the writing's bottom), m."),
    ] = 1.0,
    board_yaw: Annotated[
        float, typer.Option(help="Sky board: turn about the vertical, degrees (0: facing -y).")
    ] = 0.0,
    board_tilt: Annotated[
        float, typer.Option(help="Sky board: lean back from vertical, degrees (-80 to 80).")
    ] = 0.0,
    plane_weight: Annotated[
        float | None,
        typer.Option(
            help="Sky board: weight of the cost that keeps the path on the board's plane "
            "(paper 003 §5.3); 0 disables it. Default 1e5."
        ),
    ] = None,
    grid: Annotated[
        str | None,
        typer.Option(help="Sky boards of several drones: ROWSxCOLUMNS (default nearly square)."),
    ] = None,
    split: Annotated[
        str | None,
        typer.Option(
            help="'strokes': share one drawing's strokes among --drones drones on one board, "
            "each flight about as long."
        ),
    ] = None,
    separation: Annotated[
        float, typer.Option(help="Least distance between any two drones at any time, m.")
    ] = 1.0,
    lift: Annotated[
        float | None,
        typer.Option(help="Brush lift between strokes, m (default 0.05; sky boards: none)."),
    ] = None,
    follow: Annotated[
        str,
        typer.Option(
            help="What follows the strokes on a horizontal board: tip (the swinging brush "
            "tip, which leaves the ink) or path (the vehicle's path, paper 000)."
        ),
    ] = "tip",
    brush_length: Annotated[float, typer.Option(help="Vehicle centre to brush tip, m.")] = 0.3,
    press_depth: Annotated[
        float, typer.Option(help="How deep the brush is pressed while writing (sets the width), m.")
    ] = 0.005,
    scheduler: Annotated[
        str | None,
        typer.Option(help="dask.distributed scheduler address (or 'local') for large shows."),
    ] = None,
    light_color: Annotated[
        list[str] | None,
        typer.Option(
            metavar="R,G,B|#RRGGBB",
            help="Light colour while the pen is down (kept in trajectory.json for the Skybrush "
            "exports); repeat for a palette, given out per --color-by.",
        ),
    ] = None,
    color_by: Annotated[
        str, typer.Option(help="drone (each drone the next colour) or stroke (each stroke).")
    ] = "drone",
    target: Target = None,
    min_altitude_m: MinAltitude = MIN_ALTITUDE_M,
    force: Force = False,
    no_pictures: NoPictures = False,
) -> None:
    """Plan pen-up / pen-down writing flights; write CSVs, input_strokes.json, plot, summary.

    Each drone's mission starts and ends hovering at --min-altitude above its home (the
    vehicle takes off to it and lands from it); nothing between is planned below it.

    On a sky board (light painting) also long_exposure.png, the photograph of the lights
    from in front, and preview.gif (``skyquill render`` shows them from any view).
    """
    from skyquill.calligraphy.mission import MAX_ALTITUDE_M
    from skyquill.calligraphy.show import MAX_DRONES, plan_show

    with user_errors():
        check_out(out)
        rate = positive_rate(rate)
        floor = min_altitude(min_altitude_m)
        scheduler = scheduler_address(scheduler)
        in_range("--board-height", board_height, 0.0, MAX_ALTITUDE_M, "m", open_low=True)
        in_range("--separation", separation, *SEPARATION_RANGE_M, "m", open_low=True)
        palette = _palette(light_color, color_by)
        kind = _board_kind(board, fly)
        pose = _sky_pose(kind, board_yaw, board_tilt, plane_weight, grid, lift)
        options = writing_options(
            size=size, vmax=vmax, amax=amax, jmax=jmax, vmax_axis=vmax_axis,
            amax_axis=amax_axis, jmax_axis=jmax_axis, norm_sides=norm_sides,
            best_effort=best_effort, brush_length=brush_length, press_depth=press_depth,
            follow=follow, target=target, plane_weight=plane_weight,
        )  # fmt: skip
        if not 1 <= drones <= MAX_DRONES:  # before the text is typed: that takes seconds
            raise InputError(f"--drones: got {drones}, expected 1 to {MAX_DRONES}")
        sharing = _Sharing(kind, board_height, pose, lift, separation, _split(split, drones))
        if sharing.split or drones == 1:
            parts = load_parts(text, strokes, svg, hanzi, font, true_size=true_size, layers=layers)
        else:
            if text is None or strokes is not None or svg is not None:
                raise InputError(
                    "--drones: several drones need TEXT to share out, got a file "
                    "(or --split strokes)"
                )
            parts = _text_parts(text, drones, font, hanzi, by_character=kind == "sky")
        if true_size:
            options = dataclasses.replace(options, size_m=true_size_m(parts))
        places, extra = sharing.places(parts, drones, options)
        if sharing.split:
            parts = places.parts
        with stage_progress() as progress:
            show = plan_show(
                parts,
                options,
                separation,
                scheduler=scheduler,
                board_kind=kind,
                board_height_m=board_height,
                lift_m=lift,
                fly=fly,
                progress=progress,
                board_yaw_deg=pose.yaw_deg,
                board_tilt_deg=pose.tilt_deg,
                grid=pose.grid,
                places=places.places if sharing.split else None,
                home_altitude_m=floor,
            )
        inputs = [p for p in (strokes, svg, hanzi) if p is not None]
        summary = write_outputs(
            show,
            out,
            rate,
            force=force,
            inputs=inputs,
            extra=extra(show),
            palette=palette,
            min_altitude_m=floor,
            pictures=not no_pictures,
        )
    say_done(
        f"{out}: {summary['duration_s']:.1f} s of flight, planned in "
        f"{summary['planning_time_s']:.2f} s, deviation {1e3 * summary['deviation']['max_m']:.2f}"
        f" mm, max excess {summary['max_excess']:.1e}{_uploads_note(summary)}"
    )


def _uploads_note(summary: dict[str, Any]) -> str:
    """``", 2 uploads for crazyflie (31, 31 pieces)"`` with a target, else nothing."""
    if "target" not in summary:
        return ""
    pieces = [u["pieces"] for d in summary["drones"] for u in d["target"]["uploads"]]
    return (
        f", {len(pieces)} upload(s) for {summary['target']['name']} "
        f"({', '.join(map(str, pieces))} pieces)"
    )


def _follow(name: str) -> Any:
    if name not in ("tip", "path"):
        raise InputError(f"--follow: got {name!r}, expected tip or path")
    return name


def _board_kind(name: str, fly: bool) -> Any:
    if name not in ("horizontal", "wall", "sky"):
        raise InputError(f"--board: got {name!r}, expected horizontal, wall or sky")
    if fly and name != "horizontal":
        raise InputError(
            f"--fly: got --board {name}, expected horizontal (the simulated contact board)"
        )
    return name


@dataclasses.dataclass(frozen=True)
class _Pose:
    """A sky board's pose and grid from the command line (zeros and ``None`` otherwise)."""

    yaw_deg: float = 0.0
    tilt_deg: float = 0.0
    grid: tuple[int, int] | None = None


def _sky_pose(
    kind: str,
    yaw: float,
    tilt: float,
    plane_weight: float | None,
    grid: str | None,
    lift: float | None,
) -> _Pose:
    """``--board-yaw``, ``--board-tilt``, ``--plane-weight``, ``--grid`` against ``--board``."""
    from skyquill.calligraphy.board import MAX_TILT_DEG

    given = {
        "--board-yaw": yaw != 0.0,
        "--board-tilt": tilt != 0.0,
        "--plane-weight": plane_weight is not None,
        "--grid": grid is not None,
    }
    if kind != "sky":
        for flag, used in given.items():
            if used:
                raise InputError(f"{flag}: got it with --board {kind}, expected --board sky")
        return _Pose()
    if lift is not None:
        raise InputError(
            f"--lift: got {lift:g} m with --board sky, expected none (the light is off between "
            "strokes and the transits stay in the board's plane)"
        )
    if not (np.isfinite(yaw) and -180.0 <= yaw <= 180.0):
        raise InputError(f"--board-yaw: got {yaw:g}, expected -180 to 180 degrees")
    if not (np.isfinite(tilt) and abs(tilt) <= MAX_TILT_DEG):
        raise InputError(
            f"--board-tilt: got {tilt:g}, expected -{MAX_TILT_DEG:g} to {MAX_TILT_DEG:g} degrees "
            "from vertical"
        )
    if plane_weight is not None and not (np.isfinite(plane_weight) and plane_weight >= 0):
        raise InputError(f"--plane-weight: got {plane_weight:g}, expected >= 0 (0: off)")
    return _Pose(yaw, tilt, None if grid is None else _grid(grid))


_DIGITS = re.compile(r"[0-9]{1,6}", re.ASCII)


def _grid(text: str) -> tuple[int, int]:
    """``"4x5"`` to ``(4, 5)``."""
    rows, sep, columns = text.lower().partition("x")
    if not (sep and _DIGITS.fullmatch(rows.strip()) and _DIGITS.fullmatch(columns.strip())):
        raise InputError(f"--grid: got {text!r}, expected ROWSxCOLUMNS, e.g. 4x5")
    from skyquill.calligraphy.show import MAX_DRONES

    shape = int(rows), int(columns)
    if min(shape) < 1:
        raise InputError(f"--grid: got {text!r}, expected at least one row and one column")
    if shape[0] * shape[1] > MAX_DRONES:
        raise InputError(
            f"--grid: got {text!r} ({shape[0] * shape[1]:,} boards), expected at most "
            f"{MAX_DRONES} boards, one per drone (rows x columns <= {MAX_DRONES})"
        )
    return shape


def _split(name: str | None, drones: int) -> bool:
    """Whether ``--split strokes`` was asked for (checked)."""
    if name is None:
        return False
    if name != "strokes":
        raise InputError(f"--split: got {name!r}, expected strokes")
    if drones < 2:
        raise InputError(f"--split: got --drones {drones}, expected at least 2 drones to share")
    return True


def _text_parts(
    text: str, drones: int, font: str, hanzi: Path | None, *, by_character: bool
) -> list[Any]:
    """``text`` shared among ``drones`` with one scale: by words (hanzi: characters),
    or on a sky grid, when there are fewer words than drones, a character each."""
    from skyquill.strokes import typed_parts

    if by_character and len(text.split()) < drones:
        # typed_parts shares Latin text by words: one word per character.
        text = " ".join(c for c in text if not c.isspace())
    return typed_parts(text, drones, font, hanzi)


@dataclasses.dataclass(frozen=True)
class _Places:
    """Drones sharing one board (``--split strokes``): their parts and places."""

    parts: list[Any]
    places: list[tuple[Any, Any]]


@dataclasses.dataclass(frozen=True)
class _Sharing:
    """How several drones share the work: own boards (plan_show's layout) or a split."""

    kind: BoardKind
    height_m: float
    pose: _Pose
    lift_m: float | None
    separation_m: float
    split: bool

    def places(
        self, parts: list[Any], drones: int, options: WritingOptions
    ) -> tuple[_Places, Callable[[Any], dict[str, Any]]]:
        """With a split: each drone's strokes, board and home, and the summary's
        ``split`` section (the flight-time balance) once planned; else nothing."""
        if not self.split:
            return _Places(parts, []), lambda show: self._grid(len(parts))
        from skyquill.calligraphy.artwork import split_homes, split_strokes
        from skyquill.calligraphy.board import Board
        from skyquill.calligraphy.show import DEFAULT_LIFT_M

        if len(parts) != 1:
            raise InputError("--split: got SVG layers (--layers keep), expected one drawing")
        lift = DEFAULT_LIFT_M[self.kind] if self.lift_m is None else self.lift_m
        origin = np.array([0.0, 0.0, self.height_m])
        board = Board(self.kind, origin, lift, self.pose.yaw_deg, self.pose.tilt_deg)
        shared = split_strokes(parts[0], drones, board, options)
        homes = split_homes(shared, board, options.size_m, self.separation_m)

        def balance(show: Any) -> dict[str, Any]:
            times = [m.trajectory.duration for m in show.missions]
            return {
                "split": {
                    "by": "strokes",
                    "strokes_per_drone": [list(s) for s in shared.strokes],
                    "estimated_writing_s": list(shared.estimated_s),
                    "flight_time_s": times,
                    "max_over_min_flight_time": max(times) / min(times),
                }
            }

        return _Places(list(shared.parts), [(board, h) for h in homes]), balance

    def _grid(self, n: int) -> dict[str, Any]:
        """The summary's ``grid`` section for several sky boards, else nothing."""
        if self.kind != "sky" or n < 2:
            return {}
        from skyquill.calligraphy.artwork import grid_shape

        rows, columns = grid_shape(n, self.pose.grid)
        return {"grid": {"rows": rows, "columns": columns}}


def write_outputs(
    show: Any,
    out: Path,
    rate: float,
    *,
    force: bool = False,
    inputs: Sequence[Path] = (),
    extra: dict[str, Any] | None = None,
    palette: tuple[Sequence[RGB], str] | None = None,
    min_altitude_m: float = MIN_ALTITUDE_M,
    pictures: bool = True,
) -> dict[str, Any]:
    """The plan directory: trajectories, ``input_strokes.json``, ``plot.png``, ``summary.json``.

    ``pictures``: draw them (``--no-pictures`` skips every picture; ``summary.json``'s
    ``pictures`` says which were drawn and how long they took).

    ``extra``: more top-level sections of ``summary.json`` (``--split``'s balance).
    ``palette``: the light colours and how they are given out (``"drone"`` or
    ``"stroke"``, :func:`~skyquill.show.lights.window_palette`), kept per pen window in
    each ``trajectory.json``. On sky boards also ``long_exposure.png`` and
    ``preview.gif`` (:func:`~skyquill.viz.light_painting.write_pictures`).

    Flown over a horizontal board (``show.flights``), also each drone's
    simulated ink beside its input: ``ink.png`` (``ink_<i>.png`` for several
    drones, like ``trajectory_<i>.csv``), and its fidelity in the drone's
    ``flight`` section of ``summary.json``.
    """
    missions = list(show.missions)
    names = trajectory_names(len(missions))
    per_drone: list[dict[str, Any]] = []
    planned = []
    strokes_json: list[Any] = []
    inks: dict[str, InkFidelity] = {}  # ink picture name: the fidelity it shows
    colors = _window_colors(missions, palette)
    for mission, (name, _), rgb in zip(missions, names, colors, strict=True):
        vehicle = mission.vehicle_trajectory()
        limits = mission.limits
        planned.append(PlannedTrajectory(vehicle, tuple(mission.pen_windows), limits, rgb))
        strokes_json.append([(s + mission.brush_offset).tolist() for s in mission.strokes_world])
        flight = show.flights[len(per_drone)] if show.flights else None
        fidelity = _ink_fidelity(mission, flight)
        if fidelity is not None:
            inks[_ink_name(name)] = fidelity
        per_drone.append(_drone_summary(mission, name, flight, fidelity))
    firsts = np.cumsum([0] + [len(s) for s in strokes_json]).tolist()
    payload: dict[str, Any] = {
        "strokes": [stroke for drone in strokes_json for stroke in drone],
        "frame": "world, z up, m; the vehicle's positions (brush tip + brush offset)",
        # Drone i wrote strokes[first[i]:first[i + 1]] (its trajectory_<i>.csv).
        "first_stroke_of_drone": firsts,
    }
    closest = show.min_separation_m if len(missions) > 1 else None
    drawn = Pictures(pictures)
    with staged_output(out, "write", force=force, inputs=inputs) as stage:
        write_json(stage / "input_strokes.json", payload, indent=None)
        if drawn.drawn:
            with drawn.timing(*inks):
                _write_ink_pictures(stage, inks)
            _light_pictures(stage, missions, planned, drawn)
        return write_plan(
            stage,
            planned,
            rate=rate,
            guaranteed=True,
            summary=_merge(per_drone)
            | {
                "vehicle_limits": missions[0].options.limits.as_dict(),
                "min_separation_m": closest,
                "drones": per_drone,
                "pictures": drawn.entry,
            }
            | (extra or {}),
            plot=drawn.sampled(lambda: _missions_drawing(missions)),
            min_altitude_m=min_altitude_m,
        )


def _palette(colors: list[str] | None, by: str) -> tuple[list[RGB], str] | None:
    """``--light-color`` (repeated) and ``--color-by``, checked; ``None`` without colours."""
    if by not in COLOR_BY:
        raise InputError(f"--color-by: got {by!r}, expected one of {', '.join(COLOR_BY)}")
    if not colors:
        return None
    return [parse_color("--light-color", c) for c in colors], by


def _window_colors(
    missions: Sequence[Any], palette: tuple[Sequence[RGB], str] | None
) -> list[tuple[RGB, ...]]:
    """Each mission's colour per pen window; empty tuples without a palette."""
    if palette is None:
        return [()] * len(missions)
    return window_palette([len(m.pen_windows) for m in missions], *palette)


def _missions_drawing(missions: Sequence[Any]) -> Drawing:
    """``plot.png``: matplotlib is imported where it is drawn, only when drawn, inside the
    pictures' time (:class:`~skyquill.cli.pictures.Pictures`)."""
    samples = sample_missions(list(missions), "skyquill write")
    return Drawing("skyquill.viz.writing_plot", "draw_missions", samples)


def _light_pictures(
    stage: Path, missions: Sequence[Any], planned: Sequence[PlannedTrajectory], drawn: Pictures
) -> None:
    """Light painting (sky boards): the long exposure and the preview; else nothing."""
    if missions[0].board.kind != "sky":
        return
    from skyquill.viz.light_painting import write_pictures

    # The preview keeps every light on screen: it builds up the photograph.
    with drawn.timing("long_exposure.png", "preview.gif"):
        drawn.entry |= write_pictures(planned, stage, trail_s=math.inf)


def _ink_fidelity(mission: Any, flight: Any) -> InkFidelity | None:
    """The flight's ink against the mission's strokes; ``None`` unflown or off a contact board."""
    if flight is None:
        return None
    from skyquill.calligraphy.ink import flight_ink

    return flight_ink(flight, mission)


def _ink_name(trajectory_csv: str) -> str:
    """``ink.png`` beside ``trajectory.csv``, ``ink_<i>.png`` beside ``trajectory_<i>.csv``."""
    return "ink" + trajectory_csv.removeprefix("trajectory").removesuffix(".csv") + ".png"


def _write_ink_pictures(out: Path, inks: dict[str, InkFidelity]) -> None:
    """Draw each drone's ink beside its input (:func:`~skyquill.viz.ink_plot.render_ink`)."""
    from skyquill.viz.ink_plot import render_ink

    for name, fidelity in inks.items():
        with atomic_path(out / name) as tmp:
            render_ink(fidelity, tmp, f"skyquill write, {name.removesuffix('.png')}:")


def _drone_summary(
    mission: Any, name: str, flight: Any, ink: InkFidelity | None = None
) -> dict[str, Any]:
    """A drone's entry in ``summary.json``; flown, its flight and (``ink``) its ink's fidelity."""
    entry: dict[str, Any] = {"file": name} | mission.summary()
    if flight is None:
        return entry
    entry["flight"] = flight.summary()  # flown by plan_show(fly=True): RPT over the board
    if ink is not None:  # a horizontal (contact) board: the brush left ink
        numbers = ink.as_dict()
        entry["flight"] |= {
            "ink_max_deviation_m": numbers["max_deviation_m"],  # None: no ink at all
            "ink_strokes": ink.ink_strokes,
            "input_strokes": ink.input_strokes,
            "ink_iou": ink.iou,
            "ink_width_m": ink.width_m,
            "ink": numbers,
        }
    return entry


def _merge(drones: list[dict[str, Any]]) -> dict[str, Any]:
    """The summary's top level: worst case over drones."""
    return {
        "duration_s": max(d["duration_s"] for d in drones),
        "planning_time_s": sum(d["planning_time_s"] for d in drones),
        "limits": drones[0]["limits"],
        "max_speed": max(d["max_speed"] for d in drones),
        "max_acc": np.max([d["max_acc"] for d in drones], axis=0).tolist(),
        "max_jerk": np.max([d["max_jerk"] for d in drones], axis=0).tolist(),
        "max_excess": max(d["max_excess"] for d in drones),
        "deviation": {k: max(d["deviation"][k] for d in drones) for k in drones[0]["deviation"]},
        "strokes": sum(d["strokes"] for d in drones),
    } | _merge_targets(drones)


def _merge_targets(drones: list[dict[str, Any]]) -> dict[str, Any]:
    """With ``--target``: the target and the largest upload over drones (details per drone)."""
    if "target" not in drones[0]:
        return {}
    uploads = [u for d in drones for u in d["target"]["uploads"]]
    return {
        "target": {
            "name": drones[0]["target"]["name"],
            "strategies": [d["target"]["strategy"] for d in drones],
            "uploads_per_drone": [len(d["target"]["uploads"]) for d in drones],
            "max_upload_pieces": max(u["pieces"] for u in uploads),
            "max_upload_bytes": max(u["bytes"] for u in uploads),
        }
    }


@app.command()
def demo(out: OutDir = Path("out/demo"), force: Force = False) -> None:
    """Write 永 on a horizontal board, fly it with the RPT controller, plot and summarise."""
    from skyquill.calligraphy.mission import WritingOptions
    from skyquill.calligraphy.show import plan_show
    from skyquill.strokes import hanzi_strokes

    with user_errors():
        check_out(out)
        with console.status("planning 永 (the eight strokes of calligraphy), flying it"):
            show = plan_show([hanzi_strokes("永")], WritingOptions(), fly=True)
        summary = write_outputs(show, out, 100.0, force=force)
    flight = summary["drones"][0]["flight"]
    say_done(
        f"wrote 永 in {summary['duration_s']:.1f} s of flight "
        f"(planned in {summary['planning_time_s']:.2f} s, pen-down deviation "
        f"{1e3 * summary['deviation']['max_m']:.2f} mm, max excess {summary['max_excess']:.1e}); "
        f"flown with RPT: RMSE {1e3 * flight['rmse_m']:.2f} mm, the ink within "
        f"{1e3 * flight['ink_max_deviation_m']:.2f} mm, IoU {flight['ink_iou']:.2f}.\n"
        f"  {out / 'plot.png'}\n  {out / 'ink.png'}\n  {out / 'summary.json'}\n"
        f"  {out / 'trajectory.csv'}"
    )


def writing_options(
    *,
    size: float,
    vmax: float | None,
    amax: float | None,
    jmax: float | None,
    vmax_axis: float | None,
    amax_axis: float | None,
    jmax_axis: float | None,
    norm_sides: int | None,
    best_effort: bool,
    brush_length: float,
    press_depth: float,
    follow: str,
    target: str | None,
    plane_weight: float | None = None,
) -> WritingOptions:
    """The ``WritingOptions`` :func:`write` plans with, from its own arguments."""
    from skyquill.calligraphy.brush import Brush
    from skyquill.calligraphy.mission import WritingOptions

    options = WritingOptions(
        size_m=size,
        limits=VehicleLimits(vmax, amax, jmax, vmax_axis, amax_axis, jmax_axis),
        norm_sides=norm_sides,
        best_effort=best_effort,
        brush=Brush(length_m=brush_length, press_depth_m=press_depth),
        follow=_follow(follow),
        target=upload_target(target),
    )
    if plane_weight is None:
        return options
    return dataclasses.replace(options, plane_weight=plane_weight)


def default_writing_options() -> WritingOptions:
    """What ``skyquill write`` plans with when no option is given (benchmarks and tests)."""
    defaults = {name: p.default for name, p in inspect.signature(write).parameters.items()}
    wanted = inspect.signature(writing_options).parameters
    return writing_options(**{name: defaults[name] for name in wanted})
