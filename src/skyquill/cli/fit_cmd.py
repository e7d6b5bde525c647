"""``skyquill fit`` and ``skyquill demo``: fit points, write trajectory.csv, plot, summary."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.markup import escape

from skyquill.cli.main import (
    Altitude,
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
    positive_rate,
    say_done,
    upload_target,
    user_errors,
)
from skyquill.cli.pictures import NoPictures, Pictures
from skyquill.errors import InputError
from skyquill.io.outputs import staged_output
from skyquill.io.plan_dir import write_plan
from skyquill.io.points import read_points_csv
from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.limits import VehicleLimits, lifted_limits
from skyquill.optimize.budget import lifted
from skyquill.optimize.fit import FitOptions, PointFit, fit_points
from skyquill.phases import DEFAULT_ALTITUDE_M, MIN_ALTITUDE_M, check_altitude
from skyquill.validation import FloatArray
from skyquill.viz.sampled import sample_fit
from skyquill.viz.worker import Drawing

#: ``--weight`` of the point deviation: beyond 1e9 the solver's conditioning, not the fit,
#: decides (1e300 did not end).
WEIGHT_RANGE = (0.0, 1e9)
#: ``--tolerance``, m: more than a kilometre from the points is no fit of them.
TOLERANCE_RANGE_M = (0.0, 1000.0)


def fit_summary(fit: PointFit, options: FitOptions, rate: float) -> dict[str, Any]:
    """The ``summary.json`` of a fit (SI units).

    With a target split into uploads, solve time, cost and control points
    add up over the uploads' fits, and ``"target"`` lists the uploads.
    """
    r, check = fit.result, fit.verification
    fits = [c.result for c in fit.budget.chunks] if fit.budget is not None else [r]
    summary = {
        "duration_s": fit.trajectory.duration,
        "solve_time_s": sum(f.solve_time_s for f in fits),
        "cost": sum(f.cost for f in fits),
        "cost_terms": {key: sum(f.cost_terms[key] for f in fits) for key in r.cost_terms},
        "max_speed": check.max_speed,
        "max_acc": list(check.max_acc),
        "max_jerk": list(check.max_jerk),
        "max_excess": check.max_excess,
        "rms_deviation_m": fit.rms_deviation_m,
        "max_deviation_m": fit.max_deviation_m,
        "status": r.status,
        "method": r.method,
        "solver": r.solver,
        "time_scale": fit.time_scale,
        "degree": r.trajectory.degree,
        "n_control_points": sum(int(f.trajectory.control_points.shape[0]) for f in fits),
        "n_points": int(fit.points.shape[0]),
        "rate_hz": rate,
        "limits": check.limits_report(),
        "vehicle_limits": options.limits.as_dict(),
        "norms_held_by": "second-order cones (exact)"
        if options.norm_sides is None
        else f"inscribed polytope of {options.norm_sides} sides",
        "dense_samples": check.n_samples,
    }
    return summary if fit.budget is None else summary | {"target": fit.budget.summary()}


@dataclass(frozen=True)
class Flight:
    """Where a fit is flown: a 2-D input's altitude (``None`` for 3-D), the minimum altitude."""

    altitude_m: float | None = DEFAULT_ALTITUDE_M
    min_altitude_m: float = MIN_ALTITUDE_M


def run_fit(
    points: FloatArray,
    times: FloatArray | None,
    options: FitOptions,
    out: Path,
    rate: float,
    source: Path,
    force: bool = False,
    flight: Flight | None = None,
    pictures: bool = True,
) -> dict[str, Any]:
    """Fit the points of ``source``, then write the plan directory ``out``.

    2-D points are fitted in the plane and flown at ``flight.altitude_m``; 3-D ones as
    they are. Either way the mission keeps ``flight.min_altitude_m`` (else refused).
    ``pictures``: draw ``plot.png`` (``--no-pictures`` skips it).
    """
    flight = flight or Flight()
    title = source.stem
    with console.status(f"fitting {points.shape[0]} points ({escape(title)})"):
        fit = fit_points(points, times, options)
    flat = fit.trajectory.dim == 2
    altitude = flight.altitude_m if flat and flight.altitude_m is not None else 0.0
    planned = PlannedTrajectory(
        lifted(fit.trajectory, altitude),
        limits=lifted_limits(fit.limits) if flat else fit.limits,
    )
    fields = fit_summary(fit, options, rate) | {"altitude_m": altitude if flat else None}
    drawn = Pictures(pictures)
    with (
        console.status("writing and checking the plan"),
        staged_output(out, "fit", force=force, inputs=[source]) as stage,
    ):
        summary = write_plan(
            stage,
            [planned],
            rate=rate,
            guaranteed=True,
            summary=fields | {"pictures": drawn.entry},
            plot=drawn.sampled(lambda: _fit_drawing(fit, title)),
            min_altitude_m=flight.min_altitude_m,
        )
    uploads = "" if fit.budget is None else f", {len(fit.budget.uploads)} upload(s)"
    where = f", flown at {altitude:g} m (--altitude)" if flat else ""
    say_done(
        f"{out}: duration {summary['duration_s']:.2f} s, solve "
        f"{1e3 * summary['solve_time_s']:.1f} ms, max excess {summary['max_excess']:.1e}, "
        f"rms deviation {1e3 * summary['rms_deviation_m']:.2f} mm{uploads}{where}"
    )
    return summary


def _fit_drawing(fit: PointFit, title: str) -> Drawing:
    """``plot.png``: matplotlib is imported where it is drawn, only when drawn, inside the
    pictures' time (:class:`~skyquill.cli.pictures.Pictures`)."""
    return Drawing("skyquill.viz.fit_plot", "draw_fit", sample_fit(fit, title))


@app.command()
def fit(
    points_csv: Annotated[Path, typer.Argument(help="CSV with columns x,y[,z][,t] in m and s.")],
    out: OutDir,
    vmax: Vmax = 1.0,
    amax: Amax = 2.0,
    jmax: Jmax = 10.0,
    vmax_axis: VmaxAxis = None,
    amax_axis: AmaxAxis = None,
    jmax_axis: JmaxAxis = None,
    norm_sides: NormSides = None,
    degree: Annotated[int, typer.Option(help="Spline degree (3 to 7).")] = 5,
    weight: Annotated[float, typer.Option(help="Weight of the point deviation.")] = 1e4,
    rate: Annotated[float, typer.Option(help="Sample rate of trajectory.csv, Hz.")] = 100.0,
    knot_interval: Annotated[float, typer.Option(help="Seconds per knot span.")] = 0.1,
    hull: Annotated[str, typer.Option(help="Limit hull: bspline (papers') or bezier.")] = "bspline",
    solver: Annotated[str, typer.Option(help="QP backend: piqp, clarabel or osqp.")] = "piqp",
    timing: Annotated[
        str | None,
        typer.Option(
            help="given (the CSV's t column), path (along the path, slowing in turns) or "
            "segments (rest to rest at every point). Default: given if there is a t column, "
            "else path."
        ),
    ] = None,
    tolerance: Annotated[
        float | None,
        typer.Option(
            help="Largest distance from the points, m (default 1 % of their extent; 30 % with "
            "--timing given, a tablet's own clock)."
        ),
    ] = None,
    best_effort: Annotated[
        bool, typer.Option(help="Write the fit even if it misses the points by more.")
    ] = False,
    target: Target = None,
    altitude: Altitude = None,
    min_altitude_m: MinAltitude = MIN_ALTITUDE_M,
    force: Force = False,
    no_pictures: NoPictures = False,
) -> None:
    """Fit a smooth trajectory to POINTS_CSV that starts and ends at rest.

    With --target the fit is made of degree-7 pieces (--degree and --knot-interval are
    the target's), split into uploads that hover between them when one upload misses
    the tolerance (untimed points only).
    """
    with user_errors():
        check_out(out)
        in_range("--weight", weight, *WEIGHT_RANGE, "(no unit)")
        if tolerance is not None:
            in_range("--tolerance", tolerance, *TOLERANCE_RANGE_M, "m", open_low=True)
        options = FitOptions(
            limits=VehicleLimits(vmax, amax, jmax, vmax_axis, amax_axis, jmax_axis),
            norm_sides=norm_sides,
            degree=degree,
            weight=weight,
            knot_interval=knot_interval,
            hull=_hull(hull),
            solver=solver,
            timing="segments" if timing == "segments" else "path",
            tolerance_m=tolerance,
            best_effort=best_effort,
            target=upload_target(target),
        )
        points, times = read_points_csv(points_csv)
        if timing not in (None, "given", "path", "segments"):
            raise InputError(f"--timing: got {timing!r}, expected given, path or segments")
        if timing == "given" and times is None:
            raise InputError(f"--timing: got 'given', but {points_csv.name} has no t column")
        if timing in ("path", "segments"):
            times = None
        flight = _flight(points, altitude, min_altitude(min_altitude_m))
        run_fit(
            points,
            times,
            options,
            out,
            positive_rate(rate),
            points_csv,
            force,
            flight,
            not no_pictures,
        )


def _flight(points: FloatArray, altitude: float | None, floor: float) -> Flight:
    """``--altitude`` for 2-D points (default :data:`DEFAULT_ALTITUDE_M`, or the minimum
    altitude when that is higher); refused for 3-D."""
    if points.shape[1] == 3:
        if altitude is not None:
            raise InputError(
                f"--altitude: got {altitude:g} m for 3-D points (x, y, z), expected it only "
                "with 2-D points (x, y): 3-D points are flown at their own z"
            )
        return Flight(None, floor)
    chosen = max(DEFAULT_ALTITUDE_M, floor) if altitude is None else altitude
    return Flight(check_altitude("--altitude", chosen, floor), floor)


def _hull(name: str) -> Any:
    if name not in ("bspline", "bezier"):
        raise InputError(f"--hull: got {name!r}, expected 'bspline' or 'bezier'")
    return name
