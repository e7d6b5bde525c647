"""Simulator benchmark: simulated seconds per wall-clock second, ours against RotorPy.

Run from the repository root::

    .venv/bin/python bench/sim.py           # full run, about 5-6 minutes
    .venv/bin/python bench/sim.py --quick   # smoke test: 3 runs, no 500 Hz RotorPy, ~1 min

It writes ``bench/results/sim.json`` (``sim_quick.json`` with ``--quick``) and
prints a table.

The issue's text: "Simulated seconds per wall-clock second at a 500 Hz step for
a 60 s flight: target >= 50x real time; report the ratio against RotorPy
measured in the same run."

What is flown and timed:

* The reference: a slow 3-D figure-eight (1 m by 0.5 m, two loops of x, four of
  y, z = 1 m +- 0.1 m; at most about 0.2 m/s), 601 points at 10 Hz over
  exactly 60 s fitted by :func:`skyquill.optimize.fit.fit_points` (degree 5,
  default limits, rest to rest); it is evaluated once per run by each
  simulator, as a user's flight would be.
* Ours: :func:`skyquill.sim.simulate` with :class:`~skyquill.sim.RPTController`
  at 500 Hz (30,001 steps), no disturbances. ``median_s`` is
  ``time.perf_counter`` around the whole call (reference evaluation
  included); ``loop_median_s`` is the flight's own ``wall_time_s`` (the
  stepping loop only).
* RotorPy, through :func:`skyquill.sim.rotorpy_adapter.fly_rotorpy`
  (RotorPy's ``Environment.run``: 6-DoF rigid body, motor dynamics and
  aerodynamics, RK45 per step): the same RPT outer loop through RotorPy's
  ``cmd_acc`` abstraction at 100 Hz (RotorPy's default rate) and at 500 Hz
  (the issue's step), and RotorPy's own SE(3) controller at 100 Hz.
* Per run, every configuration is flown once, alternating, so all see the
  same machine noise; one short warm-up flight of each first; the garbage
  collector is off while timing; medians, p10 and p90 over ``--runs`` (>= 5)
  runs; BLAS pinned to one thread (``threadpoolctl``).
* ``realtime_factor = 60 s / median_s``; the ratios divide our realtime
  factor by RotorPy's (equivalently RotorPy's median time by ours). The
  simulators do different amounts of physics per step (ours: translational
  dynamics with first-order inner loops; RotorPy: the full rigid body), so the
  ratio is a cost-of-use figure, not a like-for-like efficiency claim. RMSE
  of each flight is recorded to show that each one actually tracked.
"""

from __future__ import annotations

import argparse
import gc
import importlib.util
import json
import statistics
import time
from collections.abc import Callable
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    SpinnerColumn,
    TextColumn,
    TimeElapsedColumn,
)
from rich.table import Table
from threadpoolctl import threadpool_info, threadpool_limits

from common import machine_info
from skyquill.optimize.fit import fit_points
from skyquill.sim import Flight, RPTController, simulate
from skyquill.trajectory import SplineTrajectory, Trajectory

RESULTS = Path(__file__).resolve().parent / "results" / "sim.json"
QUICK_RESULTS = RESULTS.with_name("sim_quick.json")
ISSUE = (
    "Simulated seconds per wall-clock second at a 500 Hz step for a 60 s flight: target "
    ">= 50x real time; report the ratio against RotorPy measured in the same run."
)
DURATION_S = 60.0
RATE_HZ = 500.0
TARGET_REALTIME = 50.0
MIN_RUNS = 5


def figure_eight(duration: float = DURATION_S) -> tuple[SplineTrajectory, dict[str, Any]]:
    """The reference: a slow 3-D figure-eight fitted over ``duration`` s; and its description."""
    t = np.linspace(0.0, duration, round(10 * duration) + 1)
    phase = 2.0 * np.pi * 2.0 * t / duration  # two loops in x
    points = np.column_stack(
        [np.sin(phase / 2.0), 0.5 * np.sin(phase), 1.0 + 0.1 * np.sin(phase / 2.0)]
    )
    fit = fit_points(points, t)
    traj = fit.result.trajectory
    info = {
        "shape": "figure-eight x = sin(w t / 2), y = 0.5 sin(w t), z = 1 + 0.1 sin(w t / 2), m",
        "duration_s": traj.duration,
        "degree": traj.degree,
        "n_control_points": int(traj.control_points.shape[0]),
        "max_speed_mps": fit.result.verification.max_speed,
        "rms_deviation_m": fit.rms_deviation_m,
        "time_scale": fit.time_scale,
    }
    return traj, info


def hover(duration: float = 1.0) -> SplineTrajectory:
    """A short hover at (0, 0, 1) m for the warm-up flights."""
    return SplineTrajectory(np.tile([0.0, 0.0, 1.0], (6, 1)), 5, duration)


def timed(fly: Callable[[], Flight]) -> tuple[float, Flight]:
    """Wall time of one call (garbage collector off, as ``timeit`` does) and its flight."""
    gc.collect()
    enabled = gc.isenabled()
    gc.disable()
    try:
        start = time.perf_counter()
        flight = fly()
        return time.perf_counter() - start, flight
    finally:
        if enabled:
            gc.enable()


def configurations(traj: Trajectory, with_500: bool) -> dict[str, Callable[[], Flight]]:
    """``{id: callable}`` of every flight timed; RotorPy ones only when it imports."""
    configs: dict[str, Callable[[], Flight]] = {
        "ours_rpt_500hz": lambda: simulate(traj, controller=RPTController(), rate_hz=RATE_HZ)
    }
    if rotorpy_available() is None:
        from skyquill.sim.rotorpy_adapter import fly_rotorpy

        configs["rotorpy_rpt_100hz"] = lambda: fly_rotorpy(traj, RPTController(), rate_hz=100.0)
        configs["rotorpy_se3_100hz"] = lambda: fly_rotorpy(traj, "se3", rate_hz=100.0)
        if with_500:
            configs["rotorpy_rpt_500hz"] = lambda: fly_rotorpy(
                traj, RPTController(), rate_hz=RATE_HZ
            )
    return configs


def rotorpy_available() -> str | None:
    """``None`` when RotorPy and the adapter import; otherwise why not."""
    if importlib.util.find_spec("rotorpy") is None:
        return "rotorpy is not installed (pip install 'skyquill[rotorpy]')"
    try:
        import skyquill.sim.rotorpy_adapter  # noqa: F401
    except ImportError as exc:
        return f"skyquill.sim.rotorpy_adapter does not import: {exc}"
    return None


def entry(config: str, times: list[float], flight: Flight, loops: list[float]) -> dict[str, Any]:
    """One configuration's JSON entry."""
    median = statistics.median(times)
    quantiles = np.quantile(times, [0.1, 0.9])
    sim_time = float(flight.t[-1] - flight.t[0])
    rate = round(1.0 / float(np.median(np.diff(flight.t))))
    out: dict[str, Any] = {
        "id": config,
        "sim": flight.sim,
        "controller": flight.controller,
        "rate_hz": rate,
        "steps": int(flight.t.size),
        "sim_time_s": sim_time,
        "runs": len(times),
        "median_s": median,
        "p10_s": float(quantiles[0]),
        "p90_s": float(quantiles[1]),
        "loop_median_s": statistics.median(loops),
        "realtime_factor": sim_time / median,
        "us_per_step": 1e6 * median / flight.t.size,
        "rmse_m": flight.rmse_m,
        "max_error_m": flight.max_error_m,
        "saturations": dict(flight.saturations),
    }
    if config.startswith("ours"):
        out["target_realtime_factor"] = TARGET_REALTIME
        out["meets_target"] = out["realtime_factor"] >= TARGET_REALTIME
    return out


def run(runs: int, with_500: bool, console: Console) -> dict[str, Any]:
    """Fly every configuration ``runs`` times, alternating; the JSON document."""
    traj, reference = figure_eight()
    configs = configurations(traj, with_500)
    warm = configurations(hover(), with_500)
    times: dict[str, list[float]] = {k: [] for k in configs}
    loops: dict[str, list[float]] = {k: [] for k in configs}
    flights: dict[str, Flight] = {}
    with Progress(
        SpinnerColumn(),
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=console,
    ) as progress:
        task = progress.add_task("warm-up", total=len(configs) * (runs + 1))
        for key, fly in warm.items():
            progress.update(task, description=f"warm-up {key}")
            fly()
            progress.advance(task)
        for i in range(runs):
            for key, fly in configs.items():
                progress.update(task, description=f"run {i + 1}/{runs}: {key}")
                wall, flight = timed(fly)
                times[key].append(wall)
                loops[key].append(flight.wall_time_s)
                flights[key] = flight
                progress.advance(task)
    entries = {k: entry(k, times[k], flights[k], loops[k]) for k in configs}
    ours = entries["ours_rpt_500hz"]
    ratios = {
        f"ours_500hz_over_{key}": ours["realtime_factor"] / e["realtime_factor"]
        for key, e in entries.items()
        if key != "ours_rpt_500hz"
    }
    why_not = rotorpy_available()
    return {
        "schema": 1,
        "generated_utc": datetime.now(UTC).isoformat(timespec="seconds"),
        "issue": ISSUE,
        "reference": reference,
        "timing": {
            "runs": runs,
            "warm_up": "one 1 s hover flight per configuration",
            "clock": "time.perf_counter around the call, gc off",
            "alternating": True,
        },
        "ours": ours,
        "rotorpy": {
            "available": why_not is None,
            "note": why_not
            or (
                "fly_rotorpy: RotorPy Environment.run, px4_sihsim_quadx vehicle, RK45 per step"
                + ("" if with_500 else "; 500 Hz skipped (--quick or --no-rotorpy-500)")
            ),
            "cases": [e for k, e in entries.items() if k.startswith("rotorpy")],
        },
        "ratios": ratios,
        "headline": {
            "realtime_factor_ours_500hz": ours["realtime_factor"],
            "meets_target": ours["meets_target"],
            "ratio_ours_500hz_over_rotorpy_100hz": ratios.get("ours_500hz_over_rotorpy_rpt_100hz"),
            "ratio_ours_500hz_over_rotorpy_500hz": ratios.get("ours_500hz_over_rotorpy_rpt_500hz"),
        },
    }


def print_table(console: Console, out: dict[str, Any]) -> None:
    """The results as one rich table."""
    table = Table(title=f"60 s flight, medians over {out['timing']['runs']} runs")
    for col in ("id", "rate Hz", "median s", "p10-p90 s", "x real time", "µs/step", "RMSE mm"):
        table.add_column(col, justify="left" if col == "id" else "right")
    for e in [out["ours"], *out["rotorpy"]["cases"]]:
        table.add_row(
            e["id"],
            f"{e['rate_hz']:g}",
            f"{e['median_s']:.3f}",
            f"{e['p10_s']:.3f}-{e['p90_s']:.3f}",
            f"{e['realtime_factor']:.1f}",
            f"{e['us_per_step']:.1f}",
            f"{1e3 * e['rmse_m']:.2f}",
        )
    console.print(table)
    ours = out["ours"]
    met = "[green]meets[/]" if ours["meets_target"] else "[red]MISSES[/]"
    console.print(
        f"ours: {ours['realtime_factor']:.1f}x real time at 500 Hz, {met} the >= "
        f"{TARGET_REALTIME:g}x target"
    )
    for key, ratio in out["ratios"].items():
        console.print(f"{key}: {ratio:.1f}x")
    if not out["rotorpy"]["available"]:
        console.print(f"[yellow]RotorPy skipped:[/] {out['rotorpy']['note']}")


def main(argv: list[str] | None = None) -> None:
    """Parse arguments, run, write the JSON, print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--quick", action="store_true", help="3 runs, no 500 Hz RotorPy")
    parser.add_argument("--runs", type=int, default=MIN_RUNS, help="timed runs (>= 5)")
    parser.add_argument(
        "--no-rotorpy-500", action="store_true", help="skip RotorPy at 500 Hz (~50 s per run)"
    )
    parser.add_argument("--out", type=Path, default=None, help="JSON output path")
    args = parser.parse_args(argv)
    if not args.quick and args.runs < MIN_RUNS:
        parser.error(f"--runs: got {args.runs}, expected at least {MIN_RUNS}")
    runs = 3 if args.quick else args.runs
    with_500 = not (args.quick or args.no_rotorpy_500)
    out_path: Path = args.out or (QUICK_RESULTS if args.quick else RESULTS)
    console = Console()
    if not console.is_terminal and console.width < 120:
        console = Console(width=120)  # logs and pipes: do not squeeze the table
    wall = time.perf_counter()
    with threadpool_limits(limits=1):
        blas = threadpool_info()
        out = run(runs, with_500, console)
    out = {
        **out,
        "quick": args.quick,
        "total_wall_s": time.perf_counter() - wall,
        "machine": machine_info(("scipy", "rotorpy")),
        "blas": blas,
    }
    out_path.parent.mkdir(parents=True, exist_ok=True)
    out_path.write_text(json.dumps(out, indent=2, allow_nan=False) + "\n", encoding="utf-8")
    print_table(console, out)
    console.print(f"wrote {out_path}")


if __name__ == "__main__":
    main()
