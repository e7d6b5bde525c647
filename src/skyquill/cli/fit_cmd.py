"""``skyquill fit`` and ``skyquill demo``: fit points, write trajectory.csv, plot, summary."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer
from rich.markup import escape

from skyquill.cli.main import (
    Amax,
    AmaxAxis,
    Force,
    Jmax,
    JmaxAxis,
    NormSides,
    OutDir,
    Target,
    Vmax,
    VmaxAxis,
    app,
    check_out,
    console,
    in_range,
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
from skyquill.limits import VehicleLimits
from skyquill.optimize.budget import lifted
from skyquill.optimize.fit import FitOptions, PointFit, fit_points
from skyquill.validation import FloatArray

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


def run_fit(
    points: FloatArray,
    times: FloatArray | None,
    options: FitOptions,
    out: Path,
    rate: float,
    source: Path,
    force: bool = False,
    pictures: bool = True,
) -> dict[str, Any]:
    """Fit the points of ``source``, then write the plan directory ``out``.

    ``pictures``: draw ``plot.png`` (``--no-pictures`` skips it).
    """
    from skyquill.viz.fit_plot import plot_fit

    title = source.stem
    with console.status(f"fitting {points.shape[0]} points ({escape(title)})"):
        fit = fit_points(points, times, options)
    drawn = Pictures(pictures)
    with (
        console.status("writing and checking the plan"),
        staged_output(out, "fit", force=force, inputs=[source]) as stage,
    ):
        summary = write_plan(
            stage,
            [PlannedTrajectory(lifted(fit.trajectory, 0.0), limits=fit.limits)],
            rate=rate,
            guaranteed=True,
            summary=fit_summary(fit, options, rate) | {"pictures": drawn.entry},
            plot=drawn.plot(lambda path: plot_fit(fit, path, title)),
        )
    uploads = "" if fit.budget is None else f", {len(fit.budget.uploads)} upload(s)"
    say_done(
        f"{out}: duration {summary['duration_s']:.2f} s, solve "
        f"{1e3 * summary['solve_time_s']:.1f} ms, max excess {summary['max_excess']:.1e}, "
        f"rms deviation {1e3 * summary['rms_deviation_m']:.2f} mm{uploads}"
    )
    return summary


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
        run_fit(
            points, times, options, out, positive_rate(rate), points_csv, force, not no_pictures
        )


def _hull(name: str) -> Any:
    if name not in ("bspline", "bezier"):
        raise InputError(f"--hull: got {name!r}, expected 'bspline' or 'bezier'")
    return name
