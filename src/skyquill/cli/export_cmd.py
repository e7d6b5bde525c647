"""``skyquill export``: a plan (any planning command's output) to a drone's or a show's format."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from skyquill.cli.main import app, console, positive_rate, user_errors
from skyquill.errors import InputError
from skyquill.export import EXPORTERS, ExportOptions
from skyquill.io.atomic import write_json
from skyquill.io.plan_dir import read_plan

FORMAT_HELP = "; ".join(f"{e.name}: {e.help}" for e in EXPORTERS.values())


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
    rate: Annotated[float, typer.Option(help="Sample rate of px4/csv/json, Hz.")] = 100.0,
) -> None:
    """Export the planned trajectories of PLAN; read them back; report to <out>.summary.json."""
    with user_errors():
        if format not in EXPORTERS:
            raise InputError(f"--format: got {format!r}, expected one of {', '.join(EXPORTERS)}")
        chosen = EXPORTERS[format]
        options = ExportOptions(rate_hz=positive_rate(rate))
        plans = read_plan(plan)
        out.parent.mkdir(parents=True, exist_ok=True)
        with console.status(f"exporting {len(plans)} trajectory(ies) to {format}"):
            report = chosen(plans, out, options)
        summary = report.as_dict() | {"plan": str(plan), "drones": [name for name, _ in plans]}
        write_json(out.with_name(f"{out.stem}.summary.json"), summary)
    console.print(
        f"[green]done[/] {report.message} (read back: within {1e3 * report.max_error_m:.3g} mm)",
        highlight=False,
    )
