"""How ``skyquill show`` grows with the number of drones (issues 18, 26, 27): 10 to 1,000 drones.

Each show is the structure of ``examples/show_100.toml`` scaled to N drones: take-off, the
words SKY QUILL SHOW as a formation (in a double-stroke font, sized so its points stay
``safety`` apart and below the check's 120 m ceiling), up to 40 drones light-painting one letter
each on sky boards in front of it while the others hold, a grid (at most 22 rows), landing. It is
planned, proven and written by the command itself (``skyquill show`` in this process, BLAS on
one thread), so the time is what a user waits for; ``summary.json``'s ``planning_time_s``
splits it into stages (scenes, the independent check, the ``.skyc`` and its check, pictures,
files). Growth is the log-log slope against N of the total time, of the separation proof
(``check``) and of the ``.skyc`` (written and played back); goal (issue 27): a 1,000-drone show
in at most 120 s, the check and the ``.skyc`` with slopes at most 1.1. Each transition (take-off
to the formation, formation to formation, landing) is recorded against its lower bound, the
longest single move at the limits (goal: at most 1.5x).

The peer, run in the same process on the same shows: the 5 Hz sampled distance check that
Skybrush's validation does (the closest pair per sample by a k-d tree), against the guaranteed
check (``show.check_show``) on the same trajectories; its ratio says what the guarantee costs.

Written to ``bench/results/show.json``. Run: ``.venv/bin/python bench/show.py`` (about
5 minutes on two free cores); ``--drones 10 100`` for fewer, ``--scheduler local`` to plan
the writing on a dask cluster.
"""

from __future__ import annotations

import argparse
import json
import math
import resource
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial import cKDTree
from threadpoolctl import threadpool_limits
from typer.testing import CliRunner

from common import jsonable, machine_info
from skyquill.cli.main import app
from skyquill.io.plan_dir import read_plan
from skyquill.show import ShowDrone, check_show

RESULTS = Path(__file__).resolve().parent / "results"
SAFETY_M = 3.0
SPACING_M = 4.5
LETTERS = "SKYQUILLDRAWSLIGHTINTHEAIRABOVETHEFIELDS"


def script(n: int) -> str:
    """The show of ``n`` drones as TOML."""
    columns = math.ceil(math.sqrt(n))
    grid_columns = max(columns, math.ceil(n / 22))  # 22 rows of 4.5 m from 10 m: below 120 m
    writers = max(2, n // 5)
    text = " ".join(LETTERS[:writers])
    # 1.6 m of text per drone, plus 12 m: 50 drones at 80 m found only 48 points 3 m apart
    size = min(1000.0, max(48.0, 1.6 * n + 12.0))
    return f"""
[show]
drones = {n}
safety_distance = {SAFETY_M}
home_spacing = {SPACING_M}
home_origin = [{-SPACING_M * columns / 2:.1f}, -80.0]
rate = 10

[limits]
vmax = 4.0
amax = 2.0
jmax = 10.0

[[scene]]
type = "takeoff"
altitude = 4.0
stagger = 1.0

[[scene]]
type = "formation"
shape = "text"
text = "SKY QUILL SHOW"
font = "futuram"
origin = [{-size / 2:.1f}, 0.0, 10.0]
size = {size:.1f}
hold = 5.0
color = "#ffb000"

[[scene]]
type = "write"
text = "{text}"
size = 3.0
origin = [{-min(writers, 10) * 3.5:.1f}, -25.0, 10.0]
columns = {min(writers, 10)}
color = [255, 255, 255]

[[scene]]
type = "formation"
shape = "grid"
origin = [{-SPACING_M * grid_columns / 2:.1f}, 0.0, 10.0]
columns = {grid_columns}
spacing = {SPACING_M}
hold = 5.0
color = "#2080ff"

[[scene]]
type = "land"
altitude = 4.0
stagger = 1.0
"""


def sampled_min_distance(drones: list[ShowDrone], rate_hz: float = 5.0) -> float:
    """Skybrush's validation: the closest two drones at ``rate_hz`` samples, m."""
    end = max(d.end_s for d in drones)
    t = np.linspace(0.0, end, int(end * rate_hz) + 1)
    p = np.stack([d.trajectory.evaluate(np.minimum(t, d.end_s)) for d in drones], axis=1)
    best = math.inf
    for k in range(t.size):
        gaps, _ = cKDTree(p[k]).query(p[k], k=2)  # each drone's nearest other drone
        best = min(best, float(gaps[:, 1].min()))
    return best


def cpu_s() -> float:
    """CPU time of this process and its finished children (the writing's workers), s."""
    me, children = (
        resource.getrusage(resource.RUSAGE_SELF),
        resource.getrusage(resource.RUSAGE_CHILDREN),
    )
    return me.ru_utime + me.ru_stime + children.ru_utime + children.ru_stime


def transitions(summary: dict[str, Any]) -> list[dict[str, Any]]:
    """Each transition of the show against its lower bound (``summary.json``'s scenes)."""
    names = {"formation": "to formation", "land": "landing"}
    rows = []
    for k, scene in enumerate(summary["scenes"]):
        if "transition" in scene:
            before = summary["scenes"][k - 1]["type"]
            name = names[scene["type"]]
            if scene["type"] == "formation":
                name = f"{'take-off' if before == 'takeoff' else 'formation'} {name}"
            rows.append({"transition": name, "scene": k} | scene["transition"])
    return rows


def run(n: int, folder: Path, where: list[str]) -> dict[str, Any]:
    """Plan, prove and write the show of ``n`` drones (``where``: the writing's options)."""
    path = folder / f"show_{n}.toml"
    path.write_text(script(n))
    out = folder / f"out_{n}"
    clock, cpu = time.perf_counter(), cpu_s()
    result = CliRunner().invoke(app, ["show", str(path), "--out", str(out), *where])
    wall, cpu = time.perf_counter() - clock, cpu_s() - cpu
    if result.exit_code != 0:
        return {"drones": n, "error": result.output.strip()}
    summary = json.loads((out / "summary.json").read_text())
    drones = [ShowDrone(p.trajectory, name) for name, p in read_plan(out)]
    clock = time.perf_counter()
    guaranteed = check_show(drones, SAFETY_M, None).separation
    check_s = time.perf_counter() - clock
    clock = time.perf_counter()
    sampled = sampled_min_distance(drones)
    sampled_s = time.perf_counter() - clock
    played = summary["skyc"]["played_back"]
    return {
        "drones": n,
        "show_duration_s": summary["duration_s"],
        "wall_s": wall,
        "cpu_s": cpu,
        "stages_s": summary["planning_time_s"],
        "transitions": transitions(summary),
        "separation_m": {
            "requested": SAFETY_M,
            "guaranteed_plan": summary["min_separation_m"]["guaranteed"],
            "guaranteed_independent_check": guaranteed.lower_bound_m,
            "guaranteed_skyc_as_played": played["guaranteed_separation_m"],
            "sampled_5hz": sampled,
        },
        "skyc": {
            "segments": summary["skyc"]["details"]["segments"],
            "limit_excess_as_played": summary["skyc"]["details"]["limit_excess"],
            # issue 26: the worst relative excess per order of show.skyc as Skybrush plays it
            # (speed, acceleration <= 1 %, jerk <= 5 %) and the verdict
            "as_played_relative_excess": summary["skyc"]["as_played"]["relative_excess"],
            "as_played_verdict": summary["skyc"]["as_played"]["verdict"],
            "max_offset_ms_lights": max(
                d["max_offset_ms"] for d in summary["skyc"]["details"]["lights"]["per_drone"]
            ),
        },
        "peer": {
            "guaranteed_check_s": check_s,
            "sampled_5hz_check_s": sampled_s,
            "ratio_guaranteed_over_sampled": check_s / sampled_s,
        },
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--drones", type=int, nargs="+", default=[10, 50, 100, 1000])
    parser.add_argument("--scheduler", help="plan the writing on this dask scheduler")
    args = parser.parse_args()
    where = ["--scheduler", args.scheduler] if args.scheduler else ["--workers", "2"]
    rows = []
    with threadpool_limits(1), tempfile.TemporaryDirectory() as tmp:
        for n in args.drones:
            rows.append(run(n, Path(tmp), where))
            print(json.dumps(jsonable(rows[-1]))[:300])
    ok = [r for r in rows if "error" not in r]
    big = max(ok, key=lambda r: r["drones"]) if ok else None
    report = {
        "machine": machine_info(("numpy", "scipy", "ruckig", "clarabel")),
        "safety_distance_m": SAFETY_M,
        "writing_planned_on": " ".join(where),
        "runs": rows,
        "loglog_slope_vs_drones": slopes(ok),
        # The two largest sizes only: where the fixed costs of a small show no longer count.
        "loglog_slope_vs_drones_last_two_sizes": slopes(ok[-2:]),
        "goals": {
            "largest_show": None if big is None else big["drones"],
            "largest_show_wall_s (goal <= 120 at 1,000)": None if big is None else big["wall_s"],
            "largest_show_cpu_s": None if big is None else big["cpu_s"],
            "worst_transition_over_lower_bound (goal <= 1.5)": max(
                (t["over_lower_bound"] for r in ok for t in r["transitions"]), default=None
            ),
        },
        "note": "one run per size; cpu_s is this process's and its finished workers' CPU "
        "time (the shared machine's load inflates wall_s, see machine.loadavg_at_start); "
        "wall_s includes the writing planned as writing_planned_on "
        "says; slopes are log-log fits of the stage's time against the number of drones over "
        "all sizes run",
    }
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "show.json").write_text(json.dumps(jsonable(report), indent=2) + "\n")


def slopes(rows: list[dict[str, Any]]) -> dict[str, float | None]:
    """The log-log slopes of the total, CPU, separation proof and ``.skyc`` times in N."""
    return {
        "wall_s": slope(rows, lambda r: r["wall_s"]),
        "cpu_s": slope(rows, lambda r: r["cpu_s"]),
        "separation_check_s": slope(rows, lambda r: r["stages_s"]["check"]),
        "skyc_s": slope(rows, lambda r: r["stages_s"]["skyc"]),
    }


def slope(rows: list[dict[str, Any]], value: Any) -> float | None:
    """The log-log slope of ``value(row)`` against the number of drones (``None``: < 2 rows)."""
    if len(rows) < 2:
        return None
    sizes = np.log([r["drones"] for r in rows])
    return float(np.polyfit(sizes, np.log([value(r) for r in rows]), 1)[0])


if __name__ == "__main__":
    main()
