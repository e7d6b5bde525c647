"""Looser limits never give a slower flight, where the flown plan strays from its probe.

``bench/timing_monotone.py`` sweeps the issue's limit sets, whose shape is the pace's: their
plans are their probes. A vehicle whose jerk limit is low for its acceleration times its
writing faster than it can fly faithfully, so its plan strays and steps down the pace
ladder (``calligraphy.allocation._flown``). This draws such pairs: a bundled character of
few strokes (人八十口三大川山), limits (v, a, j) from (0.5, 1, 2) x (1, 2, 4) x (5, 8, 12)
m/s, m/s², m/s³ and the same with one limit raised 2-4x, and records every pair whose
looser flight is more than 1 % longer (planned as ``skyquill write`` plans, the home 1 m
in front of the board).

Run: ``.venv/bin/python bench/timing_strays.py [--seeds 3 4] [--pairs 40]`` ->
``bench/results/timing_strays.json`` (about 40 s a seed).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path
from typing import Any

import numpy as np

from common import jsonable, machine_info, one_blas_thread
from skyquill.calligraphy.board import Board
from skyquill.calligraphy.mission import WritingOptions, plan_writing
from skyquill.errors import InfeasibleError
from skyquill.limits import VehicleLimits
from skyquill.strokes import hanzi_strokes

RESULTS = Path(__file__).parent / "results" / "timing_strays.json"
HOME = np.array([0.25, -1.0, 0.0])
CHARACTERS = "人八十口三大川山"


def duration(char: str, bounds: tuple[float, float, float]) -> float:
    """The planned flight's duration, s (faithful and within the limits: checked)."""
    opts = dataclasses.replace(WritingOptions(), limits=VehicleLimits(*bounds))
    mission = plan_writing(hanzi_strokes(char), Board(), opts, home=HOME)
    assert mission.faithful and mission.verification.max_excess <= 1e-9
    return float(mission.trajectory.duration)


def sweep(seed: int, pairs: int) -> dict[str, Any]:
    """``pairs`` drawn with ``seed``: the slower ones and the largest ratio."""
    rng = np.random.default_rng(seed)
    slower, worst, planned = [], 1.0, 0
    for _ in range(pairs):
        char = CHARACTERS[rng.integers(len(CHARACTERS))]
        tight = (float(rng.choice([0.5, 1.0, 2.0])), float(rng.choice([1.0, 2.0, 4.0])),
                 float(rng.choice([5.0, 8.0, 12.0])))  # fmt: skip
        factors = [1.0, 1.0, 1.0]
        factors[int(rng.integers(3))] = float(rng.choice([2.0, 3.0, 4.0]))
        loose = tuple(t * f for t, f in zip(tight, factors, strict=True))
        try:
            tighter = duration(char, tight)
        except InfeasibleError:
            continue
        looser = duration(char, loose)  # type: ignore[arg-type]
        planned += 1
        worst = max(worst, looser / tighter)
        if looser > 1.01 * tighter:
            slower.append({"char": char, "tight": tight, "loose": loose,
                           "tight_s": tighter, "loose_s": looser})  # fmt: skip
    return {"seed": seed, "pairs": planned, "slower": slower, "largest_ratio": worst}


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
