"""Writing while someone draws: one stroke appended to a planned flight (issue 27, part 2).

For each of ``--n`` bundled characters (drawn with a fixed seed, 0.5 m, the
CLI's default options) the first stroke is planned with
:func:`~skyquill.calligraphy.mission.plan_writing`, then every other stroke is
appended in turn with :func:`~skyquill.calligraphy.incremental.append_stroke`
-- from a home (as ``skyquill write`` flies) and hovering above the strokes.
Each append is timed (CPU time of the process, BLAS pinned to one thread, the
collector off: what one free core takes; the machine is shared) and its
result checked: the largest jump of position, velocity, acceleration and jerk
at the join (relative), the dense check's excess over the limits, and whether
every stroke so far is within the tolerance. The peer, in the same run: the
same strokes planned from scratch as one flight (what incremental planning
saves), after the last append of each character.

Written to ``bench/results/calligraphy_append.json``: per append the times and
checks; per mode the median, p90 and max append time, against the issue's
target of 50 ms, and the median ratio of an append to a whole replanning.

Run: ``.venv/bin/python bench/calligraphy_append.py`` (a few minutes).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any

import numpy as np
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

from common import gc_off, jsonable, machine_info, one_blas_thread

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results" / "calligraphy_append.json"
SEED = 27
TARGET_S = 0.05
#: Where ``skyquill write`` puts one drone's home (calligraphy.show.layout), m.
HOME = np.array([0.25, -1.0, 0.0])


def characters(n: int) -> list[str]:
    """``n`` bundled characters of at least three strokes, drawn with :data:`SEED`."""
    from skyquill.strokes import bundled_hanzi, hanzi_strokes

    chars = sorted(bundled_hanzi())
    out: list[str] = []
    for i in np.random.default_rng(SEED).permutation(len(chars)):
        if len(hanzi_strokes(chars[i]).paths) >= 3:
            out.append(chars[i])
        if len(out) == n:
            return out
    return out


def cpu(call: Any) -> tuple[Any, float]:
    """``call()`` and its CPU time, s (the collector off)."""
    with gc_off():
        start = time.process_time()
        out = call()
        return out, time.process_time() - start


def join_jump(before: Any, after: Any) -> float:
    """Largest relative jump of position to jerk where ``after`` joins ``before``."""
    t = np.array([before.join_s])
    worst = 0.0
    for order in range(4):
        left = before.trajectory.evaluate(t, order)[0]
        right = after.trajectory.evaluate(t, order)[0]
        worst = max(worst, float(np.abs(right - left).max()) / max(1.0, float(np.abs(left).max())))
    return worst


def run_character(char: str, home: np.ndarray | None) -> list[dict[str, Any]]:
    """Every append of ``char`` (mode ``home``), checked; the peer after the last."""
    from skyquill.calligraphy.board import Board
    from skyquill.calligraphy.incremental import append_stroke
    from skyquill.calligraphy.mission import plan_writing
    from skyquill.cli.write_cmd import default_writing_options
    from skyquill.strokes import Strokes, hanzi_strokes

    opts = default_writing_options()
    paths = hanzi_strokes(char).scaled(opts.size_m).paths
    mission = plan_writing(Strokes(paths[:1]), Board(), opts, home=home)
    rows = []
    for k, stroke in enumerate(paths[1:], start=2):
        appended, seconds = cpu(lambda m=mission, s=stroke: append_stroke(m, s))
        rows.append(
            {
                "char": char,
                "strokes": k,
                "append_cpu_s": seconds,
                "join_jump_rel": join_jump(mission, appended),
                "max_excess": appended.verification.max_excess,
                "faithful": appended.faithful,
                "deviation_mm": 1e3 * appended.deviation.max_m,
                "duration_s": appended.trajectory.duration,
            }
        )
        mission = appended
    whole, seconds = cpu(lambda: plan_writing(Strokes(paths), Board(), opts, home=home))
    rows[-1] |= {"replan_cpu_s": seconds, "replan_duration_s": whole.trajectory.duration}
    return rows


def summarise(rows: list[dict[str, Any]]) -> dict[str, Any]:
    times = np.array([r["append_cpu_s"] for r in rows])
    ratios = [r["append_cpu_s"] / r["replan_cpu_s"] for r in rows if "replan_cpu_s" in r]
    return {
        "appends": len(rows),
        "append_cpu_s": {
            "median": float(np.median(times)),
            "p90": float(np.percentile(times, 90)),
            "max": float(times.max()),
        },
        "within_target": int(np.count_nonzero(times <= TARGET_S)),
        "append_over_replan_median": float(np.median(ratios)),
        "largest_join_jump_rel": max(r["join_jump_rel"] for r in rows),
        "largest_excess": max(r["max_excess"] for r in rows),
        "all_faithful": all(r["faithful"] for r in rows),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=10, help="characters")
    args = parser.parse_args()
    chars = characters(args.n)
    result: dict[str, Any] = {
        "what": __doc__.split("\n\n")[1].replace("\n", " "),
        "machine": machine_info(("scipy", "threadpoolctl")),
        "characters": "".join(chars),
        "target_s": TARGET_S,
    }
    with (
        one_blas_thread(),
        Progress(
            TextColumn("[bold]append"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn()
        ) as bar,
    ):
        run_character("中", None)  # warm-up: imports, caches
        task = bar.add_task("chars", total=2 * len(chars))
        for mode, home in (("home", HOME), ("hover", None)):
            rows: list[dict[str, Any]] = []
            for char in chars:
                rows.extend(run_character(char, home))
                bar.advance(task)
            result[mode] = {"summary": summarise(rows), "rows": rows}
    tmp = RESULTS.with_suffix(".tmp")
    tmp.write_text(json.dumps(jsonable(result), indent=1, ensure_ascii=False) + "\n", "utf-8")
    tmp.replace(RESULTS)
    for mode in ("home", "hover"):
        s = result[mode]["summary"]
        print(
            f"{mode}: {s['appends']} appends, median {1e3 * s['append_cpu_s']['median']:.1f} ms, "
            f"max {1e3 * s['append_cpu_s']['max']:.1f} ms, {s['within_target']} within "
            f"{1e3 * TARGET_S:g} ms; append/replan {s['append_over_replan_median']:.2f}; "
            f"join jump {s['largest_join_jump_rel']:.1e}, excess {s['largest_excess']:.1e}, "
            f"all faithful {s['all_faithful']}"
        )


if __name__ == "__main__":
    main()
