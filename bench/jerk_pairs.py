"""The pairs method against the LP and the jerk-free plan (issue 27 part 3: jerk on <= 3x off).

For each path of ``bench/jerk_terms.py`` (the 10 m square's spiral, a wiggle, a zigzag) and
grid size, ``plan_speed`` is timed, interleaved in one process (one call of each in turn,
medians over ``--runs``): jerk off (the default: the reachability passes), jerk on by the
pairs method (``method="pairs"``), and jerk on by the HiGHS LP (``method="lp"``, up to
:data:`LP_MAX_POINTS`) or the banded interior point (``method="banded"``, from
:data:`BANDED_FROM` points). Limits v 3 m/s, a 5 m/s^2, j 3 m/s^3, per axis and as the
16-gon norm, the default refinement to 2 %. It reports the time ratios pairs / jerk off
(the goal: <= 3) and LP / pairs, the duration gap pairs / LP - 1 (the LP is the optimum of
every linearised problem: the gap is the price of the greedy pass) and the dense check's
excess of the pairs plan. The first call (numba's compile, or its cache) is untimed.

    .venv/bin/python bench/jerk_pairs.py                  # -> bench/results/jerk_pairs.json
    .venv/bin/python bench/jerk_pairs.py --points 2000 --runs 1   # a smoke test
"""

from __future__ import annotations

import argparse
import importlib
import json
import sys
import time
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from common import jsonable, machine_info, one_blas_thread
from jerk_terms import paths
from skyquill.coverage.speed import SpeedPlan, plan_speed

RESULTS = Path(__file__).resolve().parent / "results" / "jerk_pairs.json"
VMAX, AMAX, JMAX = 3.0, 5.0, 3.0
POINTS = (2000, 8000, 32000)
#: The HiGHS LP is timed up to this many points (19 s a plan at 8,000).
LP_MAX_POINTS = 4000
#: The banded interior point is the reference from this many points.
BANDED_FROM = 8000
GOAL = 3.0


def _load_pairs() -> None:
    """Import the pairs module (and numba) with this folder off ``sys.path``: numba probes
    the ``coverage`` package on import, and ``bench/coverage.py`` would shadow it."""
    here = str(Path(__file__).resolve().parent)
    kept = list(sys.path)
    sys.path[:] = [p for p in sys.path if p and Path(p).resolve() != Path(here)]
    try:
        importlib.import_module("skyquill.coverage.speed.pairs")
    finally:
        sys.path[:] = kept


def _calls(curve: Any, n: int, sides: int | None) -> dict[str, Any]:
    kw: dict[str, Any] = {"n": n, "norm_sides": sides}
    calls = {
        "jerk_off": lambda: plan_speed(curve, VMAX, AMAX, None, **kw),
        "pairs": lambda: plan_speed(curve, VMAX, AMAX, JMAX, method="pairs", **kw),
    }
    if n <= LP_MAX_POINTS:
        calls["lp"] = lambda: plan_speed(curve, VMAX, AMAX, JMAX, method="lp", **kw)
    if n >= BANDED_FROM:
        calls["banded"] = lambda: plan_speed(curve, VMAX, AMAX, JMAX, method="banded", **kw)
    return calls


def case(name: str, curve: Any, n: int, sides: int | None, runs: int) -> dict[str, Any]:
    """One path, grid and limit kind: medians, ratios, durations."""
    calls = _calls(curve, n, sides)
    times: dict[str, list[float]] = {k: [] for k in calls}
    plans: dict[str, SpeedPlan] = {}
    for _ in range(runs):
        for key, fn in calls.items():
            start = time.perf_counter()
            plans[key] = fn()
            times[key].append(time.perf_counter() - start)
    med = {k: float(np.median(v)) for k, v in times.items()}
    ref = "lp" if "lp" in plans else "banded"
    pairs = plans["pairs"]
    return {
        "path": name,
        "grid_points": n,
        "norm_sides": sides,
        "median_s": med,
        "pairs_over_jerk_off": med["pairs"] / med["jerk_off"],
        "reference": ref,
        f"{ref}_over_pairs": med[ref] / med["pairs"],
        f"{ref}_over_jerk_off": med[ref] / med["jerk_off"],
        "duration_s": {k: p.duration for k, p in plans.items()},
        "duration_gap_pairs_over_reference": pairs.duration / plans[ref].duration - 1.0,
        "pairs_solves": pairs.lp_solves,
        "pairs_refinements": pairs.refinements,
        "pairs_solve_time_s": pairs.solve_time,
        "pairs_method": pairs.method,
        "pairs_verify_max_excess": pairs.verify(2.0).max_excess,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--points", type=int, nargs="+", default=list(POINTS))
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--out", type=Path, default=RESULTS)
    args = parser.parse_args(argv)
    wall = time.perf_counter()
    rows = []
    _load_pairs()
    with one_blas_thread():
        compile_start = time.perf_counter()
        plan_speed(paths()["spiral"], VMAX, AMAX, JMAX, n=200, method="pairs")
        first_call = time.perf_counter() - compile_start
        for n in args.points:
            for name, curve in paths().items():
                for sides in (None, 16):
                    row = case(name, curve, n, sides, args.runs if n < 32000 else 1)
                    rows.append(row)
                    ref = row["reference"]
                    print(
                        f"{name:<7} n={n:>6} sides={sides!s:<4} pairs/off "
                        f"{row['pairs_over_jerk_off']:5.1f}  {ref}/off "
                        f"{row[f'{ref}_over_jerk_off']:5.1f}  {ref}/pairs "
                        f"{row[f'{ref}_over_pairs']:5.2f}  gap "
                        f"{100 * row['duration_gap_pairs_over_reference']:+.2f} %  "
                        f"({row['pairs_solves']} solves, verify "
                        f"{100 * row['pairs_verify_max_excess']:.2f} %)",
                        flush=True,
                    )
    out = {
        "schema": 1,
        "generated_utc": datetime.now(UTC).isoformat(timespec="seconds"),
        "total_wall_s": time.perf_counter() - wall,
        "machine": machine_info(("numba", "scipy", "highspy")),
        "blas_threads_pinned_to": 1,
        "first_pairs_call_s": first_call,
        "limits": {"vmax": VMAX, "amax": AMAX, "jmax": JMAX},
        "goal_pairs_over_jerk_off": GOAL,
        "rows": rows,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(jsonable(out), indent=2) + "\n")
    print(f"wrote {args.out} in {out['total_wall_s']:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
