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

Written to ``bench/results/pictures.json``. Run: ``.venv/bin/python bench/pictures.py``
(about 10 minutes on two free cores with ``--runs 3``, the default); ``--runs 1`` on a busy
machine (``runs`` is recorded), ``--only write`` for the workloads whose name starts with that
(written to ``pictures_quick.json``).
"""

from __future__ import annotations

import argparse
import json
import shutil
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


def measure(name: str, args: list[str], runs: int, folder: Path, plan: Path) -> dict[str, Any]:
    """The workload with and without pictures, alternated, ``runs`` times each."""
    with_s, without_s, shares = [], [], []
    drawn: list[str] = []
    for _ in range(runs):
        wall, summary = _run(args, folder, plan)
        pictures = summary["pictures"]
        with_s.append(wall)
        shares.append(pictures["time_s"] / wall)
        drawn = pictures["files"]
        wall, summary = _run([*args, "--no-pictures"], folder, plan)
        assert summary["pictures"]["drawn"] is False
        without_s.append(wall)
    share = float(np.median(shares))
    return {
        "workload": name,
        "command": " ".join(args),
        "pictures": drawn,
        "wall_with_pictures_s": float(np.median(with_s)),
        "wall_without_pictures_s": float(np.median(without_s)),
        "pictures_s": float(np.median([s * w for s, w in zip(shares, with_s, strict=True)])),
        "share": share,
        "without_over_with": float(np.median(without_s) / np.median(with_s)),
        "runs": runs,
        "meets_goal": share <= GOAL_SHARE,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--only", default="")
    args = parser.parse_args()
    rows = []
    with threadpool_limits(1), tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        plan = folder / "plan"
        _run(WORKLOADS["fit spiral"], folder, plan)  # the plan fly flies
        shutil.copytree(folder / "out", plan)
        for name, command in WORKLOADS.items():
            if name.startswith(args.only):
                rows.append(measure(name, command, args.runs, folder, plan))
                print(json.dumps(jsonable(rows[-1])))
    report = {
        "machine": machine_info(("matplotlib", "pillow")),
        "goal": f"pictures at most {GOAL_SHARE:.0%} of each command's wall time",
        "workloads": rows,
        "worst_share": max(r["share"] for r in rows) if rows else None,
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
