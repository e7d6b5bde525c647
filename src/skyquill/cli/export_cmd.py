"""``skyquill export``: a planned trajectory (``fit``/``write`` output) to a drone's format."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Annotated, Any

import typer

from skyquill.cli.main import app, console, positive_rate, user_errors
from skyquill.errors import InputError
from skyquill.io.atomic import write_json
from skyquill.io.points import write_trajectory_csv
from skyquill.io.spline_json import read_spline_json
from skyquill.trajectory import SplineTrajectory

FORMATS = ("crazyswarm", "skyc", "px4", "csv", "json")


def find_trajectories(directory: Path) -> list[tuple[str, SplineTrajectory]]:
    """``trajectory.json`` or ``trajectory_<i>.json`` of a ``fit``/``write`` output, in order."""
    if not directory.is_dir():
        raise InputError(f"DIR: got {str(directory)!r}, expected an output directory of fit/write")
    single = directory / "trajectory.json"
    numbered = sorted(
        (
            p
            for p in directory.glob("trajectory_*.json")
            if re.fullmatch(r"trajectory_\d+\.json", p.name)
        ),
        key=lambda p: int(p.stem.split("_")[1]),
    )
    files = [single] if single.is_file() else numbered
    if not files:
        raise InputError(
            f"DIR: got {str(directory)!r} without trajectory.json or trajectory_<i>.json, "
            "expected the output directory of `skyquill fit` or `skyquill write`"
        )
    return [(f.stem, read_spline_json(f)) for f in files]


def _target(out: Path, name: str, several: bool, suffix: str) -> Path:
    return out.with_name(f"{out.stem}_{name}{suffix}") if several else out.with_suffix(suffix)


@app.command()
def export(
    directory: Annotated[Path, typer.Argument(metavar="DIR", help="Output of fit or write.")],
    out: Annotated[Path, typer.Option("--out", help="File to write (one per drone if several).")],
    format: Annotated[str, typer.Option(help="crazyswarm, skyc, px4, csv or json.")] = "csv",
    rate: Annotated[float, typer.Option(help="Sample rate of px4/csv/json, Hz.")] = 100.0,
) -> None:
    """Export the planned trajectories of DIR; a summary goes to <out>.summary.json."""
    with user_errors():
        if format not in FORMATS:
            raise InputError(f"--format: got {format!r}, expected one of {', '.join(FORMATS)}")
        rate = positive_rate(rate)
        trajectories = find_trajectories(directory)
        out.parent.mkdir(parents=True, exist_ok=True)
        summary = _export(trajectories, out, format, rate)
        write_json(out.with_name(f"{out.stem}.summary.json"), summary)
    console.print(f"[green]done[/] {summary['message']}", highlight=False)


def _export(
    trajectories: list[tuple[str, SplineTrajectory]], out: Path, fmt: str, rate: float
) -> dict[str, Any]:
    several = len(trajectories) > 1
    files: list[str] = []
    notes: list[str] = []
    if fmt == "skyc":
        from skyquill.io.skyc import write_skyc

        show = write_skyc([t for _, t in trajectories], out.with_suffix(".skyc"))
        return {
            "format": fmt,
            "files": [str(show.path)],
            "max_error_m": show.max_error_m,
            "exact": show.exact,
            "message": show.message,
        }
    for name, traj in trajectories:
        if fmt == "crazyswarm":
            from skyquill.io.crazyswarm import write_crazyswarm

            result = write_crazyswarm(traj, _target(out, name, several, ".csv"))
            files += [str(f) for f in result.files]
            notes.append(result.message)
        elif fmt == "px4":
            from skyquill.io.px4 import px4_setpoints

            path = _target(out, name, several, ".csv")
            px4_setpoints(traj, rate_hz=rate).to_csv(path)
            files.append(str(path))
        elif fmt == "csv":
            path = _target(out, name, several, ".csv")
            write_trajectory_csv(path, traj, rate)
            files.append(str(path))
        else:
            from skyquill.io.setpoints_json import write_setpoints_json

            path = _target(out, name, several, ".json")
            write_setpoints_json(traj, path, rate)
            files.append(str(path))
    message = "; ".join(notes) if notes else f"wrote {len(files)} {fmt} file(s): {', '.join(files)}"
    return {"format": fmt, "files": files, "rate_hz": rate, "message": message}
