"""``skyquill fly``: fly a plan in closed loop, write flight.csv, plot, summary."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal

import typer
from rich.markup import escape

from skyquill.cli.main import (
    Force,
    OutDir,
    app,
    check_out,
    console,
    parse_vector3,
    positive_rate,
    say_done,
    user_errors,
)
from skyquill.cli.pictures import NoPictures, Pictures
from skyquill.errors import InputError
from skyquill.io.atomic import write_json
from skyquill.io.outputs import staged_output
from skyquill.viz.sampled import sample_flight
from skyquill.viz.worker import Drawing

if TYPE_CHECKING:  # the fly command imports the simulator lazily
    from skyquill.sim import Disturbances, Flight, OuterLoop
    from skyquill.trajectory import Trajectory

FLY_CONTROLLERS = ("rpt", "pid-ff", "pid", "se3")
FLY_SIMS = ("skyquill", "rotorpy")
#: Largest wind or gust accepted, m/s (a hurricane is ~70 m/s; more is a unit mistake).
MAX_WIND_MPS = 100.0


@app.command()
def fly(
    plan: Annotated[
        Path,
        typer.Argument(
            metavar="PLAN",
            help="A plan directory (fit, write, cover, paint), its trajectory.json, or a "
            "trajectory.csv (t,x,y,z,vx,vy,vz,ax,ay,az[,jx,jy,jz], SI).",
        ),
    ],
    out: OutDir,
    controller: Annotated[
        str,
        typer.Option(
            help="Outer loop: rpt, pid-ff, pid (or se3 with --sim rotorpy). With --sim "
            "rotorpy, rpt is matched to RotorPy's vehicle (lag, rotor drag, height loop)."
        ),
    ] = "rpt",
    sim: Annotated[str, typer.Option(help="Simulator: skyquill or rotorpy.")] = "skyquill",
    wind: Annotated[str, typer.Option(help="Constant wind x,y,z in m/s, e.g. 2,0,0.")] = "0,0,0",
    gust: Annotated[float, typer.Option(help="Gust standard deviation per axis, m/s.")] = 0.0,
    noise: Annotated[
        float, typer.Option(help="Position measurement noise, standard deviation per axis, m.")
    ] = 0.0,
    seed: Annotated[int, typer.Option(help="Seed of the random generator (gusts, noise).")] = 0,
    rate: Annotated[float, typer.Option(help="Control and integration rate, Hz.")] = 500.0,
    allow_motion: Annotated[
        bool,
        typer.Option(help="Fly a trajectory that does not start and end at rest (a cut-out)."),
    ] = False,
    force: Force = False,
    no_pictures: NoPictures = False,
) -> None:
    """Fly every trajectory of PLAN in closed loop; write summary.json, flight.csv, plot.png."""
    import numpy as np

    from skyquill.io.plan_dir import plan_files, read_plan
    from skyquill.sim import Disturbances, check_rest_ends
    from skyquill.sim.bounds import MAX_RATE_HZ, MIN_RATE_HZ
    from skyquill.validation import as_seed

    with user_errors():
        check_out(out)
        if sim not in FLY_SIMS:
            raise InputError(f"--sim: got {sim!r}, expected 'skyquill' or 'rotorpy'")
        loop = _fly_controller(controller, sim)
        wind_mps = parse_vector3("--wind", wind, "m/s")
        if np.abs(wind_mps).max() > MAX_WIND_MPS:
            raise InputError(
                f"--wind: got {wind!r}, expected components of at most {MAX_WIND_MPS:g} m/s"
            )
        for option, value, most in (("--gust", gust, MAX_WIND_MPS), ("--noise", noise, 1.0)):
            if not 0.0 <= value <= most:
                raise InputError(f"{option}: got {value:g}, expected a number from 0 to {most:g}")
        rate = positive_rate(rate, low=MIN_RATE_HZ, high=MAX_RATE_HZ)
        seed = as_seed("--seed", seed)
        plans = read_plan(plan)
        if not allow_motion:
            for _, planned in plans:
                check_rest_ends(planned.trajectory)
        disturbances = Disturbances(wind_mps=wind_mps, gust_std_mps=gust, position_noise_m=noise)
        setup = _Setup(loop, sim, disturbances, seed, rate)
        drawn = Pictures(not no_pictures)
        with staged_output(out, "fly", force=force, inputs=plan_files(plan)) as stage:
            flights = [
                _fly_drone(name, p.trajectory, setup, stage, (len(plans) > 1, drawn))
                for name, p in plans
            ]
            summary = _worst(flights) | {
                "plan": str(plan),
                "rate_hz": rate,
                "wind_mps": [float(w) for w in wind_mps],
                "gust_std_mps": gust,
                "position_noise_m": noise,
                "seed": seed,
                "drones": flights,
                "pictures": drawn.entry,
            }
            write_json(stage / "summary.json", summary)
    say_done(
        f"{out}: RMSE {1e3 * summary['rmse_m']:.2f} mm, max "
        f"{1e3 * summary['max_error_m']:.2f} mm, {summary['realtime_factor']:.0f}x real time"
    )


@dataclass(frozen=True)
class _Setup:
    loop: OuterLoop | Literal["se3"]
    sim: str
    disturbances: Disturbances
    seed: int
    rate: float


def _fly_drone(
    name: str, trajectory: Trajectory, setup: _Setup, out: Path, pictures: tuple[bool, Pictures]
) -> dict[str, Any]:
    """Fly one trajectory; write its flight CSV and plot; its summary entry.

    ``pictures``: whether the plan has several drones (files named after each), and
    what to draw.
    """
    import numpy as np

    from skyquill.errors import SolverError
    from skyquill.io.trajectory_csv import write_flight_csv

    with console.status(
        f"flying {trajectory.duration:.1f} s of {escape(name)} on {setup.sim} at {setup.rate:g} Hz"
    ):
        flight = _fly_once(trajectory, setup)
    if not (np.all(np.isfinite(flight.p)) and np.all(np.isfinite(flight.v))):
        raise SolverError(
            f"{setup.sim}: the flight of {name} diverged (non-finite state), nothing written; "
            "lower the disturbances"
        )
    several, drawn = pictures
    suffix = f"_{name}" if several else ""
    rows = write_flight_csv(out / f"flight{suffix}.csv", flight)
    if drawn.drawn:
        with console.status("plotting"), drawn.timing(f"plot{suffix}.png"):
            # matplotlib: imported where it is drawn, only when drawn, inside the timing.
            samples = sample_flight(flight, name)
            drawn.draw(
                Drawing("skyquill.viz.flight_plot", "draw_flight", samples),
                out / f"plot{suffix}.png",
            )
    summary = flight.summary()
    return summary | {
        "name": name,
        "realtime_factor": summary["sim_time_s"] / max(flight.wall_time_s, 1e-12),
        "duration_s": trajectory.duration,
        "flight_rows": rows,
    }


def _worst(flights: list[dict[str, Any]]) -> dict[str, Any]:
    """The summary's top level: the worst drone by RMSE, the slowest simulation."""
    worst = max(flights, key=lambda f: f["rmse_m"])
    top = {k: v for k, v in worst.items() if k != "name"}
    return top | {
        "realtime_factor": min(f["realtime_factor"] for f in flights),
        "flight_rows": sum(f["flight_rows"] for f in flights),
    }


def _fly_controller(name: str, sim: str) -> OuterLoop | Literal["se3"]:
    """The outer loop named on the command line, or ``"se3"`` (RotorPy's own).

    ``rpt`` is RPT with its feed-forward matched to the vehicle that is flown:
    skyquill's own on ``--sim skyquill``, RotorPy's preset on ``--sim rotorpy``
    (:func:`~skyquill.sim.rotorpy_adapter.matched_rpt`; the skyquill-tuned
    feed-forward tracked a 1 m circle to 56 mm there, the matched one to 1.2 mm,
    RotorPy's SE3 to 8.5 mm).
    """
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
    if name != "rpt":
        return CascadePID(feed_forward=name == "pid-ff")
    return _rotorpy_rpt() if sim == "rotorpy" else RPTController()


def _rotorpy_rpt() -> OuterLoop:
    """RPT matched to the RotorPy vehicle ``fly`` flies (its default preset)."""
    try:
        from skyquill.sim.rotorpy_adapter import matched_rpt

        return matched_rpt()
    except ImportError as exc:
        raise InputError(f"--sim rotorpy: RotorPy adapter unavailable ({exc})") from None


def _fly_once(trajectory: Trajectory, setup: _Setup) -> Flight:
    """One flight on the chosen simulator (RotorPy imported only when asked for)."""
    import numpy as np

    from skyquill.sim import simulate

    loop, sim, disturbances, seed, rate = (
        setup.loop,
        setup.sim,
        setup.disturbances,
        setup.seed,
        setup.rate,
    )
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
