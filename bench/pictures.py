"""How much of each command's wall time its pictures take (issue 27, part 5): goal at most 20 %.

Every planning command draws pictures (``plot.png``; on sky boards and in shows also
``long_exposure.png`` and ``preview.gif``) and records the time spent drawing them in
``summary.json`` (``pictures.time_s``). Each workload below is run by the command
itself in this process (``CliRunner``, BLAS on one thread), with pictures and with
``--no-pictures``, the two alternated so both see the same machine noise:

* ``share`` is the median over runs of ``pictures.time_s / wall`` of the runs with
  pictures (what the goal is about);
* ``without_over_with`` is the median wall time without pictures over the median
  with them: the same share seen from outside the command (``1 - share`` up to noise).

A command run from the shell also starts Python and imports skyquill (a few seconds on
this machine, more than ``fit`` plans in), and, when it draws, matplotlib (inside the
pictures' time). So the short commands (:data:`FRESH`) are also run as a user runs them,
``skyquill ...`` in a fresh process, alternated the same way: ``fresh_process`` holds
their shares of that wall time. There ``fit``, ``fly``, ``write`` and ``cover`` draw in the
picture worker (:mod:`skyquill.viz.worker`) when a core is free as they start:
``runs_drawn_in_the_worker`` counts those runs. In the same loop each is also run with
the worker always started (``worker_always``) and never (``worker_never``), the A/B of
the worker under the same load (``always_over_never``: the ratio of their wall times).

Written to ``bench/results/pictures.json``. Run: ``.venv/bin/python bench/pictures.py``
(about 2 minutes on two free cores with ``--runs 3``, the default: 1.5 in session 40);
``--runs 1`` on a busy machine (``runs`` is recorded), ``--only write`` for the workloads whose
name starts with that (written to ``pictures_quick.json``).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
from threadpoolctl import threadpool_limits
from typer.testing import CliRunner

from common import jsonable, machine_info
from skyquill.cli.main import app

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
RESULTS = ROOT / "bench" / "results"
GOAL_SHARE = 0.2

#: name: the command's arguments ({out} is its output folder, {plan} a fit plan for fly).
WORKLOADS: dict[str, list[str]] = {
    "fit spiral": ["fit", str(EXAMPLES / "spiral.csv"), "--out", "{out}"],
    "write Hi": ["write", "Hi", "--out", "{out}"],
    "write ABCDEFGHIJ 10 drones sky": [
        "write", "ABCDEFGHIJ", "--drones", "10", "--board", "sky", "--out", "{out}",
    ],
    "cover l_field": ["cover", str(EXAMPLES / "coverage" / "l_field.geojson"), "--out", "{out}"],
    "paint paper_140": [
        "paint", str(EXAMPLES / "painting" / "paper_140.csv"), "--out", "{out}",
    ],
    "fly spiral": ["fly", "{plan}", "--out", "{out}"],
    "show small": ["show", str(EXAMPLES / "show_small.toml"), "--out", "{out}"],
}  # fmt: skip
#: Workloads also run in a fresh process: those whose planning takes under a second here.
FRESH = ("fit spiral", "fly spiral", "write Hi", "cover l_field")
#: The console script a user runs, and BLAS on one thread in its process too.
SKYQUILL = Path(sys.executable).with_name("skyquill")
ONE_THREAD = {name: "1" for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")}
#: The console script's entry with the picture worker always (True) or never (False) started.
FORCED = (
    "import skyquill.viz.worker as w; w.a_core_is_free = lambda: %s; "
    "from skyquill.cli.entry import run; run()"
)


def _run(args: list[str], folder: Path, plan: Path) -> tuple[float, dict[str, Any]]:
    """Wall time of one command and its summary."""
    out = folder / "out"
    shutil.rmtree(out, ignore_errors=True)
    filled = [a.format(out=out, plan=plan) for a in args]
    clock = time.perf_counter()
    result = CliRunner().invoke(app, filled)
    wall = time.perf_counter() - clock
    if result.exit_code != 0:
        raise RuntimeError(f"{' '.join(filled)}: {result.output.strip()[-400:]}")
    return wall, json.loads((out / "summary.json").read_text())


def _run_fresh(
    args: list[str], folder: Path, plan: Path, worker: bool | None = None
) -> tuple[float, dict[str, Any]]:
    """Wall time of one command run as ``skyquill ...`` in a new process, and its summary.

    ``worker``: ``None`` as a user runs it (the worker when a core is free); ``True`` or
    ``False``, the console script's entry with the worker always or never started.
    """
    out = folder / "out"
    shutil.rmtree(out, ignore_errors=True)
    filled = [a.format(out=out, plan=plan) for a in args]
    program = [str(SKYQUILL)] if worker is None else [sys.executable, "-c", FORCED % worker]
    clock = time.perf_counter()
    done = subprocess.run(
        [*program, *filled],
        check=False,
        capture_output=True,
        text=True,
        env=os.environ | ONE_THREAD,
    )
    wall = time.perf_counter() - clock
    if done.returncode != 0:
        raise RuntimeError(f"skyquill {' '.join(filled)}: {done.stderr.strip()[-400:]}")
    return wall, json.loads((out / "summary.json").read_text())


def measure(
    name: str, args: list[str], runs: int, folder: Path, plan: Path, *, fresh: bool = False
) -> dict[str, Any]:
    """The workload with and without pictures, alternated, ``runs`` times each.

    ``fresh``: each run is ``skyquill ...`` in a new process (else in this one).
    """
    run = _run_fresh if fresh else _run
    with_s, without_s, shares = [], [], []
    drawn: list[str] = []
    in_worker = 0
    forced: dict[bool, list[tuple[float, float]]] = {True: [], False: []}
    for _ in range(runs):
        wall, summary = run(args, folder, plan)
        pictures = summary["pictures"]
        in_worker += pictures.get("process") == "worker"
        with_s.append(wall)
        shares.append(pictures["time_s"] / wall)
        drawn = pictures["files"]
        for worker in forced if fresh else ():
            wall, summary = _run_fresh(args, folder, plan, worker)
            forced[worker].append((wall, summary["pictures"]["time_s"] / wall))
        wall, summary = run([*args, "--no-pictures"], folder, plan)
        assert summary["pictures"]["drawn"] is False
        without_s.append(wall)
    share = float(np.median(shares))
    return _forced_rows(forced, float(np.median(without_s))) | {
        "workload": name,
        "command": " ".join(args),
        "pictures": drawn,
        "wall_with_pictures_s": float(np.median(with_s)),
        "wall_without_pictures_s": float(np.median(without_s)),
        "pictures_s": float(np.median([s * w for s, w in zip(shares, with_s, strict=True)])),
        "share": share,
        "without_over_with": float(np.median(without_s) / np.median(with_s)),
        "runs": runs,
        "process": "fresh (skyquill ...)" if fresh else "this one (CliRunner)",
        "runs_drawn_in_the_worker": in_worker,
        "meets_goal": share <= GOAL_SHARE,
    }


def _forced_rows(forced: dict[bool, list[tuple[float, float]]], without_s: float) -> dict[str, Any]:
    """The runs with the worker forced on and off (fresh processes): A/B under one load."""
    if not forced[True]:
        return {}
    rows = {}
    for worker, runs in forced.items():
        wall = float(np.median([w for w, _ in runs]))
        rows["worker_always" if worker else "worker_never"] = {
            "wall_with_pictures_s": wall,
            "share": float(np.median([s for _, s in runs])),
            "without_over_with": without_s / wall,
        }
    rows["always_over_never"] = (
        rows["worker_always"]["wall_with_pictures_s"] / rows["worker_never"]["wall_with_pictures_s"]
    )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--only", default="")
    args = parser.parse_args()
    rows, fresh = [], []
    with threadpool_limits(1), tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        plan = folder / "plan"
        _run(WORKLOADS["fit spiral"], folder, plan)  # the plan fly flies
        shutil.copytree(folder / "out", plan)
        for name, command in WORKLOADS.items():
            if name.startswith(args.only):
                rows.append(measure(name, command, args.runs, folder, plan))
                print(json.dumps(jsonable(rows[-1])), flush=True)
        for name in FRESH:
            if name.startswith(args.only):
                fresh.append(measure(name, WORKLOADS[name], args.runs, folder, plan, fresh=True))
                print(json.dumps(jsonable(fresh[-1])), flush=True)
    report = {
        "machine": machine_info(("matplotlib", "pillow")),
        "goal": f"pictures at most {GOAL_SHARE:.0%} of each command's wall time",
        "workloads": rows,
        "worst_share": max(r["share"] for r in rows) if rows else None,
        "fresh_process": fresh,
        "runs": args.runs,
        "note": "share = median of summary.json's pictures.time_s / wall over runs with "
        "pictures; the machine is shared (load in machine.loadavg_at_start), so read the "
        "shares, not the seconds",
    }
    RESULTS.mkdir(exist_ok=True)
    name = "pictures.json" if not args.only else "pictures_quick.json"
    (RESULTS / name).write_text(json.dumps(jsonable(report), indent=2) + "\n")


if __name__ == "__main__":
    main()
