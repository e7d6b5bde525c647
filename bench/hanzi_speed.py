"""Calligraphy planning speed, old code against new, character by character (issue 27).

``--n`` bundled characters (drawn with a fixed seed) are planned as ``skyquill
write CHAR`` plans them -- :func:`~skyquill.strokes.typed_strokes` then
:func:`~skyquill.calligraphy.show.plan_show` with the CLI's default options,
from the home one drone takes off from -- by two long-lived worker processes,
one on a base revision (exported with ``git archive``, default :data:`BASE`:
the branch point of issue 27's work) and one on this tree, each with BLAS
pinned to one thread (threadpoolctl) and warmed up on one character first.
The characters go to the two workers in turn (old, new, old, new, ...), so
the machine's noise falls on both alike; each worker measures the CPU time of
its own process per character (``time.process_time``: what one free core
would take; the machine is shared, so wall times are noise).

Written to ``bench/results/hanzi_speed.json``: per character the CPU time,
flight duration, time scale and deviation of both; per tree the median, p90
and max CPU time; and the new/old ratios (of the medians, and the median of
the per-character ratios). The issue's target: median <= 0.1 s, max <= 0.3 s
on the whole bundled set (``bench/hanzi_all.py`` measures that; this is the
side-by-side peer on a sample).

Run: ``.venv/bin/python bench/hanzi_speed.py`` (20 characters, a few minutes).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

from common import export_base, jsonable, machine_info

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results" / "hanzi_speed.json"
#: main with the consumer packages split out, before issue 27's work on the planner.
BASE = "bac3736"
SEED = 27
#: One worker: plans the characters it reads from stdin, one JSON line each.
WORKER = r"""
import json, sys, time
from threadpoolctl import threadpool_limits
threadpool_limits(limits=1)
import inspect
from skyquill.calligraphy.show import plan_show
from skyquill.cli.write_cmd import default_writing_options, write
from skyquill.strokes import typed_strokes

defaults = {k: p.default for k, p in inspect.signature(write).parameters.items()}
show = {"board_kind": defaults["board"], "board_height_m": defaults["board_height"],
        "lift_m": defaults["lift"]}
options = default_writing_options()

def plan(char):
    cpu, wall = time.process_time(), time.perf_counter()
    mission = plan_show([typed_strokes(char)], options, **show).missions[0]
    return {"cpu_s": time.process_time() - cpu, "wall_s": time.perf_counter() - wall,
            "duration_s": mission.trajectory.duration, "time_scale": mission.time_scale,
            "deviation_m": mission.deviation.max_m, "faithful": mission.faithful,
            "jerk_cost": sum(f.cost_terms["smoothness"] for f in mission.fits),
            "max_excess": max(f.verification.max_excess for f in mission.fits)}

plan("\u4e2d")  # warm-up: imports, caches
# Again now that the planner has loaded every BLAS it uses (scipy's own among them):
# threadpoolctl limits only the libraries loaded when it is called.
threadpool_limits(limits=1)
print("ready", flush=True)
for line in sys.stdin:
    char = line.strip()
    try:
        row = plan(char)
    except Exception as exc:
        row = {"error": f"{type(exc).__name__}: {exc}"}
    print(json.dumps(row), flush=True)
"""


def characters(n: int, seed: int = SEED) -> list[str]:
    """``n`` bundled characters drawn with ``seed``."""
    sys.path.insert(0, str(ROOT / "src"))
    from skyquill.strokes import bundled_hanzi

    chars = sorted(bundled_hanzi())
    return [chars[i] for i in np.random.default_rng(seed).choice(len(chars), n, replace=False)]


def start_worker(src: Path) -> subprocess.Popen[str]:
    """A worker planning with the tree whose ``src`` folder is given."""
    env = os.environ | {"PYTHONPATH": str(src), "PYTHONIOENCODING": "utf-8"}
    proc = subprocess.Popen(
        [sys.executable, "-c", WORKER],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
        encoding="utf-8",
        env=env,
    )
    assert proc.stdout is not None
    if proc.stdout.readline().strip() != "ready":
        raise RuntimeError(f"the worker on {src} did not start")
    return proc


def ask(proc: subprocess.Popen[str], char: str) -> dict[str, Any]:
    """One character planned by ``proc``: its JSON row."""
    assert proc.stdin is not None and proc.stdout is not None
    proc.stdin.write(char + "\n")
    proc.stdin.flush()
    return dict(json.loads(proc.stdout.readline()))


def stats(values: list[float]) -> dict[str, float]:
    v = np.asarray(values)
    return {
        "median": float(np.median(v)),
        "p90": float(np.percentile(v, 90)),
        "max": float(v.max()),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=20, help="characters")
    parser.add_argument("--base", default=BASE, help="the revision to compare with")
    args = parser.parse_args()
    chars = characters(args.n)
    rows: list[dict[str, Any]] = []
    with tempfile.TemporaryDirectory() as tmp:
        old_src = export_base(args.base, Path(tmp))
        workers = {"old": start_worker(old_src), "new": start_worker(ROOT / "src")}
        with Progress(
            TextColumn("[bold]old vs new"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn()
        ) as bar:
            task = bar.add_task("plan", total=len(chars))
            for char in chars:
                rows.append({"char": char} | {k: ask(w, char) for k, w in workers.items()})
                bar.advance(task)
        for w in workers.values():
            w.terminate()
    done = [r for r in rows if "cpu_s" in r["old"] and "cpu_s" in r["new"]]
    per_char = [r["new"]["cpu_s"] / r["old"]["cpu_s"] for r in done]
    result = {
        "what": __doc__.split("\n\n")[1].replace("\n", " "),
        "machine": machine_info(("scipy", "piqp", "clarabel", "threadpoolctl")),
        "base": args.base,
        "characters": "".join(chars),
        "seed": SEED,
        "rows": rows,
        "failed": [r["char"] for r in rows if r not in done],
        "old_cpu_s": stats([r["old"]["cpu_s"] for r in done]),
        "new_cpu_s": stats([r["new"]["cpu_s"] for r in done]),
        "new_over_old_median": float(np.median([r["new"]["cpu_s"] for r in done]))
        / float(np.median([r["old"]["cpu_s"] for r in done])),
        "new_over_old_per_character": stats(per_char),
        "new_duration_over_old": stats(
            [r["new"]["duration_s"] / r["old"]["duration_s"] for r in done]
        ),
        # The smoothing's jerk cost (fixed total time: re-segmentation moves time only).
        "new_jerk_cost_over_old": stats(
            [r["new"]["jerk_cost"] / r["old"]["jerk_cost"] for r in done]
        ),
        "new_jerk_cost_over_old_min": min(
            r["new"]["jerk_cost"] / r["old"]["jerk_cost"] for r in done
        ),
        "all_faithful": all(r[k]["faithful"] for r in done for k in ("old", "new")),
        "max_excess": max(r[k]["max_excess"] for r in done for k in ("old", "new")),
    }
    tmp_out = RESULTS.with_suffix(".tmp")
    tmp_out.write_text(json.dumps(jsonable(result), indent=1, ensure_ascii=False) + "\n", "utf-8")
    tmp_out.replace(RESULTS)
    print(
        f"old median {result['old_cpu_s']['median']:.3f} s max {result['old_cpu_s']['max']:.3f} s; "
        f"new median {result['new_cpu_s']['median']:.3f} s max {result['new_cpu_s']['max']:.3f} s; "
        f"new/old {result['new_over_old_median']:.2f}; durations new/old "
        f"{result['new_duration_over_old']}; jerk cost new/old {result['new_jerk_cost_over_old']}"
    )


if __name__ == "__main__":
    main()
