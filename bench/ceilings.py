"""The worst input at each ceiling, run by the command line in its own process: memory and time.

docs/ceilings.md promises that every input within the ceilings runs in at most 2 GiB and
10 minutes on two cores. Each case here builds the input that sits at (just under) one
ceiling -- the cases issue 25 found exhausting memory or time among them -- and runs
``skyquill`` on it in a child process (BLAS on one thread, an address-space limit of 4 GiB
so that a regression fails instead of swapping the machine), recording the exit status,
the child's peak resident memory (``wait4``'s ``ru_maxrss``), its CPU time and its wall
time. A case passes when it ends (done, or refused with one line) within both bounds,
time counted as CPU time: the machine is shared, and wall time says more about the
neighbours than about skyquill.

Written to ``bench/results/ceilings.json``. Run: ``.venv/bin/python bench/ceilings.py``
(``--case fit_spans`` for one; ``--list``). Wall times are what one run measured on a
shared machine, quoted with its load average.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from common import jsonable, machine_info

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results"
#: The promise of docs/ceilings.md (tools/ceilings.py states the same numbers).
MEMORY_BOUND_GIB = 2.0
TIME_BOUND_S = 600.0
#: A child is stopped above this address space (a regression then fails, not swaps), and
#: above twice the time bound of CPU.
ADDRESS_LIMIT = 4 * 2**30
_CLI = "from skyquill.cli.entry import run; run()"


def _fit_spans(tmp: Path) -> list[str]:
    """``fit --timing segments`` just under the knot-span ceiling (issue 25: 50,000 took 260 s)."""
    from skyquill.optimize.fit import MAX_SPANS
    from skyquill.optimize.timing import allocate_segment_times

    knot = 0.1
    step = np.array([0.1, 0.0])
    n = 2
    while True:  # the most points whose rest-to-rest timing stays under the ceiling
        pts = _zigzag(n + 200, step)
        spans = math.ceil(allocate_segment_times(pts, 1.0, 0.5 * 2.0)[-1] / knot)
        if spans > 0.97 * MAX_SPANS:
            break
        n += 200
    _csv(tmp / "p.csv", _zigzag(n, step))
    return ["fit", str(tmp / "p.csv"), "--timing", "segments", "--out", str(tmp / "o")]


def _fit_points(tmp: Path) -> list[str]:
    """``fit`` of the most points accepted (200,000), a long recording along a path."""
    from skyquill.optimize.fit import MAX_POINTS

    s = np.linspace(0.0, 40.0 * math.pi, MAX_POINTS)
    pts = np.column_stack([(1.0 + 0.02 * s) * np.cos(s), (1.0 + 0.02 * s) * np.sin(s)])
    _csv(tmp / "p.csv", pts)
    return ["fit", str(tmp / "p.csv"), "--out", str(tmp / "o"), "--knot-interval", "0.5"]


def _write_svg(tmp: Path) -> list[str]:
    """``write --svg`` of one path of 19,000 points with a corner at each (issue 25: 8 GiB)."""
    k = np.arange(19_000)
    angle = 2 * math.pi * k / 2_000
    radius = 100.0 + 2.0 * (k % 2)  # a tooth at every point: every vertex turns
    xy = np.column_stack([radius * np.cos(angle), radius * np.sin(angle) + 0.02 * k])
    d = "M " + " L ".join(f"{x:.3f} {y:.3f}" for x, y in xy)
    (tmp / "d.svg").write_text(
        f'<svg xmlns="http://www.w3.org/2000/svg"><path d="{d}"/></svg>', encoding="utf-8"
    )
    return ["write", "--svg", str(tmp / "d.svg"), "--out", str(tmp / "o")]


def _check_skyc(tmp: Path) -> list[str]:
    """``check`` of a .skyc of the most drones accepted, neighbours circling close (7 GiB)."""
    from skyquill.cli.check_cmd import MAX_DRONES
    from skyquill.export.skybrush.keyframes import skybrush_keyframes
    from skyquill.export.skybrush.skyc_file import SkycDrone, write_skyc
    from skyquill.trajectory import SplineTrajectory

    side = math.ceil(math.sqrt(MAX_DRONES))
    u = np.linspace(0.0, 2 * math.pi, 40)
    circle = 0.5 * np.column_stack([np.cos(u), np.sin(u), np.zeros_like(u)])
    drones = []
    for i in range(MAX_DRONES):
        home = np.array([4.2 * (i % side), 4.2 * (i // side), 10.0])  # 3.2 m apart at closest
        path = SplineTrajectory(home + circle, 5, 60.0)
        drones.append(SkycDrone(f"d{i}", skybrush_keyframes(path)))
    write_skyc(drones, tmp / "show.skyc")
    return ["check", str(tmp / "show.skyc"), "--json"]


def _fly_steps(tmp: Path) -> list[str]:
    """``fly`` of the longest flight accepted at 500 Hz (2,000,000 steps)."""
    from skyquill.sim.bounds import MAX_SIM_STEPS

    rate = 500.0
    t = np.linspace(0.0, (MAX_SIM_STEPS - 2) / rate, 4_001)
    rows = np.zeros((t.size, 10))
    rows[:, 0], rows[:, 3] = t, 1.0
    header = "t,x,y,z,vx,vy,vz,ax,ay,az"
    np.savetxt(tmp / "hover.csv", rows, delimiter=",", header=header, comments="", fmt="%.6f")
    return ["fly", str(tmp / "hover.csv"), "--out", str(tmp / "o"), "--rate", str(rate)]


def _cover_path(tmp: Path) -> list[str]:
    """``cover`` of a field whose path is estimated just under the path-length ceiling."""
    from skyquill.coverage.regions import MAX_PATH_LENGTH_M

    width = 45.0
    side = (-4 * width + math.sqrt((4 * width) ** 2 + 4 * 0.95 * MAX_PATH_LENGTH_M * width)) / 2
    (tmp / "field.wkt").write_text(
        f"POLYGON ((0 0, {side:.1f} 0, {side:.1f} {side:.1f}, 0 {side:.1f}, 0 0))",
        encoding="utf-8",
    )
    # --min-coverage 0: fly the given spacing (a tuned plan would search several).
    return [
        "cover", str(tmp / "field.wkt"), "--width", str(width), "--min-coverage", "0",
        "--out", str(tmp / "o"),
    ]  # fmt: skip


def _cover_cells(tmp: Path) -> list[str]:
    """``cover`` of the largest region at a swath whose path is estimated just under the
    cells' ceiling, at a rate whose ``trajectory.csv`` fits (10 Hz: a 19 h flight)."""
    from skyquill.coverage.plan import MAX_REGION_SIZE_M
    from skyquill.coverage.regions import MAX_MISSION_PATH_M

    side = MAX_REGION_SIZE_M
    width = side * side / (0.95 * MAX_MISSION_PATH_M - 4 * side)
    (tmp / "field.wkt").write_text(
        f"POLYGON ((0 0, {side:.1f} 0, {side:.1f} {side:.1f}, 0 {side:.1f}, 0 0))",
        encoding="utf-8",
    )
    return [
        "cover", str(tmp / "field.wkt"), "--width", f"{width:.3f}", "--min-coverage", "0",
        "--rate", "10", "--time-limit", "600", "--out", str(tmp / "o"),
    ]  # fmt: skip


def _paint_dots(tmp: Path) -> list[str]:
    """``paint`` of the most dots accepted, at a rate whose ``trajectory.csv`` fits (10 Hz).

    10,000 dots are a 67,000 s flight: at the default 100 Hz its trajectory.csv would
    hold more rows than it is read back with, and is refused before sampling.
    """
    from skyquill.painting.dots import MAX_DOTS

    side = math.ceil(math.sqrt(MAX_DOTS))
    k = np.arange(MAX_DOTS)  # a grid 7.9 m wide (the wall spans -4..4 m) and 2 m high
    dots = np.column_stack([-3.95 + 7.9 / side * (k % side), 0.5 + 2.0 / side * (k // side)])
    np.savetxt(tmp / "dots.csv", dots, delimiter=",", header="x,z", comments="", fmt="%.4f")
    return ["paint", str(tmp / "dots.csv"), "--rate", "10", "--out", str(tmp / "o")]


def _zigzag(n: int, step: np.ndarray) -> np.ndarray:
    k = np.arange(n)
    return np.column_stack([step[0] * k, 0.05 * (k % 2)])


def _csv(path: Path, pts: np.ndarray) -> None:
    np.savetxt(path, pts, delimiter=",", header="x,y", comments="", fmt="%.6f")


CASES: dict[str, Callable[[Path], list[str]]] = {
    "fit_spans": _fit_spans,
    "fit_points": _fit_points,
    "write_svg": _write_svg,
    "check_skyc": _check_skyc,
    "fly_steps": _fly_steps,
    "cover_path": _cover_path,
    "cover_cells": _cover_cells,
    "paint_dots": _paint_dots,
}


def _limit() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_LIMIT, ADDRESS_LIMIT))
    cpu = int(2 * TIME_BOUND_S)
    resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 5))


def run_case(name: str) -> dict[str, Any]:
    """Build the case's input, run the command in a child, measure it (``wait4``'s rusage)."""
    with tempfile.TemporaryDirectory(prefix=f"ceiling-{name}-") as folder:
        tmp = Path(folder)
        args = CASES[name](tmp)
        env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")
        start = time.perf_counter()
        with (tmp / "stderr.txt").open("w+b") as err:
            child = subprocess.Popen(
                [sys.executable, "-c", _CLI, *args],
                stdout=subprocess.DEVNULL,
                stderr=err,
                preexec_fn=_limit,  # noqa: PLW1509 - the parent runs no threads
                env=env,
            )
            _, status, usage = os.wait4(child.pid, 0)
            child.returncode = os.waitstatus_to_exitcode(status)
            wall = time.perf_counter() - start
            err.seek(0)
            text = err.read().decode("utf-8", "replace").strip().splitlines()
        peak_gib = usage.ru_maxrss * 1024.0 / 2**30
        cpu = usage.ru_utime + usage.ru_stime
        return {
            "case": name,
            "doc": (CASES[name].__doc__ or "").strip(),
            "command": " ".join(["skyquill", *(a.replace(folder, "<tmp>") for a in args)]),
            "exit_status": child.returncode,
            "last_line": text[-1] if text else "",
            "stderr_lines": len(text),
            "peak_rss_gib": peak_gib,
            "cpu_s": cpu,
            "wall_s": wall,
            # CPU time, not wall time, is held to the bound: the machine is shared.
            "within_bounds": bool(peak_gib <= MEMORY_BOUND_GIB and cpu <= TIME_BOUND_S)
            and child.returncode in (0, 1, 2),  # done, a check that fails, or refused
        }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", action="append", choices=sorted(CASES))
    parser.add_argument("--list", action="store_true")
    args = parser.parse_args()
    if args.list:
        print("\n".join(CASES))
        return
    names = args.case or list(CASES)
    out = RESULTS / "ceilings.json"
    previous = json.loads(out.read_text()) if out.is_file() else {}
    results = {r["case"]: r for r in previous.get("cases", [])}
    for name in names:
        # Each case in a fresh interpreter: RUSAGE_CHILDREN is a maximum over all children.
        done = subprocess.run(
            [sys.executable, __file__, "--one", name], capture_output=True, text=True, check=False
        )
        record = json.loads(done.stdout.strip().splitlines()[-1])
        results[name] = record
        print(
            f"{name}: exit {record['exit_status']}, {record['peak_rss_gib']:.2f} GiB, "
            f"{record['cpu_s']:.0f} s CPU ({record['wall_s']:.0f} s wall), "
            f"{'within' if record['within_bounds'] else 'BEYOND'} "
            f"the bounds; {record['last_line'][:100]}",
            flush=True,
        )
        payload = {
            "command": "python bench/ceilings.py",
            "date": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
            "machine": machine_info(("numpy", "scipy", "clarabel", "piqp")),
            "load_average": os.getloadavg(),
            "bounds": {"memory_gib": MEMORY_BOUND_GIB, "wall_s": TIME_BOUND_S},
            "cases": [results[n] for n in CASES if n in results],
        }
        out.write_text(json.dumps(jsonable(payload), indent=2) + "\n", encoding="utf-8")


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--one":
        print(json.dumps(jsonable(run_case(sys.argv[2]))))
    else:
        main()
