"""``skyquill export``: a plan (any planning command's output) to a drone's or a show's format."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from skyquill.cli.main import (
    Force,
    app,
    console,
    parse_color,
    positive_rate,
    say_done,
    user_errors,
)
from skyquill.coverage.geo import plan_frame
from skyquill.errors import InfeasibleError, InputError
from skyquill.export import EXPORTERS, ExportOptions
from skyquill.io.atomic import write_json
from skyquill.io.outputs import staged_output
from skyquill.io.plan_dir import plan_files, read_plan


def summary_name(out: Path) -> str:
    """The export's summary beside ``out``: ``<file name>.summary.json``, extension included."""
    return f"{out.name}.summary.json"


FORMAT_HELP = "; ".join(f"{e.name}: {e.help}" for e in EXPORTERS.values())
#: ``--tolerance`` by default, m: Skybrush's millimetre grid and float32 polynomials stay far
#: below it; a sampled format at too low a rate does not.
DEFAULT_TOLERANCE_M = 0.01
#: ``--tolerance`` accepted, m.
TOLERANCE_RANGE_M = (1e-6, 1.0)


@app.command()
def export(
    plan: Annotated[
        Path,
        typer.Argument(
            metavar="PLAN",
            help="A plan directory (fit, write, cover, paint) or a trajectory .json/.csv in one.",
        ),
    ],
    out: Annotated[Path, typer.Option("--out", help="File to write (one per drone if several).")],
    format: Annotated[str, typer.Option(help=FORMAT_HELP)] = "csv",
    rate: Annotated[
        float, typer.Option(help="Sample rate of px4/csv/json/skybrush-csv, Hz.")
    ] = 100.0,
    light: Annotated[
        str,
        typer.Option(
            "--light",
            metavar="R,G,B|#RRGGBB",
            help="Light colour while the pen is down (skyc, skybrush-csv), 0..255 each; "
            "off while it is up.",
        ),
    ] = "255,255,255",
    tolerance: Annotated[
        float,
        typer.Option(
            help="Largest distance, m, of the export as its consumer plays it from the plan; "
            "a larger one is refused and nothing is written (a higher --rate helps)."
        ),
    ] = DEFAULT_TOLERANCE_M,
    force: Force = False,
) -> None:
    """Export the planned trajectories of PLAN; read them back; report to <out>.summary.json.

    The summary is named after the whole file name (``four.skyc.summary.json``), so exports
    of one plan into one folder in different formats never collide.
    """
    with user_errors():
        if format not in EXPORTERS:
            raise InputError(f"--format: got {format!r}, expected one of {', '.join(EXPORTERS)}")
        chosen = EXPORTERS[format]
        if out.suffix.lower() != chosen.suffix:
            raise InputError(
                f"--out: got {str(out)!r}, expected a file ending in {chosen.suffix} for "
                f"--format {format}"
            )
        low, high = TOLERANCE_RANGE_M
        if not low <= tolerance <= high:
            raise InputError(f"--tolerance: got {tolerance:g}, expected {low:g} to {high:g} m")
        options = ExportOptions(
            rate_hz=positive_rate(rate),
            light_rgb=parse_color("--light", light),
            origin=plan_frame(plan),
        )
        plans = read_plan(plan)
        folder = out.parent
        with (
            console.status(f"exporting {len(plans)} trajectory(ies) to {format}"),
            staged_output(
                folder, f"export {out.name}", force=force, inputs=plan_files(plan)
            ) as stage,
        ):
            report = chosen(plans, stage / out.name, options)
            _check_faithful(report.max_error_m, tolerance, out, options.rate_hz)
            summary = report.as_dict() | {
                "files": [str(folder / f.name) for f in report.files],
                "message": report.message.replace(str(stage), str(folder)),
                "plan": str(plan),
                "drones": [name for name, _ in plans],
            }
            write_json(stage / summary_name(out), summary)
    say_done(f"{summary['message']} (read back: within {1e3 * report.max_error_m:.3g} mm)")


def _check_faithful(error_m: float, tolerance_m: float, out: Path, rate_hz: float) -> None:
    """Refuse an export that its consumer would play farther from the plan than asked."""
    if not error_m <= tolerance_m:  # NaN is refused too
        raise InfeasibleError(
            f"--tolerance: got {out.name} {1e3 * error_m:.4g} mm from the plan as its consumer "
            f"reads it back, expected at most {1e3 * tolerance_m:.4g} mm; nothing was written "
            f"(a higher --rate than {rate_hz:g} Hz, or a larger --tolerance)",
            ("tolerance",),
        )
