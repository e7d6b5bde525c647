"""Looser limits never give a slower flight: the sweep of issue 27.

Ten bundled characters (drawn with a fixed seed) are planned as ``skyquill
write`` plans them (a 0.5 m horizontal board at 1 m, the home on the ground
1 m in front, every other option at its default) at four nested limit sets,
each looser than the last in every limit: (vmax, amax, jmax) = (1, 2, 10),
(2, 4, 40), (5, 10, 100), (20, 50, 1000) in m/s, m/s^2, m/s^3. For every
character and every pair of sets (tighter, looser) the flight's durations are
compared: a pair is *slower* when the looser flight is longer than the tighter
one (strictly, and beyond 1 %).

Written to ``bench/results/timing_monotone.json`` under the ``--label``
given (default ``after``), so that runs of two revisions sit side by side:
``git stash; python bench/timing_monotone.py --label before; git stash pop;
python bench/timing_monotone.py``. Per plan: duration, time scale, deviation,
the CPU time of planning (one BLAS thread); per label: the slower pairs, how
many characters have one, the largest ratio, and each set's median duration.

Run: ``.venv/bin/python bench/timing_monotone.py`` (40 plans, a few minutes).
"""

from __future__ import annotations

import argparse
import itertools
import json
import time
from pathlib import Path
from typing import Any

import numpy as np
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

from common import jsonable, machine_info, one_blas_thread

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results" / "timing_monotone.json"
#: The issue's four nested limit sets (vmax m/s, amax m/s^2, jmax m/s^3), tightest first.
LIMIT_SETS = ((1.0, 2.0, 10.0), (2.0, 4.0, 40.0), (5.0, 10.0, 100.0), (20.0, 50.0, 1000.0))
SEED = 27
N_CHARACTERS = 10
#: Where ``skyquill write`` puts one drone's home (calligraphy.show.layout), m.
HOME = (0.25, -1.0, 0.0)


def characters(n: int, seed: int = SEED) -> list[str]:
    """``n`` bundled characters drawn with ``seed``."""
    from skyquill.strokes import bundled_hanzi

    chars = sorted(bundled_hanzi())
    return [chars[i] for i in np.random.default_rng(seed).choice(len(chars), n, replace=False)]


def plan(char: str, bounds: tuple[float, float, float]) -> dict[str, Any]:
    """``char`` planned as ``skyquill write`` plans it at ``bounds``; its numbers or its error."""
    from dataclasses import replace

    from skyquill.calligraphy.board import Board
    from skyquill.calligraphy.mission import plan_writing
    from skyquill.cli.write_cmd import default_writing_options
    from skyquill.limits import VehicleLimits
    from skyquill.strokes import typed_strokes

    opts = replace(default_writing_options(), limits=VehicleLimits(*bounds))
    cpu = time.process_time()
    try:
        mission = plan_writing(typed_strokes(char), Board(), opts, home=np.array(HOME))
    except Exception as exc:  # every failure is reported, whatever its kind
        return {"error": f"{type(exc).__name__}: {exc}", "cpu_s": time.process_time() - cpu}
    return {
        "duration_s": mission.trajectory.duration,
        "time_scale": mission.time_scale,
        "deviation_mm": 1e3 * mission.deviation.max_m,
        "faithful": mission.faithful,
        "max_excess": mission.verification.max_excess,
        "cpu_s": time.process_time() - cpu,
    }


def slower_pairs(rows: dict[str, list[dict[str, Any]]]) -> list[dict[str, Any]]:
    """Every (character, tighter set, looser set) whose looser flight is longer."""
    out = []
    for char, plans in rows.items():
        for i, j in itertools.combinations(range(len(LIMIT_SETS)), 2):
            a, b = plans[i].get("duration_s"), plans[j].get("duration_s")
            if a is not None and b is not None and b > a:
                out.append(
                    {"char": char, "tighter": LIMIT_SETS[i], "looser": LIMIT_SETS[j]}
                    | {"tighter_s": a, "looser_s": b, "ratio": b / a}
                )
    return out


def summarise(rows: dict[str, list[dict[str, Any]]]) -> dict[str, Any]:
    """The slower pairs and each set's median duration and CPU time."""
    pairs = slower_pairs(rows)
    beyond = [p for p in pairs if p["ratio"] > 1.01]
    per_set = []
    for k, bounds in enumerate(LIMIT_SETS):
        plans = [r[k] for r in rows.values()]
        durations = [p["duration_s"] for p in plans if "duration_s" in p]
        per_set.append(
            {
                "limits": bounds,
                "median_duration_s": float(np.median(durations)) if durations else None,
                "median_cpu_s": float(np.median([p["cpu_s"] for p in plans])),
                "max_cpu_s": float(max(p["cpu_s"] for p in plans)),
                "failed": sum("error" in p for p in plans),
            }
        )
    return {
        "slower_pairs": len(pairs),
        "slower_pairs_beyond_1pct": len(beyond),
        "characters_with_a_slower_pair": len({p["char"] for p in pairs}),
        "largest_ratio": max((p["ratio"] for p in pairs), default=None),
        "pairs": pairs,
        "per_limit_set": per_set,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--label", default="after", help="key of this run in the JSON")
    parser.add_argument("--n", type=int, default=N_CHARACTERS, help="characters")
    args = parser.parse_args()
    chars = characters(args.n)
    rows: dict[str, list[dict[str, Any]]] = {}
    with (
        one_blas_thread(),
        Progress(
            TextColumn("[bold]limits sweep"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn()
        ) as bar,
    ):
        task = bar.add_task("plan", total=len(chars) * len(LIMIT_SETS))
        plan(chars[0], LIMIT_SETS[0])  # warm-up: imports, caches
        for char in chars:
            rows[char] = []
            for bounds in LIMIT_SETS:
                rows[char].append(plan(char, bounds))
                bar.advance(task)
    run = {
        "machine": machine_info(("scipy", "piqp", "clarabel")),
        "characters": "".join(chars),
        "seed": SEED,
        "limit_sets": LIMIT_SETS,
        "home": HOME,
        "plans": rows,
    } | summarise(rows)
    held = json.loads(RESULTS.read_text(encoding="utf-8")) if RESULTS.is_file() else {}
    held["what"] = __doc__.split("\n\n")[1].replace("\n", " ")
    held[args.label] = run
    tmp = RESULTS.with_suffix(".tmp")
    tmp.write_text(json.dumps(jsonable(held), indent=1, ensure_ascii=False) + "\n", "utf-8")
    tmp.replace(RESULTS)
    print(
        f"{args.label}: {run['slower_pairs']} slower pairs ({run['slower_pairs_beyond_1pct']} "
        f"beyond 1 %) on {run['characters_with_a_slower_pair']} of {len(chars)} characters; "
        f"largest ratio {run['largest_ratio']}"
    )
    for entry in run["per_limit_set"]:
        print(entry)


if __name__ == "__main__":
    main()
