"""``skyquill paint``: a simulated dot-painting mission on a wall (paper 002).

Writes a plan directory into ``--out``: ``painted.csv`` (per dot: reference and painted
``x, z``), ``plot.png``, the flight's ``trajectory.csv``/``trajectory.json`` and
``summary.json``.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from skyquill.cli.main import (
    Force,
    MinAltitude,
    OutDir,
    app,
    check_out,
    console,
    in_range,
    min_altitude,
    parse_vector3,
    positive_rate,
    progress_bar,
    say_done,
    user_errors,
)
from skyquill.cli.pictures import NoPictures, Pictures
from skyquill.errors import InputError
from skyquill.phases import MIN_ALTITUDE_M

if TYPE_CHECKING:  # the painting package is imported lazily
    from rich.progress import Progress

    from skyquill.painting.estimate import UpdateMode
    from skyquill.painting.mission import MissionResult
    from skyquill.validation import FloatArray

#: Largest |gamma| accepted, deg: beyond it the drone does not face the wall.
MAX_GAMMA_DEG = 60.0
#: Widest probing pass spacing, m (wider is one probe at each end of any drawing).
MAX_PROBE_SPACING_M = 10.0
#: Largest ``--width`` of a stippled drawing, m.
MAX_WIDTH_M = 20.0


@app.command()
def paint(
    out: OutDir,
    dots_csv: Annotated[
        Path | None,
        typer.Argument(help="Dots CSV with columns x (along the wall) and z (height), m."),
    ] = None,
    image: Annotated[
        Path | None, typer.Option(help="Stipple this PNG/JPEG instead of reading DOTS.csv.")
    ] = None,
    dots: Annotated[int, typer.Option(help="Number of dots to stipple from --image.")] = 140,
    width: Annotated[float, typer.Option(help="Width of the stippled drawing, m.")] = 3.5,
    gamma: Annotated[float, typer.Option(help="True yaw offset of the placement, deg.")] = 0.0,
    offset: Annotated[
        str, typer.Option(help="True placement offset delta x,y,z in the wall frame, m.")
    ] = "0,-1.1,0",
    wall_angles: Annotated[
        str,
        typer.Option(
            help="Segment angles left to right, deg, e.g. -10,0,10 (0: flat), splitting the "
            "drawing's width equally."
        ),
    ] = "0",
    wall: Annotated[
        Path | None,
        typer.Option(
            help="The wall from a TOML file instead: [[segment]]s, a [cylinder] or a [recess] "
            "(docs/wall-painting-estimation.md)."
        ),
    ] = None,
    estimator: Annotated[
        str,
        typer.Option(
            help="joint (placement and wall shape together), or paper 002's none, svd, robust."
        ),
    ] = "joint",
    localization: Annotated[str, typer.Option(help="onboard or truth.")] = "onboard",
    order: Annotated[
        str,
        typer.Option(
            help="shortest (a short tour), spread (first dots far apart), paper (right-left, "
            "top-bottom) or given."
        ),
    ] = "shortest",
    probe_spacing: Annotated[
        float,
        typer.Option(
            help="joint: touch the wall without painting every this many m across the drawing "
            "before the first dot (0: no probing pass)."
        ),
    ] = 0.4,
    update: Annotated[
        str, typer.Option(help="Segmented walls: depth (eq. 15) or normal (fresco).")
    ] = "depth",
    false_contacts: Annotated[
        float, typer.Option(help="Probability of a false contact per approach.")
    ] = 0.0,
    missed_contacts: Annotated[
        float, typer.Option(help="Probability of a missed contact per approach.")
    ] = 0.0,
    seed: Annotated[int, typer.Option(help="Seed of the random generator.")] = 0,
    rate: Annotated[float, typer.Option(help="Sample rate of trajectory.csv, Hz.")] = 100.0,
    min_altitude_m: MinAltitude = MIN_ALTITUDE_M,
    force: Force = False,
    no_pictures: NoPictures = False,
) -> None:
    """Paint DOTS.csv (or a stippled --image) on a wall; write summary.json, painted.csv, plot."""
    import numpy as np

    from skyquill.io.outputs import staged_output
    from skyquill.io.plan_dir import write_plan
    from skyquill.io.points import check_rows_written
    from skyquill.io.trajectory_json import PlannedTrajectory
    from skyquill.painting.dots import MAX_DOTS, drawing_span
    from skyquill.painting.flight import FlightClock, painting_flight
    from skyquill.painting.mission import MissionConfig, check_on_wall, run_mission
    from skyquill.painting.wall import Placement, Wall, parse_angles
    from skyquill.painting.wall_file import read_wall
    from skyquill.validation import as_int, as_seed
    from skyquill.viz.painting_plot import plot_mission

    with user_errors():
        check_out(out)
        floor = min_altitude(min_altitude_m)
        seed = as_seed("--seed", seed)
        positive_rate(rate)  # a long painting needs a lower one: trajectory.csv has a ceiling
        as_int("--dots", dots, low=1, high=MAX_DOTS)  # checked with a CSV too: never ignored
        in_range("--width", width, 0.0, MAX_WIDTH_M, "m", open_low=True)
        _check_choices(estimator, order, false_contacts, missed_contacts)
        update_mode = _update(update)
        if not -MAX_GAMMA_DEG <= gamma <= MAX_GAMMA_DEG:
            raise InputError(
                f"--gamma: got {gamma:g}, expected an angle from -{MAX_GAMMA_DEG:g} to "
                f"{MAX_GAMMA_DEG:g} deg"
            )
        delta = parse_vector3("--offset", offset, "m")
        if not -20.0 <= delta[1] < 0.0 or np.abs(delta).max() > 20.0:
            raise InputError(
                f"--offset: got {offset!r}, expected the drone in front of the wall: "
                "-20 <= y < 0 m and every component within 20 m"
            )
        angles = parse_angles(wall_angles)
        if wall is not None and wall_angles != "0":
            raise InputError(
                f"--wall / --wall-angles: got both ({wall.name}, {wall_angles!r}), expected one"
            )
        if not (math.isfinite(probe_spacing) and 0.0 <= probe_spacing <= MAX_PROBE_SPACING_M):
            raise InputError(
                f"--probe-spacing: got {probe_spacing:g}, expected 0 (no probing pass) to "
                f"{MAX_PROBE_SPACING_M:g} m"
            )
        surface = None if wall is None else read_wall(wall)
        with _progress() as bar:
            points = _dots(dots_csv, image, dots, width, seed, bar)
            if surface is None:
                surface = Wall.segmented(angles, drawing_span(points))
            check_on_wall(
                points,
                surface,
                name=str(dots_csv.name if dots_csv else "--image"),
                wall_name=wall.name if wall else "--wall-angles",
            )
            task = bar.add_task("painting", total=None)
            result = run_mission(
                points,
                wall=surface,
                truth=Placement(delta, math.radians(gamma)),
                estimator=estimator,
                localization=localization,
                order=order,
                update=update_mode,
                config=MissionConfig(
                    false_contact_rate=false_contacts,
                    missed_contact_rate=missed_contacts,
                    probe_spacing_m=probe_spacing,
                ),
                rng=np.random.default_rng(seed),
                progress=lambda done, total: bar.update(task, completed=done, total=total),
                # trajectory.csv too long for its readers: refused as soon as it is sure
                flown=FlightClock(
                    lambda at_least_s: check_rows_written(at_least_s, rate, "--rate", at_least=True)
                ).add,
            )
        inputs = [p for p in (dots_csv, image, wall) if p is not None]
        with (
            console.status("timing the flight's legs, writing and checking the plan"),
            staged_output(out, "paint", force=force, inputs=inputs) as stage,
        ):
            _write_painted(stage / "painted.csv", result)
            flown = painting_flight(result)
            drawn = Pictures(not no_pictures)
            name = (dots_csv or image or Path("")).name
            write_plan(
                stage,
                [PlannedTrajectory(flown.trajectory, flown.pen_windows_s, flown.limits)],
                rate=rate,
                guaranteed=True,
                summary=result.summary()
                | {
                    "source": str(dots_csv or image),
                    "wall": str(wall) if wall else f"--wall-angles {wall_angles}",
                    "seed": seed,
                    "order": order,
                    "gamma_deg": gamma,
                    "offset_m": [float(v) for v in delta],
                    "trajectory_duration_s": flown.trajectory.duration,
                    "pictures": drawn.entry,
                },
                plot=drawn.plot(lambda path: plot_mission(result, path, name)),
                min_altitude_m=floor,
            )
    say_done(
        f"{out}: {result.painted.sum()} of {len(result.reference)} dots, RMSE "
        f"{100 * result.rmse_m:.2f} cm, max {100 * result.max_error_m:.2f} cm, "
        f"{result.flight_time_s / 60:.1f} min ({result.battery_use:.1f} batteries), "
        f"{result.landings} landing(s)" + _wall_note(result)
    )


def _wall_note(result: MissionResult) -> str:
    """What the joint estimator says of the wall, when it does not fit its model."""
    fit = result.wall_fit
    if fit is None or fit.fits:
        return ""
    return (
        f"; the wall does not fit the plane-pieces model ({fit.pieces} pieces, "
        f"{100 * fit.residual_m:.1f} cm off, {fit.outliers} contacts dropped): the painting "
        "follows the closest model"
    )


def _progress() -> Progress:
    """A rich progress bar on stderr (the console the CLI prints to)."""
    from rich.progress import BarColumn, MofNCompleteColumn, TextColumn

    return progress_bar(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn())


def _check_choices(
    estimator: str, order: str, false_contacts: float, missed_contacts: float
) -> None:
    """Refuse an unknown ``--estimator`` or ``--order``, or a contact chance outside [0, 1)."""
    from skyquill.painting.mission import ESTIMATORS
    from skyquill.painting.order import ORDERS

    if estimator not in ESTIMATORS:
        raise InputError(f"--estimator: got {estimator!r}, expected one of {', '.join(ESTIMATORS)}")
    if order not in ORDERS:
        raise InputError(f"--order: got {order!r}, expected one of {', '.join(ORDERS)}")
    for option, chance in (
        ("--false-contacts", false_contacts),
        ("--missed-contacts", missed_contacts),
    ):
        if not 0.0 <= chance < 1.0:
            raise InputError(f"{option}: got {chance:g}, expected a probability in [0, 1)")


def _update(name: str) -> UpdateMode:
    if name not in ("depth", "normal"):
        raise InputError(f"--update: got {name!r}, expected 'depth' or 'normal'")
    return "depth" if name == "depth" else "normal"


def _dots(
    dots_csv: Path | None, image: Path | None, n: int, width: float, seed: int, bar: Progress
) -> FloatArray:
    """The dots from the CSV, or stippled from the image (exactly one of them)."""
    import numpy as np

    from skyquill.painting.dots import load_darkness, read_dots_csv, stipple

    if (dots_csv is None) == (image is None):
        raise InputError(
            "DOTS.csv / --image: got "
            + ("both" if dots_csv is not None else "neither")
            + ", expected exactly one of them"
        )
    if dots_csv is not None:
        return read_dots_csv(dots_csv)
    assert image is not None  # narrowed by the check above
    darkness = load_darkness(image)
    task = bar.add_task("stippling", total=None)
    return stipple(
        darkness,
        n,
        width_m=width,
        rng=np.random.default_rng(seed),
        progress=lambda done, total: bar.update(task, completed=done, total=total),
    )


def _write_painted(path: Path, result: MissionResult) -> None:
    """``dot, order, x_ref, z_ref, x_painted, z_painted, error_m`` (empty when not painted)."""
    rank = {int(i): k for k, i in enumerate(result.order)}
    with path.open("w", newline="", encoding="utf-8") as handle:
        out = csv.writer(handle)
        out.writerow(["dot", "order", "x_ref", "z_ref", "x_painted", "z_painted", "error_m"])
        for i, (ref, hit, err) in enumerate(
            zip(result.reference, result.painted_w, result.errors_m, strict=True)
        ):
            done = math.isfinite(err)
            cells = [f"{hit[0]:.5f}", f"{hit[2]:.5f}", f"{err:.5f}"] if done else ["", "", ""]
            out.writerow([i, rank[i], f"{ref[0]:.5f}", f"{ref[1]:.5f}", *cells])
