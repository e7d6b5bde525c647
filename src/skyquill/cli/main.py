"""``skyquill`` command line: ``fit``, ``demo``, ``reproduce``.

Every command writes into ``--out DIR`` and leaves a ``summary.json`` there.
Errors that are the user's (bad input, infeasible limits) are printed as one
red line and exit with status 2; no traceback.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal

import typer
from rich.console import Console

from skyquill.errors import InputError, SkyquillError
from skyquill.io.points import read_points_csv, write_json, write_trajectory_csv
from skyquill.optimize.fit import FitOptions, PointFit, fit_points
from skyquill.validation import FloatArray

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Plan smooth, limit-respecting quadrotor trajectories for aerial drawing.",
)
console = Console(stderr=True)
EXAMPLES = Path(__file__).resolve().parents[3] / "examples"

OutDir = Annotated[Path, typer.Option("--out", help="Output directory (created).")]


@app.callback()
def main(verbose: Annotated[bool, typer.Option("--verbose", "-v")] = False) -> None:
    """skyquill: aerial drawing and painting with quadrotors."""
    logging.basicConfig(level=logging.INFO if verbose else logging.WARNING)


@contextmanager
def user_errors() -> Iterator[None]:
    """Turn skyquill's own errors into one clear line and exit status 2."""
    try:
        yield
    except SkyquillError as exc:
        console.print(f"[bold red]error:[/] {exc}", highlight=False)
        raise typer.Exit(2) from None


def fit_summary(fit: PointFit, rows: int, rate: float) -> dict[str, Any]:
    """The ``summary.json`` of a fit (SI units)."""
    r, check = fit.result, fit.result.verification
    return {
        "duration_s": r.trajectory.duration,
        "solve_time_s": r.solve_time_s,
        "cost": r.cost,
        "cost_terms": r.cost_terms,
        "max_speed": check.max_speed,
        "max_acc": list(check.max_acc),
        "max_jerk": list(check.max_jerk),
        "max_excess": check.max_excess,
        "rms_deviation_m": fit.rms_deviation_m,
        "max_deviation_m": fit.max_deviation_m,
        "method": r.method,
        "solver": r.solver,
        "time_scale": fit.time_scale,
        "degree": r.trajectory.degree,
        "n_control_points": int(r.trajectory.control_points.shape[0]),
        "n_points": int(fit.points.shape[0]),
        "rate_hz": rate,
        "trajectory_rows": rows,
        "limits": [
            {
                "label": c.label,
                "max_value": c.max_value,
                "relative_excess": c.relative_excess,
                "guaranteed": c.guaranteed,
            }
            for c in check.checks
        ],
        "dense_samples": check.n_samples,
    }


def run_fit(
    points: FloatArray,
    times: FloatArray | None,
    options: FitOptions,
    out: Path,
    rate: float,
    title: str,
) -> dict[str, Any]:
    """Fit, then write ``trajectory.csv``, ``plot.png`` and ``summary.json`` into ``out``."""
    from skyquill.viz.fit_plot import plot_fit

    out.mkdir(parents=True, exist_ok=True)
    with console.status(f"fitting {points.shape[0]} points ({title})"):
        fit = fit_points(points, times, options)
    rows = write_trajectory_csv(out / "trajectory.csv", fit.result.trajectory, rate)
    with console.status("plotting"):
        plot_fit(fit, out / "plot.png", title)
    summary = fit_summary(fit, rows, rate)
    write_json(out / "summary.json", summary)
    console.print(
        f"[green]done[/] {out}: duration {summary['duration_s']:.2f} s, solve "
        f"{1e3 * summary['solve_time_s']:.1f} ms, max excess {summary['max_excess']:.1e}, "
        f"rms deviation {1e3 * summary['rms_deviation_m']:.2f} mm",
        highlight=False,
    )
    return summary


def _rate(rate: float) -> float:
    if not rate > 0:
        raise InputError(f"--rate: got {rate:g}, expected a positive number of Hz")
    return rate


@app.command()
def fit(
    points_csv: Annotated[Path, typer.Argument(help="CSV with columns x,y[,z][,t] in m and s.")],
    out: OutDir,
    vmax: Annotated[
        float, typer.Option(help="Speed limit per axis (or norm if coupled), m/s.")
    ] = 1.0,
    amax: Annotated[float, typer.Option(help="Acceleration limit, m/s^2.")] = 2.0,
    jmax: Annotated[float, typer.Option(help="Jerk limit, m/s^3.")] = 10.0,
    coupled: Annotated[
        int | None,
        typer.Option(
            help="Couple the horizontal axes: sides of the polygon inscribed in the norm limit."
        ),
    ] = None,
    degree: Annotated[int, typer.Option(help="Spline degree (3 to 7).")] = 5,
    weight: Annotated[float, typer.Option(help="Weight of the point deviation.")] = 1e4,
    rate: Annotated[float, typer.Option(help="Sample rate of trajectory.csv, Hz.")] = 100.0,
    knot_interval: Annotated[float, typer.Option(help="Seconds per knot span.")] = 0.1,
    hull: Annotated[str, typer.Option(help="Limit hull: bspline (papers') or bezier.")] = "bspline",
    solver: Annotated[str, typer.Option(help="QP backend: piqp, clarabel or osqp.")] = "piqp",
) -> None:
    """Fit a smooth trajectory to POINTS_CSV that starts and ends at rest."""
    with user_errors():
        options = FitOptions(
            vmax=vmax,
            amax=amax,
            jmax=jmax,
            coupled=coupled,
            degree=degree,
            weight=weight,
            knot_interval=knot_interval,
            hull=_hull(hull),
            solver=solver,
        )
        points, times = read_points_csv(points_csv)
        run_fit(points, times, options, out, _rate(rate), points_csv.stem)


def _hull(name: str) -> Any:
    if name not in ("bspline", "bezier"):
        raise InputError(f"--hull: got {name!r}, expected 'bspline' or 'bezier'")
    return name


@app.command()
def demo(out: OutDir = Path("out/demo")) -> None:
    """Fit the bundled hand-drawn spiral (examples/spiral.csv) and plot it."""
    with user_errors():
        points, _ = read_points_csv(EXAMPLES / "spiral.csv")
        # Time comes from the path allocation, not the tablet's clock: the hand
        # does not start and end at rest, the drone must.
        run_fit(points, None, FitOptions(), out, 100.0, "hand-drawn spiral")


if TYPE_CHECKING:  # the fly command imports the simulator lazily
    from skyquill.io.trajectory_csv import SampledTrajectory
    from skyquill.sim import Disturbances, Flight, OuterLoop

FLY_CONTROLLERS = ("rpt", "pid-ff", "pid", "se3")
FLY_SIMS = ("skyquill", "rotorpy")
#: Largest wind or gust accepted, m/s (a hurricane is ~70 m/s; more is a unit mistake).
MAX_WIND_MPS = 100.0


@app.command()
def fly(
    trajectory_csv: Annotated[
        Path,
        typer.Argument(
            help="trajectory.csv as `fit` writes it: t,x,y,z,vx,vy,vz,ax,ay,az[,jx,jy,jz], SI."
        ),
    ],
    out: OutDir,
    controller: Annotated[
        str, typer.Option(help="Outer loop: rpt, pid-ff, pid (or se3 with --sim rotorpy).")
    ] = "rpt",
    sim: Annotated[str, typer.Option(help="Simulator: skyquill or rotorpy.")] = "skyquill",
    wind: Annotated[str, typer.Option(help="Constant wind x,y,z in m/s, e.g. 2,0,0.")] = "0,0,0",
    gust: Annotated[float, typer.Option(help="Gust standard deviation per axis, m/s.")] = 0.0,
    noise: Annotated[
        float, typer.Option(help="Position measurement noise, standard deviation per axis, m.")
    ] = 0.0,
    seed: Annotated[int, typer.Option(help="Seed of the random generator (gusts, noise).")] = 0,
    rate: Annotated[float, typer.Option(help="Control and integration rate, Hz.")] = 500.0,
) -> None:
    """Fly TRAJECTORY_CSV in closed loop; write summary.json, flight.csv and plot.png."""
    import numpy as np

    from skyquill.errors import SolverError
    from skyquill.io.trajectory_csv import read_trajectory_csv, write_flight_csv
    from skyquill.sim import Disturbances
    from skyquill.viz.flight_plot import plot_flight

    with user_errors():
        if sim not in FLY_SIMS:
            raise InputError(f"--sim: got {sim!r}, expected 'skyquill' or 'rotorpy'")
        loop = _fly_controller(controller, sim)
        wind_mps = _vector3("--wind", wind, "m/s")
        if np.abs(wind_mps).max() > MAX_WIND_MPS:
            raise InputError(
                f"--wind: got {wind!r}, expected components of at most {MAX_WIND_MPS:g} m/s"
            )
        for option, value, most in (("--gust", gust, MAX_WIND_MPS), ("--noise", noise, 1.0)):
            if not 0.0 <= value <= most:
                raise InputError(f"{option}: got {value:g}, expected a number from 0 to {most:g}")
        rate = _rate(rate)
        trajectory = read_trajectory_csv(trajectory_csv)
        disturbances = Disturbances(wind_mps=wind_mps, gust_std_mps=gust, position_noise_m=noise)
        with console.status(
            f"flying {trajectory.duration:.1f} s of {trajectory_csv.name} with "
            f"{controller} on {sim} at {rate:g} Hz"
        ):
            flight = _fly_once(trajectory, loop, sim, disturbances, seed, rate)
        if not (np.all(np.isfinite(flight.p)) and np.all(np.isfinite(flight.v))):
            raise SolverError(
                f"{sim}: the flight diverged (non-finite state), nothing written; "
                "lower the disturbances"
            )
        out.mkdir(parents=True, exist_ok=True)
        rows = write_flight_csv(out / "flight.csv", flight)
        with console.status("plotting"):
            plot_flight(flight, out / "plot.png", trajectory_csv.name)
        summary = flight.summary() | {
            "realtime_factor": flight.summary()["sim_time_s"] / max(flight.wall_time_s, 1e-12),
            "trajectory": str(trajectory_csv),
            "duration_s": trajectory.duration,
            "rate_hz": rate,
            "wind_mps": [float(w) for w in wind_mps],
            "gust_std_mps": gust,
            "position_noise_m": noise,
            "seed": seed,
            "flight_rows": rows,
        }
        write_json(out / "summary.json", summary)
    console.print(
        f"[green]done[/] {out}: RMSE {1e3 * summary['rmse_m']:.2f} mm, max "
        f"{1e3 * summary['max_error_m']:.2f} mm, {summary['realtime_factor']:.0f}x real time",
        highlight=False,
    )


def _fly_controller(name: str, sim: str) -> OuterLoop | Literal["se3"]:
    """The outer loop named on the command line, or ``"se3"`` (RotorPy's own)."""
    from skyquill.sim import CascadePID, RPTController

    if name not in FLY_CONTROLLERS:
        raise InputError(
            f"--controller: got {name!r}, expected one of rpt, pid-ff, pid (se3 with --sim rotorpy)"
        )
    if name == "se3":
        if sim != "rotorpy":
            raise InputError(
                "--controller: got 'se3', expected rpt, pid-ff or pid with --sim "
                f"{sim} (se3 is RotorPy's controller: use --sim rotorpy)"
            )
        return "se3"
    return RPTController() if name == "rpt" else CascadePID(feed_forward=name == "pid-ff")


def _fly_once(
    trajectory: SampledTrajectory,
    loop: OuterLoop | Literal["se3"],
    sim: str,
    disturbances: Disturbances,
    seed: int,
    rate: float,
) -> Flight:
    """One flight on the chosen simulator (RotorPy imported only when asked for)."""
    import numpy as np

    from skyquill.sim import simulate

    if sim == "skyquill":
        if isinstance(loop, str):  # _fly_controller refuses se3 here; this narrows the type
            raise InputError("--controller: got 'se3', expected rpt, pid-ff or pid")
        rng = np.random.default_rng(seed)
        return simulate(
            trajectory, controller=loop, disturbances=disturbances, rng=rng, rate_hz=rate
        )
    quiet = (
        not np.any(disturbances.wind_mps)
        and disturbances.gust_std_mps == 0.0
        and disturbances.position_noise_m == 0.0
    )
    if not quiet:
        raise InputError(
            "--sim rotorpy: got --wind, --gust or --noise, expected none of them (the RotorPy "
            "adapter flies without disturbances)"
        )
    try:
        from skyquill.sim.rotorpy_adapter import fly_rotorpy
    except ImportError as exc:
        raise InputError(f"--sim rotorpy: RotorPy adapter unavailable ({exc})") from None
    try:
        return fly_rotorpy(trajectory, loop, rate_hz=rate)
    except ImportError as exc:
        raise InputError(f"--sim rotorpy: {exc}") from None


def _vector3(option: str, text: str, unit: str) -> FloatArray:
    """Parse ``"x,y,z"`` into a (3,) float array; InputError naming ``option`` otherwise."""
    import math

    import numpy as np

    parts = [p.strip() for p in text.split(",")]
    try:
        values = [float(p) for p in parts]
    except ValueError:
        values = []
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise InputError(
            f"{option}: got {text!r}, expected three comma-separated finite numbers in {unit}, "
            "e.g. 2,0,0"
        )
    return np.array(values)


reproduce_app = typer.Typer(no_args_is_help=True, help="Reproduce the papers' experiments.")
app.add_typer(reproduce_app, name="reproduce")


@reproduce_app.command("corridor")
def reproduce_corridor(
    out: OutDir = Path("out/corridor"),
    corridor: Annotated[Path, typer.Option(help="Box corridor JSON.")] = EXAMPLES
    / "s_corridor.json",
) -> None:
    """Paper 003 §5.4 (Fig. 10): coupled vs decoupled limits in a 7-box S corridor."""
    from rich.progress import Progress

    from skyquill.reproduce.corridor import run_corridor_study

    with user_errors(), Progress(console=console, transient=True) as progress:
        task = progress.add_task("control-point counts", total=None)
        summary = run_corridor_study(
            corridor,
            out,
            on_step=lambda done, total: progress.update(task, completed=done, total=total),
        )
    console.print(f"[green]done[/] {out}: " + _claims(summary), highlight=False)


@reproduce_app.command("segments")
def reproduce_segments(
    out: OutDir = Path("out/segments"),
    segments: Annotated[Path, typer.Option(help="Waypoint CSV (x,y,z).")] = EXAMPLES
    / "segments.csv",
) -> None:
    """Paper 003 §5.2 (Fig. 7): line-segment plan, min-snap peer vs our segment fit."""
    from skyquill.reproduce.segments import run_segment_study

    with user_errors(), console.status("flying the line-segment plan three ways"):
        run_segment_study(segments, out)
    console.print(f"[green]done[/] {out}/summary.json", highlight=False)


def _claims(summary: dict[str, Any]) -> str:
    """``claim: reproduced`` for each of the paper's claims in a study summary."""
    return ", ".join(
        f"{name}: {'reproduced' if claim.get('reproduced') else 'NOT reproduced'}"
        for name, claim in summary.get("claims", {}).items()
    )


if __name__ == "__main__":  # pragma: no cover
    app()
