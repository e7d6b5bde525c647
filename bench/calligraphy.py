"""Calligraphy benchmark: every bundled character planned as a writing mission.

Issue 4: "On 50 characters of the bundled and npm data: every one within the
fidelity tolerance with zero excess; the median planning time (target <= 0.3 s
per character, re-segmentation included) and writing time, in
bench/results/calligraphy.json."

This run plans each bundled Make Me a Hanzi character on a 0.5 m horizontal
board with the default limits (1 m/s, 2 m/s^2, 10 m/s^3, per axis), starting
and ending in hover, with the default time re-segmentation (total time fixed,
8 analytic-gradient steps) included in the planning time. BLAS is pinned to
one thread; medians over 3 runs per character.

Run: ``.venv/bin/python bench/calligraphy.py``.
"""

from __future__ import annotations

import json
import platform
import time
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.progress import track
from threadpoolctl import threadpool_limits

from skyquill.calligraphy.mission import WritingOptions, plan_writing
from skyquill.strokes import bundled_hanzi, hanzi_strokes

RESULTS = Path(__file__).resolve().parent / "results" / "calligraphy.json"
RUNS = 3


def main() -> None:
    """Plan every bundled character, print a summary, write the JSON."""
    options = WritingOptions()
    rows = []
    with threadpool_limits(1):
        for char in track(sorted(bundled_hanzi()), description="characters"):
            strokes = hanzi_strokes(char)
            times = []
            for _ in range(RUNS):
                start = time.perf_counter()
                mission = plan_writing(strokes, options=options)
                times.append(time.perf_counter() - start)
            rows.append(
                {
                    "char": char,
                    "strokes": len(strokes.paths),
                    "planning_time_s": float(np.median(times)),
                    "writing_time_s": mission.trajectory.duration,
                    "deviation_max_m": mission.deviation.max_m,
                    "max_excess": mission.verification.max_excess,
                    "faithful": mission.faithful,
                    "time_scale": mission.time_scale,
                }
            )
    planning = [r["planning_time_s"] for r in rows]
    summary = {
        "n_characters": len(rows),
        "all_faithful": all(r["faithful"] for r in rows),
        "all_zero_excess": all(r["max_excess"] <= 1e-9 for r in rows),
        "tolerance_m": options.tolerance,
        "median_planning_time_s": float(np.median(planning)),
        "max_planning_time_s": float(np.max(planning)),
        "target_planning_time_s": 0.3,
        "meets_target": bool(np.median(planning) <= 0.3),
        "median_writing_time_s": float(np.median([r["writing_time_s"] for r in rows])),
        "max_deviation_m": max(r["deviation_max_m"] for r in rows),
        "resegmentation": {"mode": options.resegment, "iterations": options.resegment_iterations},
    }
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text(
        json.dumps(
            {
                "machine": {"python": platform.python_version(), "platform": platform.platform()},
                "summary": summary,
                "characters": rows,
            },
            indent=2,
            ensure_ascii=False,
        )
        + "\n",
        encoding="utf-8",
    )
    Console().print(summary)


if __name__ == "__main__":
    main()
