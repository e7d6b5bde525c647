"""``skyquill reproduce corridor|segments``: the papers' experiments."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from skyquill.cli.boundary import OneLineGroup
from skyquill.cli.main import (
    EXAMPLES,
    Force,
    OutDir,
    app,
    check_out,
    console,
    progress_bar,
    say_done,
    user_errors,
)
from skyquill.io.outputs import staged_output

reproduce_app = typer.Typer(
    cls=OneLineGroup, no_args_is_help=True, help="Reproduce the papers' experiments."
)
app.add_typer(reproduce_app, name="reproduce")


@reproduce_app.command("corridor")
def reproduce_corridor(
    out: OutDir = Path("out/corridor"),
    corridor: Annotated[Path, typer.Option(help="Box corridor JSON.")] = EXAMPLES
    / "s_corridor.json",
    force: Force = False,
) -> None:
    """Paper 003 §5.4 (Fig. 10): coupled vs decoupled limits in a 7-box S corridor."""
    from skyquill.reproduce.corridor import run_corridor_study

    with user_errors():
        check_out(out)
    with (
        user_errors(),
        progress_bar() as progress,
        staged_output(out, "reproduce corridor", force=force, inputs=[corridor]) as stage,
    ):
        task = progress.add_task("control-point counts", total=None)
        summary = run_corridor_study(
            corridor,
            stage,
            on_step=lambda done, total: progress.update(task, completed=done, total=total),
        )
    say_done(f"{out}: " + _claims(summary))


@reproduce_app.command("segments")
def reproduce_segments(
    out: OutDir = Path("out/segments"),
    segments: Annotated[Path, typer.Option(help="Waypoint CSV (x,y,z).")] = EXAMPLES
    / "segments.csv",
    force: Force = False,
) -> None:
    """Paper 003 §5.2 (Fig. 7): line-segment plan, min-snap peer vs our segment fit."""
    from skyquill.reproduce.segments import run_segment_study

    with user_errors():
        check_out(out)
    with (
        user_errors(),
        console.status("flying the line-segment plan three ways"),
        staged_output(out, "reproduce segments", force=force, inputs=[segments]) as stage,
    ):
        run_segment_study(segments, stage)
    say_done(f"{out}/summary.json")


def _claims(summary: dict[str, Any]) -> str:
    """``claim: reproduced`` for each of the paper's claims in a study summary."""
    return ", ".join(
        f"{name}: {'reproduced' if claim.get('reproduced') else 'NOT reproduced'}"
        for name, claim in summary.get("claims", {}).items()
    )
