"""``skyquill render``: the long exposure and the animated preview of a plan, from any view."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer

from skyquill.cli.main import Force, app, check_out, console, parse_color, say_done, user_errors
from skyquill.errors import InputError
from skyquill.io.atomic import write_json
from skyquill.io.outputs import staged_output
from skyquill.io.plan_dir import read_plan


@app.command()
def render(
    paths: Annotated[
        list[Path],
        typer.Argument(
            metavar="PATH...",
            help="Plan directories or trajectory .json files (with their light windows); all "
            "together are one show on one clock.",
        ),
    ],
    out: Annotated[Path, typer.Option("--out", help="Output directory (created).")],
    azimuth: Annotated[
        float,
        typer.Option(help="Direction to the camera, degrees counter-clockwise from +x (-90: -y)."),
    ] = -90.0,
    elevation: Annotated[
        float, typer.Option(help="Camera height above the show's horizon, degrees.")
    ] = 10.0,
    fov: Annotated[float, typer.Option(help="Horizontal field of view, degrees.")] = 50.0,
    trail: Annotated[
        float,
        typer.Option(help="Seconds a light's trail stays in the preview (inf: the whole show)."),
    ] = 1.0,
    light: Annotated[
        str,
        typer.Option(
            metavar="R,G,B|#RRGGBB", help="Colour of light windows whose plan has no colours."
        ),
    ] = "255,255,255",
    force: Force = False,
) -> None:
    """Write long_exposure.png (the shutter open for the whole show) and preview.gif."""
    from skyquill.viz.light_painting import View, write_pictures

    with user_errors():
        check_out(out)
        if not paths:
            raise InputError("PATH: got none, expected a plan directory or a trajectory .json")
        if not -360.0 <= azimuth <= 360.0:  # NaN fails too
            raise InputError(f"--azimuth: got {azimuth:g}, expected -360 to 360 degrees")
        if math.isnan(trail) or trail < 0:
            raise InputError(f"--trail: got {trail:g}, expected a number of seconds >= 0 or inf")
        view = View(azimuth, elevation, fov)
        rgb = parse_color("--light", light)
        drones = [planned for path in paths for _, planned in read_plan(path)]
        with (
            console.status(f"rendering {len(drones)} drone(s)"),
            staged_output(out, "render", force=force, inputs=paths) as stage,
        ):
            pictures = write_pictures(drones, stage, view, rgb, trail_s=trail)
            write_json(stage / "summary.json", pictures | {"drones": len(drones)})
    say_done(
        f"{out}: long_exposure.png ({pictures['lit_windows']} light stroke(s), "
        f"{pictures['lit_length_m']:.1f} m lit) and preview.gif ({pictures['preview_frames']} "
        "frames)"
    )
