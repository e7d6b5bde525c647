"""Looser limits never give a slower flight, where the flown plan strays from its probe.

``bench/timing_monotone.py`` sweeps the issue's limit sets, whose shape is the pace's: their
plans are their probes. A vehicle whose jerk limit is low for its acceleration times its
writing faster than it can fly faithfully, so its plan strays and steps down the pace
ladder (``calligraphy.allocation._flown``). This draws such pairs: a bundled character of
few strokes (人八十口三大川山), limits (v, a, j) from (0.5, 1, 2) x (1, 2, 4) x (5, 8, 12)
m/s, m/s², m/s³ and the same with one limit raised 2-4x, and records every pair whose
looser flight is more than 1 % longer, planned as ``skyquill write`` plans
(``timing_monotone.plan``: the command's defaults, the home 1 m in front of the board).

Run: ``.venv/bin/python bench/timing_strays.py [--seeds 3 4] [--pairs 40]`` ->
``bench/results/timing_strays.json`` (about 40 s a seed).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np

from common import jsonable, machine_info, one_blas_thread
from timing_monotone import plan

RESULTS = Path(__file__).parent / "results" / "timing_strays.json"
CHARACTERS = "人八十口三大川山"


def _whole(planned: dict[str, Any]) -> bool:
    """Whether a plan of :func:`timing_monotone.plan` is faithful and within its limits."""
    return "error" not in planned and planned["faithful"] and planned["max_excess"] <= 1e-9


def sweep(seed: int, pairs: int) -> dict[str, Any]:
    """``pairs`` drawn with ``seed``: the slower ones, those with a plan that failed,
    strays or breaks its limits (the looser set must plan where the tighter does), and the
    largest ratio."""
    rng = np.random.default_rng(seed)
    slower, failed, worst, planned = [], [], 1.0, 0
    for _ in range(pairs):
        char = CHARACTERS[rng.integers(len(CHARACTERS))]
        tight = (float(rng.choice([0.5, 1.0, 2.0])), float(rng.choice([1.0, 2.0, 4.0])),
                 float(rng.choice([5.0, 8.0, 12.0])))  # fmt: skip
        factors = [1.0, 1.0, 1.0]
        factors[int(rng.integers(3))] = float(rng.choice([2.0, 3.0, 4.0]))
        loose = tuple(t * f for t, f in zip(tight, factors, strict=True))
        tighter = plan(char, tight)
        if "error" in tighter:  # (nothing to compare against: those limits cannot be met)
            continue
        looser = plan(char, loose)  # type: ignore[arg-type]
        pair = {"char": char, "tight_limits": tight, "loose_limits": loose,
                "tight": tighter, "loose": looser}  # fmt: skip
        if not all(_whole(p) for p in (tighter, looser)):
            failed.append(pair)
            continue
        planned += 1
        ratio = looser["duration_s"] / tighter["duration_s"]
        worst = max(worst, ratio)
        if ratio > 1.01:
            slower.append(pair)
    return {"seed": seed, "pairs": planned, "slower": slower, "failed": failed,
            "largest_ratio": worst}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[3, 4])
    parser.add_argument("--pairs", type=int, default=40)
    args = parser.parse_args()
    with one_blas_thread():
        runs = [sweep(seed, args.pairs) for seed in args.seeds]
    for run in runs:
        print(json.dumps(jsonable(run)))
    out = {"machine": machine_info(("numpy", "scipy")), "runs": runs}
    RESULTS.write_text(json.dumps(jsonable(out), indent=2) + "\n")


if __name__ == "__main__":
    main()
