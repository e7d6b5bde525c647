"""Did anything get slower? The same user-level jobs, old code against new, in one run.

Usage::

    .venv/bin/python bench/regression.py [--base REV] [--repeats N]

The base revision (default: the one recorded in ``BASE``) is exported with
``git archive`` into a temporary folder; each job below runs as a fresh
``skyquill ...`` process with ``PYTHONPATH`` pointing at
either tree (same interpreter, same installed dependencies), alternating old
and new so that the machine's noise falls on both. Reported: medians, the
ratio new / old per job, and ``bench/results/regression.json``.

The jobs are command lines, so they measure what a user waits for (imports,
planning, checks, files). Where the new code does more on purpose, the job
says so in its note (every command now re-reads and checks what it wrote).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from common import export_base, machine_info

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results"
#: The last landed revision before the one-trajectory work (issue 12).
BASE = "6d58cd5"

PER_AXIS = ("--amax-axis", "5", "--jmax-axis", "3")
#: A job given as Python code (the same in both trees: ``plan_writing``'s defaults).
PLAN_ALL = (
    "from skyquill.calligraphy.mission import plan_writing",
    "from skyquill.strokes import hanzi_strokes",
    "from skyquill.strokes.hanzi import BENCHMARK_HANZI",
    "[plan_writing(hanzi_strokes(c)) for c in BENCHMARK_HANZI]",
)
#: (name, arguments after ``skyquill``, note). ``{out}`` is a fresh folder.
JOBS: tuple[tuple[str, list[str], str], ...] = (
    ("fit spiral", ["fit", "examples/spiral.csv", "--timing", "path", "--out", "{out}"], ""),
    (
        "write 永",
        ["write", "永", "--out", "{out}"],
        "norm limits are second-order cones now (Clarabel), per-axis boxes before (PIQP)",
    ),
    (
        "cover square",
        ["cover", "examples/coverage/square_10m.geojson", "--out", "{out}"],
        "the LP holds acceleration and jerk norms by a 16-gon now (per axis before)",
    ),
    (
        "cover square, per axis",
        [*("cover", "examples/coverage/square_10m.geojson", "--out", "{out}"), *PER_AXIS],
        "the same limits as before (the old code gets --amax 5 --jmax 3: per axis there)",
    ),
    ("paint", ["paint", "examples/painting/paper_140.csv", "--out", "{out}"], ""),
    (
        "plan the 57 bundled characters",
        ["python:" + "; ".join(PLAN_ALL)],
        "plan_writing with its defaults, in one process (no files): the calligraphy bench's work",
    ),
)
#: The ``skyquill`` console script, run from whichever tree ``PYTHONPATH`` names.
ENTRY = "from skyquill.cli.main import app; app(prog_name='skyquill')"
#: Flags the base revision does not know, and what it takes instead.
OLD_FLAGS = {"--amax-axis": "--amax", "--jmax-axis": "--jmax"}


def run_job(src: Path, args: list[str], out: Path) -> float:
    """Wall time of one command, s (it must succeed)."""
    env = os.environ | {"PYTHONPATH": str(src)}
    if args[0].startswith("python:"):
        command = [sys.executable, "-c", args[0].removeprefix("python:")]
    else:
        command = [sys.executable, "-c", ENTRY, *(a.format(out=out) for a in args)]
    start = time.perf_counter()
    subprocess.run(command, cwd=ROOT, env=env, check=True, capture_output=True)
    return time.perf_counter() - start


def old_args(args: list[str]) -> list[str]:
    return [OLD_FLAGS.get(a, a) for a in args]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", default=BASE)
    parser.add_argument("--repeats", type=int, default=5)
    opts = parser.parse_args()
    entries: list[dict[str, Any]] = []
    with tempfile.TemporaryDirectory() as tmp:
        base_src = export_base(opts.base, Path(tmp))
        for name, args, note in JOBS:
            times: dict[str, list[float]] = {"old": [], "new": []}
            for k in range(opts.repeats):
                for which, src, argv in (
                    ("old", base_src, old_args(args)),
                    ("new", ROOT / "src", args),
                ):
                    out = Path(tmp) / f"{which}-{k}"
                    times[which].append(run_job(src, argv, out))
            old = sorted(times["old"])[len(times["old"]) // 2]
            new = sorted(times["new"])[len(times["new"]) // 2]
            entries.append(
                {"job": name, "old_median_s": old, "new_median_s": new, "ratio": new / old}
                | ({"note": note} if note else {})
            )
            print(f"{name:28s} old {old:6.2f} s  new {new:6.2f} s  ratio {new / old:5.2f}")
    result = {
        "base": opts.base,
        "repeats": opts.repeats,
        "machine": machine_info(("numpy", "scipy", "clarabel", "piqp", "highspy", "ruckig")),
        "what": "wall time of whole commands (fresh processes), old and new interleaved",
        "jobs": entries,
    }
    (RESULTS / "regression.json").write_text(json.dumps(result, indent=2) + "\n")


if __name__ == "__main__":
    main()
