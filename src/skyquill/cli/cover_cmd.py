"""``skyquill cover``: plan a coverage flight of a region (paper 001)."""

from __future__ import annotations

from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING, Annotated, Any

import typer

from skyquill.cli.main import (
    Force,
    MinAltitude,
    OutDir,
    Target,
    Vmax,
    app,
    check_out,
    console,
    in_range,
    min_altitude,
    positive_rate,
    progress_bar,
    say_done,
    scheduler_address,
    upload_target,
    user_errors,
    worker_count,
)
from skyquill.cli.pictures import NoPictures, Pictures
from skyquill.coverage import DEFAULT_MIN_COVERAGE
from skyquill.errors import InputError
from skyquill.limits import VehicleLimits
from skyquill.parallel import Where
from skyquill.phases import MIN_ALTITUDE_M, check_altitude
from skyquill.viz.worker import Drawing

if TYPE_CHECKING:
    from rich.progress import Progress, TaskID

    from skyquill.coverage.geo import GeoFrame
    from skyquill.coverage.plan import CoveragePlan
    from skyquill.io.trajectory_json import PlannedTrajectory

#: The bar is drawn only for planning that takes longer than this, s.
BAR_AFTER_S = 1.0
#: ``--altitude``, m above the ground: a coverage flight stays under the 120 m ceiling of
#: open-category drone rules (EU 2019/947, FAA part 107's 400 ft).
ALTITUDE_RANGE_M = (0.0, 120.0)
#: ``--origin-alt``, m above mean sea level: the shore of the Dead Sea (-430 m) to the
#: summit of Everest (8849 m), with a margin.
ORIGIN_ALT_RANGE_M = (-500.0, 9000.0)
#: ``--delta``, m: a corner control point farther than 100 m is no corner of a field.
DELTA_RANGE_M = (0.0, 100.0)
#: ``--time-limit``, s: the planning budget, an hour at most.
TIME_LIMIT_RANGE_S = (0.0, 3600.0)


@app.command()
def cover(
    region: Annotated[
        Path,
        typer.Argument(
            help="Region: GeoJSON (Multi)Polygon/Feature (WGS84 lon/lat by RFC 7946, or the "
            "CRS its crs member names), or a .wkt file (local metres); holes are keep-out zones."
        ),
    ],
    out: OutDir,
    width: Annotated[float, typer.Option(help="Coverage diameter (swath), m.")] = 2.0,
    vmax: Vmax = 3.0,
    amax: Annotated[
        float | None,
        typer.Option(help="Acceleration limit: its norm, m/s^2 (default 5, or --amax-axis)."),
    ] = None,
    jmax: Annotated[
        float | None,
        typer.Option(help="Jerk limit: its norm, m/s^3 (default 3, or --jmax-axis)."),
    ] = None,
    amax_axis: Annotated[
        float | None,
        typer.Option(help="Per-axis acceleration limit instead of the norm (paper 001), m/s^2."),
    ] = None,
    jmax_axis: Annotated[
        float | None,
        typer.Option(help="Per-axis jerk limit instead of the norm (paper 001), m/s^3."),
    ] = None,
    pattern: Annotated[
        str,
        typer.Option(
            help="spiral, zigzag, zigzag-stop or zigzag-jerk (turns time-optimal for the jerk "
            "limit: the fastest on convex fields)."
        ),
    ] = "spiral",
    contours: Annotated[str, typer.Option(help="Spiral rings: offset or homothetic.")] = "offset",
    drift: Annotated[str, typer.Option(help="Spiral laps: step or lap (paper eq. 4).")] = "step",
    delta: Annotated[float, typer.Option(help="Corner control-point distance, m.")] = 0.5,
    epsilon: Annotated[float, typer.Option(help="Density: spacing = epsilon * width.")] = 1.0,
    perimeter: Annotated[
        bool, typer.Option(help="Zigzags: a lap around the region first.")
    ] = False,
    min_coverage: Annotated[
        float,
        typer.Option(
            help="Cover at least this fraction of the region: epsilon and delta are picked for "
            "the fastest flight that does (ask for less to fly faster); 0 flies --epsilon and "
            "--delta as given."
        ),
    ] = DEFAULT_MIN_COVERAGE,
    rate: Annotated[float, typer.Option(help="Setpoint rate, Hz.")] = 50.0,
    altitude: Annotated[
        float, typer.Option(help="Flight height above the ground, m (--min-altitude to 120).")
    ] = 2.0,
    time_limit: Annotated[
        float,
        typer.Option(
            help="Planning budget, s: the plan ends within it or stops with an error naming "
            "the step it was at; a budget below the estimate is refused at once."
        ),
    ] = 60.0,
    crs: Annotated[
        str | None,
        typer.Option(
            help="The region's CRS: wgs84, local (metres, x east, y north) or one pyproj knows "
            "(e.g. EPSG:32633). Default: what the file says (GeoJSON: WGS84 unless it has a "
            "crs member; WKT: local)."
        ),
    ] = None,
    origin_alt: Annotated[
        float | None,
        typer.Option(
            help="Ground altitude at the field's centre above mean sea level, m: recorded "
            "with the origin (Skybrush's show origin carries it)."
        ),
    ] = None,
    target: Target = None,
    workers: Annotated[
        int | None,
        typer.Option(
            help="Processes planning the pieces of a field with keep-outs (or of several "
            "fields) at once (default: CPUs; 1: one after the other)."
        ),
    ] = None,
    scheduler: Annotated[
        str | None,
        typer.Option(help="dask.distributed scheduler address (or 'local') planning the pieces."),
    ] = None,
    min_altitude_m: MinAltitude = MIN_ALTITUDE_M,
    force: Force = False,
    no_pictures: NoPictures = False,
) -> None:
    """Plan a coverage flight of REGION; write summary.json, trajectory.csv and plot.png.

    With --target the planned path is re-fitted into the vehicle's uploads (degree-7
    pieces, within 5 % of the swath of the path, hovering between uploads).

    A geographic region is planned in a local metric frame centred on it;
    summary.json records its origin and CRS, and path.geojson holds the flown
    path and the covered area in lon/lat.
    """
    from skyquill.coverage.geo import load_geo_region
    from skyquill.coverage.plan import (
        CoverageOptions,
        coverage_limits,
        plan_coverage,
        plan_tuned,
    )
    from skyquill.coverage.plan.checks import check_region, least_flight_s
    from skyquill.coverage.plan.tuning import check_tuned_region
    from skyquill.io.outputs import staged_output
    from skyquill.io.plan_dir import write_plan
    from skyquill.io.points import check_rows_written
    from skyquill.io.trajectory_json import PlannedTrajectory

    with user_errors():
        check_out(out)
        floor = min_altitude(min_altitude_m)
        _check_heights(altitude, origin_alt)
        altitude = check_altitude("--altitude", altitude, floor)
        rate = positive_rate(rate)
        in_range("--delta", delta, *DELTA_RANGE_M, "m", open_low=True)
        in_range("--time-limit", time_limit, *TIME_LIMIT_RANGE_S, "s", open_low=True)
        where = Where(worker_count(workers), scheduler_address(scheduler))
        geo = load_geo_region(region, crs, origin_alt)
        shape = geo.region
        options = CoverageOptions(
            width=width,
            limits=_limits(vmax, amax, jmax, amax_axis, jmax_axis),
            pattern=pattern,  # type: ignore[arg-type]  # checked by CoverageOptions
            contours=contours,  # type: ignore[arg-type]
            drift=drift,  # type: ignore[arg-type]
            epsilon=epsilon,
            perimeter=perimeter,
            delta=delta,
            rate=rate,
            altitude=altitude,
            target=upload_target(target),
            time_limit=time_limit,
        )
        if not 0.0 <= min_coverage <= 1.0:  # NaN fails too
            raise InputError(
                f"--min-coverage: got {min_coverage:g}, expected 0 (fly --epsilon/--delta as "
                "given) or a fraction in (0, 1]"
            )
        # Refused before planning: the region, then trajectory.csv's rows over the shortest
        # flight that covers enough.
        if min_coverage == 0.0:
            check_region(shape, options)
        else:
            check_tuned_region(shape, options)
        least = least_flight_s(shape, options, min_coverage)
        check_rows_written(least, rate, "--rate", at_least=True)
        with _BudgetBar() as bar:
            if min_coverage == 0.0:
                plan = plan_coverage(shape, options, progress=bar.update, where=where)
            else:
                plan = plan_tuned(shape, options, min_coverage, progress=bar.update, where=where)
        # The spray is on along the whole path, or (holes, several fields) off on the
        # transits and wherever the swath would reach into a hole.
        planned = PlannedTrajectory(
            plan.trajectory, plan.pen_windows_s, coverage_limits(plan.options)
        )
        with (
            console.status("writing and checking the plan"),
            staged_output(out, "cover", force=force, inputs=[region]) as stage,
        ):
            drawn = Pictures(not no_pictures)
            fields = (
                plan.summary()
                | {"region": str(region), "min_coverage": min_coverage or None}
                | geo.summary()
                | {"pictures": drawn.entry}
            )
            if geo.frame is not None:
                fields["path_geojson"] = _write_geojson(stage, geo.frame, plan, planned)
            summary = write_plan(
                stage,
                [planned],
                rate=rate,
                # The refit for a target holds the limits through the hull; the LP does not.
                guaranteed=plan.delivered is not None,
                summary=fields,
                plot=drawn.sampled(lambda: _coverage_drawing(plan)),
                min_altitude_m=floor,
            )
    uploads = "" if plan.delivered is None else f", {len(plan.delivered.budget.uploads)} upload(s)"
    say_done(
        f"{plan.options.pattern}: {plan.duration:.2f} s, {plan.path_length:.1f} m{uploads}, "
        f"coverage {plan.coverage:.4f}, max excess {summary['plan']['max_excess']:.4f}, "
        f"planned in {plan.planning_time:.2f} s -> {out}"
    )


def _coverage_drawing(plan: CoveragePlan) -> Drawing:
    """``plot.png``: matplotlib is imported where it is drawn (the picture worker, or here),
    only when drawn, inside the pictures' time (:class:`~skyquill.cli.pictures.Pictures`)."""
    from skyquill.viz.sampled import sample_coverage

    return Drawing("skyquill.viz.coverage_plot", "draw_coverage", sample_coverage(plan))


def _write_geojson(
    stage: Path, frame: GeoFrame, plan: CoveragePlan, planned: PlannedTrajectory
) -> dict[str, Any]:
    """``path.geojson`` (flown path and covered area in lon/lat), read back and checked."""
    from skyquill.export.geojson import write_path_geojson

    covered = plan.region.intersection(plan.sprayed)
    check = write_path_geojson(stage / "path.geojson", frame, planned, covered, plan.region)
    return {"file": "path.geojson"} | check.as_dict()


def _check_heights(altitude: float, origin_alt: float | None) -> None:
    """``--altitude`` and ``--origin-alt`` within their ranges (NaN fails too)."""
    low, high = ALTITUDE_RANGE_M
    if not low < altitude <= high:
        raise InputError(
            f"--altitude: got {altitude:g}, expected a height above the ground, more than "
            f"{low:g} and at most {high:g} m"
        )
    low, high = ORIGIN_ALT_RANGE_M
    if origin_alt is not None and not low <= origin_alt <= high:
        raise InputError(
            f"--origin-alt: got {origin_alt:g}, expected {low:g} to {high:g} m above mean sea level"
        )


def _limits(
    vmax: float,
    amax: float | None,
    jmax: float | None,
    amax_axis: float | None,
    jmax_axis: float | None,
) -> VehicleLimits:
    """Norms by default (5 m/s^2, 3 m/s^3); per axis when ``--amax-axis/--jmax-axis`` are given."""
    per_axis = amax_axis is not None or jmax_axis is not None
    if per_axis and (amax is not None or jmax is not None):
        raise InputError(
            "--amax/--jmax and --amax-axis/--jmax-axis: got both, expected the norms or the "
            "per-axis limits"
        )
    if per_axis:
        return VehicleLimits(vmax=vmax, amax_axis=amax_axis, jmax_axis=jmax_axis)
    return VehicleLimits(vmax, 5.0 if amax is None else amax, 3.0 if jmax is None else jmax)


class _BudgetBar:
    """A rich bar of the planning budget spent, labelled with the current step.

    Drawn on the CLI's console (stderr) once planning has taken
    :data:`BAR_AFTER_S`: a plan of a small region ends before it would flicker.
    """

    def __init__(self) -> None:
        self._bar: Progress | None = None
        self._task: TaskID | None = None

    def __enter__(self) -> _BudgetBar:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        value: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        if self._bar is not None:
            self._bar.stop()

    def update(self, step: str, elapsed_s: float, limit_s: float) -> None:
        """``progress`` of :func:`~skyquill.coverage.plan.plan_coverage`."""
        if self._bar is None:
            if elapsed_s < BAR_AFTER_S:
                return
            self._bar = _progress()
            self._task = self._bar.add_task(step, total=limit_s)
            self._bar.start()
        assert self._task is not None  # added with the bar
        self._bar.update(self._task, description=step, completed=min(elapsed_s, limit_s))


def _progress() -> Progress:
    """Step, and the budget spent (moved at every step: each LP solve, each check)."""
    from rich.progress import BarColumn, TextColumn

    return progress_bar(
        TextColumn("planning: {task.description}"),
        BarColumn(),
        TextColumn("{task.completed:.0f} s of the {task.total:.0f} s time limit"),
    )
