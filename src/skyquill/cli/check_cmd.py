"""``skyquill check``: validate a show (plans, trajectory files, ``.skyc``) as one.

Exit status 0 when every check passes, 1 when one fails, 2 for bad input (one
line naming the argument, what came and what was expected).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.table import Table
from rich.text import Text

from skyquill.cli.main import Force, app, check_out, console, say_done, user_errors
from skyquill.errors import InputError
from skyquill.io.atomic import write_json
from skyquill.io.outputs import staged_output
from skyquill.show import (
    MIN_DISTANCE_M,
    ShowLimits,
    ShowReport,
    check_show,
    load_show,
    read_geofence,
)
from skyquill.show.limits import MAX_TOLERANCE
from skyquill.show.report import UNITS

#: Most drones one ``check`` takes: their half a million pairs are bounded in memory (the
#: separation's intervals, :data:`~skyquill.show.separation.MAX_INTERVALS`) and in time
#: (bench/ceilings.py measures a .skyc of this many, neighbours close; 2,000 took over
#: 20 minutes, most of it playing the .skyc back as the drones would).
MAX_DRONES = 1_000


def _limit(flag: str, value: float | None, *, nonneg: bool = True) -> float | None:
    """A limit from the command line: finite (and >= 0 for speeds and distances)."""
    if value is None:
        return None
    if not math.isfinite(value) or (nonneg and value < 0):
        expected = "a finite number >= 0" if nonneg else "a finite number"
        raise InputError(f"{flag}: got {value:g}, expected {expected}")
    return value


def _tolerance(value: float) -> float:
    """``--tolerance``: a fraction from 0 to :data:`MAX_TOLERANCE`."""
    if not (math.isfinite(value) and 0.0 <= value <= MAX_TOLERANCE):
        raise InputError(
            f"--tolerance: got {value:g}, expected a fraction from 0 to {MAX_TOLERANCE:g} "
            "(0.01 allows 1 % over the speed and acceleration limits)"
        )
    return value


@app.command()
def check(
    paths: Annotated[
        list[Path],
        typer.Argument(
            metavar="PATH...",
            help="Plan directories (one or several drones), trajectory .json/.csv files or "
            ".skyc shows; all together are one show on one clock.",
        ),
    ],
    min_distance: Annotated[
        float, typer.Option(help="Distance every two drones keep at all times, m.")
    ] = MIN_DISTANCE_M,
    max_speed_xy: Annotated[float, typer.Option(help="Horizontal speed limit, m/s.")] = 8.0,
    max_speed_up: Annotated[float, typer.Option(help="Climb speed limit, m/s.")] = 2.0,
    max_speed_down: Annotated[float, typer.Option(help="Descent speed limit, m/s.")] = 2.0,
    max_acceleration: Annotated[
        float, typer.Option(help="Acceleration limit (norm), m/s^2.")
    ] = 4.0,
    min_altitude: Annotated[
        float | None, typer.Option(help="Lowest altitude (z), m; unchecked if not given.")
    ] = None,
    max_altitude: Annotated[float, typer.Option(help="Highest altitude (z), m.")] = 150.0,
    tolerance: Annotated[
        float,
        typer.Option(
            help="Relative excess allowed over the speed and acceleration limits, 0 to 0.05 "
            "(0.01: a .skyc as Skybrush plays it, whose millimetre grid may put it up to 1 % "
            "over its plan's limits)."
        ),
    ] = 0.0,
    geofence: Annotated[
        Path | None,
        typer.Option(
            help="GeoJSON or WKT polygon in the show's x, y metres (a GeoJSON Feature may give "
            "properties.ceiling_m); every start must lie inside."
        ),
    ] = None,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the summary as JSON on stdout, no table.")
    ] = False,
    out: Annotated[
        Path | None, typer.Option("--out", help="Also write summary.json into this folder.")
    ] = None,
    force: Force = False,
) -> None:
    """Check a show: guaranteed minimum distance, speeds, acceleration, altitude, geofence.

    The distance between every two drones is bounded between samples (not
    sampled): a pass proves no two drones ever come closer than --min-distance.
    """
    with user_errors():
        if out is not None:
            check_out(out)
        minimum = _limit("--min-distance", min_distance) or 0.0
        limits = ShowLimits(
            max_speed_xy=_limit("--max-speed-xy", max_speed_xy),
            max_speed_up=_limit("--max-speed-up", max_speed_up),
            max_speed_down=_limit("--max-speed-down", max_speed_down),
            max_acceleration=_limit("--max-acceleration", max_acceleration),
            min_altitude=_limit("--min-altitude", min_altitude, nonneg=False),
            max_altitude=_limit("--max-altitude", max_altitude, nonneg=False),
            geofence=read_geofence(geofence) if geofence is not None else None,
            tolerance=_tolerance(tolerance),
        )
        drones = load_show(paths, max_drones=MAX_DRONES)
        with console.status(f"checking {len(drones)} drone(s)"):
            report = check_show(drones, minimum, limits)
        summary = report.as_dict() | {"paths": [str(p) for p in paths]}
        if out is not None:
            with staged_output(out, "check", force=force, inputs=paths) as stage:
                write_json(stage / "summary.json", summary)
    if as_json:
        typer.echo(json.dumps(summary, indent=2))
    else:
        _print(report)
    if not report.passed:
        raise typer.Exit(1)
    say_done(
        f"{len(report.drones)} drone(s) pass: no two closer than "
        f"{report.separation.lower_bound_m:.3f} m (guaranteed)"
    )


def _print(report: ShowReport) -> None:
    """The verdict as rich tables on stdout: the separation, then every violation."""
    out = Console()
    sep = report.separation
    out.print(
        f"{len(report.drones)} drone(s), {report.duration_s:.2f} s; closest approach: "
        f"guaranteed >= {sep.lower_bound_m:.4f} m, seen {sep.attained_m:.4f} m "
        f"(minimum {sep.minimum_m:g} m; {sep.pairs_examined} of {sep.pairs} pair(s) looked at)",
        markup=False,
        highlight=False,
    )
    table = Table("check", "worst", "limit", "unit", "drone", "at (s)", title="measured")
    for m in report.measured:
        limit = "-" if m.limit is None else f"{m.limit:g}"
        cells = (m.check, f"{m.value:.4g}", limit, UNITS[m.check], m.drone, f"{m.time_s:.3f}")
        table.add_row(*(Text(c) for c in cells))  # names are paths: never markup
    out.print(table)
    if report.passed:
        return
    bad = Table("check", "drones", "first at (s)", "worst", "limit", "margin", title="FAILED")
    for v in report.violations:
        cells = (
            v.check,
            ", ".join(v.drones),
            f"{v.first_time_s:.4f}",
            f"{v.worst:.4g} {UNITS[v.check]}",
            f"{v.limit:g}",
            f"{v.margin:.4g}",
        )
        bad.add_row(*(Text(c) for c in cells))
    out.print(bad)
