"""``skyquill show SHOW.toml --out DIR``: plan a show script, prove it, write it and its .skyc."""

from __future__ import annotations

import gc
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path
from typing import Annotated, Any

import typer

from skyquill.cli.main import (
    Force,
    MinAltitude,
    OutDir,
    app,
    check_out,
    console,
    min_altitude,
    say_done,
    scheduler_address,
    stage_progress,
    user_errors,
    worker_count,
)
from skyquill.cli.pictures import NoPictures, Pictures
from skyquill.errors import InfeasibleError
from skyquill.io.atomic import write_json
from skyquill.io.outputs import staged_output
from skyquill.io.plan_dir import trajectory_names, with_phases, write_plan
from skyquill.io.points import check_rows_written
from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.parallel import Where
from skyquill.phases import MIN_ALTITUDE_M
from skyquill.show import ShowDrone, ShowLimits, ShowReport, check_show
from skyquill.show.build import ShowPlan, build_show
from skyquill.show.load import skyc_drones
from skyquill.show.script import ShowScript, load_script

#: Relative round-off allowed over the planned limits in the independent check
#: (Ruckig's profiles touch the limits exactly; the writing QP holds them to its tolerance).
CHECK_ROUND_OFF = 1e-6


@app.command()
def show(
    script: Annotated[Path, typer.Argument(metavar="SHOW", help="Show script (TOML).")],
    out: OutDir,
    workers: Annotated[
        int | None,
        typer.Option(
            help="Processes planning the writing, making the .skyc and Skybrush CSV and writing "
            "the files (default: CPUs)."
        ),
    ] = None,
    scheduler: Annotated[
        str | None,
        typer.Option(
            help="dask.distributed scheduler address (or 'local') for the writing, the .skyc "
            "and the Skybrush CSV."
        ),
    ] = None,
    min_altitude_m: MinAltitude = MIN_ALTITUDE_M,
    force: Force = False,
    no_pictures: NoPictures = False,
) -> None:
    """Plan a show script: formations, transitions, writing, take-off and landing.

    Every show written passes `skyquill check` at the script's safety distance
    and limits; one that does not is refused. Writes trajectory_<i>.csv/json,
    summary.json and show.skyc into --out.
    """
    with user_errors():
        check_out(out)
        floor = min_altitude(min_altitude_m)
        workers = worker_count(workers)
        scheduler = scheduler_address(scheduler)
        show_script = load_script(script)
        stages: dict[str, float] = {}
        plan = _plan(show_script, workers, scheduler)
        with _out_of_collectors_sight():
            clock = time.perf_counter()
            with console.status(f"checking {len(plan.drones)} drones"):
                report = _check(plan, show_script)
            stages["check"] = time.perf_counter() - clock
            with staged_output(out, "show", force=force, inputs=[script]) as stage:
                drawn = Pictures(not no_pictures)
                where = Where(workers, scheduler)
                summary = _write(stage, plan, show_script, report, stages, drawn, floor, where)
    say_done(
        f"{out}: {summary['drones']} drones, {summary['duration_s']:.1f} s, no two closer than "
        f"{summary['min_separation_m']['guaranteed']:.3f} m (guaranteed; "
        f"{show_script.safety_m:g} m asked); show.skyc as Skybrush plays it: "
        f"{summary['skyc']['as_played']['verdict']} (skyc.as_played in summary.json), in "
        f"{sum(summary['planning_time_s'].values()):.1f} s"
    )


@contextmanager
def _out_of_collectors_sight() -> Iterator[None]:
    """The objects alive now (the plan) frozen out of the cyclic garbage collector's sight
    while the plan is checked and its files are written, unfrozen after.

    They live to the end of the command anyway, and the exports allocate millions of small
    objects (keyframe lists, JSON, CSV rows), each full collection walking every object
    alive again; frozen, they are not walked (nor copied on write by the worker processes
    a collection would otherwise touch them in). 400 drones' ``.skyc``: 1.2 -> 0.5 s of
    collection.
    """
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


def _plan(script: ShowScript, workers: int | None, scheduler: str | None) -> ShowPlan:
    with stage_progress() as progress:
        return build_show(script, workers=workers, scheduler=scheduler, progress=progress)


def check_limits(script: ShowScript) -> ShowLimits:
    """What the independent check holds every drone to: the script's limits (norms)."""
    lim = script.limits
    assert lim.vmax is not None and lim.amax is not None
    speed = lim.vmax * (1.0 + CHECK_ROUND_OFF)
    return ShowLimits(
        max_speed_xy=speed,
        max_speed_up=speed,
        max_speed_down=speed,
        max_acceleration=lim.amax * (1.0 + CHECK_ROUND_OFF),
        min_altitude=None,
        max_altitude=120.0,
        geofence=script.geofence,
    )


def _named(plan: ShowPlan) -> list[tuple[str, PlannedTrajectory]]:
    """Each drone with the name of its files (``trajectory_<i>``)."""
    names = [csv.removesuffix(".csv") for csv, _ in trajectory_names(len(plan.drones))]
    return list(zip(names, plan.drones, strict=True))


def _check(plan: ShowPlan, script: ShowScript) -> ShowReport:
    """``skyquill check`` on the plan; refused (InfeasibleError) unless it passes."""
    drones = [ShowDrone(d.trajectory, n) for n, d in _named(plan)]
    report = check_show(drones, script.safety_m, check_limits(script))
    if not report.passed:
        v = report.violations[0]
        raise InfeasibleError(
            f"show: the check refuses the plan: {v.check} of {', '.join(v.drones)} at "
            f"t = {v.first_time_s:.2f} s is {v.worst:.4g}, expected within {v.limit:g}",
            (v.check,),
        )
    return report


def _write(
    stage: Path,
    plan: ShowPlan,
    script: ShowScript,
    report: ShowReport,
    stages: dict[str, float],
    drawn: Pictures,
    min_altitude_m: float,
    where: Where,
) -> dict[str, Any]:
    from skyquill.viz.light_painting import write_pictures

    # Each flight's phases found once, at the floor asked for: the exports and the plan
    # files all use them (as `skyquill export` reads them back from trajectory.json).
    clock = time.perf_counter()
    plan = replace(plan, drones=tuple(with_phases(d, min_altitude_m) for d in plan.drones))
    stages["phases"] = time.perf_counter() - clock
    plans = _named(plan)
    names = [name for name, _ in plans]
    clock = time.perf_counter()
    skyc = _skyc(stage, plans, script, where)
    stages["skyc"] = time.perf_counter() - clock
    clock = time.perf_counter()
    studio = _studio_csv(stage, plans, script, where)
    stages["skybrush_csv"] = time.perf_counter() - clock
    if drawn.drawn:
        with drawn.timing("long_exposure.png", "preview.gif"):
            drawn.entry |= write_pictures(plan.drones, stage)
    stages["pictures"] = drawn.entry["time_s"]
    sep = report.separation
    summary = {
        "command": "show",
        "drones": len(plan.drones),
        "duration_s": plan.duration_s,
        "safety_distance_m": script.safety_m,
        "min_separation_m": {
            "requested": script.safety_m,
            "guaranteed": sep.lower_bound_m,
            "attained": sep.attained_m,
            "between": [names[k] for k in sep.attained_drones],
            "at_s": sep.attained_time_s,
        },
        "check": report.as_dict(),
        "planning_time_s": plan.stage_times_s | stages,
        "scenes": list(plan.scenes),
        "homes_m": plan.homes.tolist(),
        "lights": [
            {
                "drone": n,
                "windows_s": [list(w) for w in d.pen_windows_s],
                "rgb": [list(c) for c in d.pen_rgb],
            }
            for n, d in plans
        ],
        "skyc": skyc,
        "skybrush_csv": studio,
        "pictures": drawn.entry,
    }
    clock = time.perf_counter()
    for drone in plan.drones:  # the script's rate, named as written there (show has no --rate)
        check_rows_written(drone.trajectory.duration, script.rate_hz, "[show].rate")
    full = write_plan(
        stage,
        plan.drones,
        rate=script.rate_hz,
        guaranteed=True,
        summary=summary,
        min_altitude_m=min_altitude_m,
        workers=where.workers,  # the files are written here, never on a remote cluster
    )
    full["planning_time_s"]["files"] = time.perf_counter() - clock
    write_json(stage / "summary.json", full)
    return full


def _studio_csv(
    stage: Path, plans: list[tuple[str, PlannedTrajectory]], script: ShowScript, where: Where
) -> dict[str, Any]:
    """Write ``show.zip``, Skybrush Studio's per-drone CSVs, read back as Studio reads them."""
    from skyquill.export.base import ExportOptions
    from skyquill.export.skybrush.csv_exporter import SkybrushCsvExporter

    exporter = SkybrushCsvExporter(workers=where.workers, scheduler=where.scheduler)
    exported = exporter(plans, stage / "show", ExportOptions(script.rate_hz))
    return {
        "file": "show.zip",
        "max_error_m": exported.max_error_m,
        "lights_exact_to_ms": exported.details["lights_exact_to_ms"],
        "rows": exported.details["rows"],
    }


def _skyc(
    stage: Path, plans: list[tuple[str, PlannedTrajectory]], script: ShowScript, where: Where
) -> dict[str, Any]:
    """Write ``show.skyc``, load it back as the drones play it and check it again.

    Skybrush stores whole millimetres and milliseconds. The exporter already keeps every
    drone's played speed and acceleration within 1 % of the script's limits and its jerk
    within 5 % (refitting, or refusing). Here the whole show as played goes through
    ``skyquill check`` again: its guaranteed separation against the safety distance less
    twice the export's ``max_error_m`` (two drones, each up to that far from its plan), its
    speeds and acceleration against the script's limits with that 1 % (``--tolerance
    0.01``); a show that fails either is refused.
    """
    from skyquill.export.base import ALLOWED_EXCESS, ExportOptions
    from skyquill.export.skybrush.skyc_exporter import SkycExporter

    exporter = SkycExporter(workers=where.workers, scheduler=where.scheduler)
    exported, show_json = exporter.export(plans, stage / "show", ExportOptions())
    # as `skyquill check show.skyc` loads it, from the show.json the exporter read back
    played = skyc_drones(show_json, "show.skyc")
    allowed = max(0.0, script.safety_m - 2.0 * exported.max_error_m)
    limits = replace(check_limits(script), tolerance=ALLOWED_EXCESS[2])
    back = check_show(played, allowed, limits)
    if not back.passed:
        v = back.violations[0]
        raise InfeasibleError(
            f"show.skyc: as Skybrush plays it, {v.check} of {', '.join(v.drones)} at "
            f"t = {v.first_time_s:.2f} s is {v.worst:.4g}, expected within {v.limit:.4g}"
            + (" (1 % allowed over the limits)" if v.check != "separation" else ""),
            (v.check,),
        )
    return {
        "file": "show.skyc",
        "message": exported.message,
        "details": exported.details,
        "as_played": exported.as_played.as_dict(),
        "played_back": {
            "guaranteed_separation_m": back.separation.lower_bound_m,
            "checked_against_m": allowed,
            "tolerance": limits.tolerance,
            "check": back.as_dict(),
        },
    }
