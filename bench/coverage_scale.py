"""Coverage planning time against field size: 1 ha to 10 ha at a 5 m swath (issue 16).

Run from the repository root::

    .venv/bin/python bench/coverage_scale.py                 # full run, about 15 minutes
    .venv/bin/python bench/coverage_scale.py --quick         # 1 timed run per field
    .venv/bin/python bench/coverage_scale.py --keepout-only  # the keep-out fields, ~10 min

It writes ``bench/results/coverage_scale.json`` (``coverage_scale_quick.json``
with ``--quick``) and prints one table. BLAS is pinned to one thread
(``threadpoolctl.threadpool_limits(1)``) for the whole run. Every timing is
``time.perf_counter`` around one ``plan_coverage`` call (path, speed LP, timing
law, dense check, coverage), 1 warm-up call on the smallest field first, the
garbage collector off while timing; medians, p10 and p90 over 3 timed runs.

The fields are squares of 1, 2.5, 5, 7.5 and 10 ha, covered by the default
spiral (offset rings, delta 0.5 m, the default norm limits vmax 3 m/s,
amax 5 m/s^2, jmax 3 m/s^3) at a 5 m swath, with a 300 s time limit. Linear
growth is read from the log-log slope of planning time against path length
(1 = linear) and from the time per kilometre, as a ratio to the 1 ha field's
measured in the same run. Read ratios, not absolute times: the reference
machine has 2 noisy cores shared with other jobs.

``keepout`` (issue 27 part 3; ``--keepout-only`` runs it alone and merges it
into the JSON): the fields with two holes each in ``examples/coverage/``
(:data:`KEEPOUT_FIELDS`: 1.3 ha, the held-out 1.3 ha field of
``tests/cli/test_cover_heldout.py`` scaled x5.8, 10 ha at a 5 m swath; 100 ha
at a 10 m swath) planned as ``skyquill cover`` plans them
(``plan_tuned`` to 99 % coverage, the default spiral and limits) with and
without their holes (the same outline), one timed run each: the
``planning_time_s`` ``summary.json`` reports (the whole planning), its ratio
to the field without holes, and where the budget (:data:`KEEPOUT_BUDGET_S`)
ran out, the step it stopped at. Goals: <= 5 s (1.3 and 10 ha), <= 60 s
(100 ha), <= 2x the field without holes.

``lp_growth``: the speed LP alone against its grid size (1,000 to 8,000 points
on the 10 m square's spiral of ``bench/coverage_lp.py``, one timed run each):
``plan_speed`` with the jerk limit (HiGHS hot starts, let finish), jerk off,
and toppra (jerk off, the same grid) as the peer; log-log slopes of each.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from shapely.geometry import Polygon, box
from threadpoolctl import threadpool_info, threadpool_limits

from common import jsonable, machine_info, time_calls, time_stats, toppra_path
from coverage_lp import spiral
from skyquill.coverage import DEFAULT_MIN_COVERAGE
from skyquill.coverage.plan import CoverageOptions, CoveragePlan, plan_coverage, plan_tuned
from skyquill.coverage.regions import load_region
from skyquill.coverage.speed import plan_speed
from skyquill.errors import SkyquillError

RESULTS = Path(__file__).parent / "results" / "coverage_scale.json"
QUICK_RESULTS = Path(__file__).parent / "results" / "coverage_scale_quick.json"
HECTARES = (1.0, 2.5, 5.0, 7.5, 10.0)
WIDTH_M = 5.0
TIME_LIMIT_S = 300.0
RUNS = 3
#: Issue 16's target: a 10 ha field at a 5 m swath "well under a minute".
TARGET_10HA_S = 60.0
LP_GRIDS = (1000, 2000, 4000, 8000)
EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "coverage"
#: Issue 27's fields with keep-outs: (file in examples/coverage, swath m, goal s).
KEEPOUT_FIELDS = (
    ("holes_1_3ha", 5.0, 5.0),
    ("heldout_holes_1_3ha", 5.0, 5.0),
    ("holes_10ha", 5.0, 5.0),
    ("holes_100ha", 10.0, 60.0),
)
#: Planning budget of one keep-out field, s (a plan not done by then is reported as such).
KEEPOUT_BUDGET_S = 180.0


def options() -> CoverageOptions:
    """The default spiral at the bench's swath and time limit."""
    return CoverageOptions(width=WIDTH_M, time_limit=TIME_LIMIT_S)


def field_case(hectares: float, runs: int) -> dict[str, Any]:
    """Planning time of one square field, with what the plan holds."""
    side = math.sqrt(hectares * 1e4)
    region = box(0.0, 0.0, side, side)
    times, plan = time_calls(lambda: plan_coverage(region, options()), runs)
    assert isinstance(plan, CoveragePlan)
    lp = plan.speed_plan
    return {
        "hectares": hectares,
        "side_m": side,
        "path_length_m": plan.path_length,
        "duration_s": plan.duration,
        "coverage_fraction": plan.coverage,
        "max_excess": plan.limits["max_excess"],
        "joins": plan.limits["joins"],
        "lp": None
        if lp is None
        else {"grid_points": int(lp.u.size), "solves": lp.lp_solves, "solve_time_s": lp.solve_time},
        "planning": time_stats(times, warmup=0),
    }


def _tuned_time(region: Any, width: float) -> dict[str, Any]:
    """``plan_tuned`` as ``skyquill cover`` runs it: its planning time, or where it stopped."""
    opts = CoverageOptions(width=width, time_limit=KEEPOUT_BUDGET_S)
    start = time.perf_counter()
    try:
        plan = plan_tuned(region, opts, DEFAULT_MIN_COVERAGE)
    except SkyquillError as exc:
        return {"planned": False, "wall_s": time.perf_counter() - start, "error": str(exc)}
    return {
        "planned": True,
        "wall_s": time.perf_counter() - start,
        "planning_time_s": plan.planning_time,
        "path_length_m": plan.path_length,
        "duration_s": plan.duration,
        "coverage_fraction": plan.coverage,
        "max_excess": plan.limits["max_excess"],
    }


def keepout_cases() -> list[dict[str, Any]]:
    """Each keep-out field with and without its holes."""
    cases = []
    for name, width, goal in KEEPOUT_FIELDS:
        region = load_region(EXAMPLES / f"{name}.geojson")
        outline = Polygon(region.exterior)
        holed = _tuned_time(region, width)
        open_field = _tuned_time(outline, width)
        case = {
            "field": name,
            "hectares_outline": outline.area / 1e4,
            "width_m": width,
            "goal_s": goal,
            "with_holes": holed,
            "without_holes": open_field,
        }
        if holed["planned"] and open_field["planned"]:
            case["ratio_with_over_without"] = (
                holed["planning_time_s"] / open_field["planning_time_s"]
            )
        cases.append(case)
        print_keepout([case])
    return cases


def print_keepout(cases: list[dict[str, Any]]) -> None:
    for c in cases:
        line = f"{c['field']:>20} ({c['hectares_outline']:.2f} ha, {c['width_m']:g} m swath):"
        for label in ("with_holes", "without_holes"):
            r = c[label]
            got = f"{r['planning_time_s']:.1f} s" if r["planned"] else f"not planned ({r['error']})"
            line += f" {label.replace('_', ' ')} {got};"
        if "ratio_with_over_without" in c:
            line += f" ratio {c['ratio_with_over_without']:.2f} (goal <= {c['goal_s']:g} s, 2x)"
        print(line)


def growth(cases: list[dict[str, Any]]) -> dict[str, Any]:
    """Log-log slope of planning time against path length, and time per km against 1 ha's."""
    length = np.array([c["path_length_m"] for c in cases])
    median = np.array([c["planning"]["median_s"] for c in cases])
    slope = float(np.polyfit(np.log(length), np.log(median), 1)[0])
    per_km = median / (length / 1e3)
    return {
        "loglog_slope_time_vs_path_length": slope,
        "s_per_km": per_km.tolist(),
        "s_per_km_ratio_to_1ha": (per_km / per_km[0]).tolist(),
    }


def _toppra(curve: Any, n: int) -> float | None:
    """Seconds toppra takes on ``curve`` at ``n`` grid points (jerk off), or None without it."""
    path = toppra_path(curve)
    if path is None:
        return None
    import toppra.algorithm as algo
    from toppra import constraint

    limits = [
        constraint.JointVelocityConstraint(np.array([[-100.0, 100.0]] * 2)),
        constraint.JointAccelerationConstraint(np.array([[-5.0, 5.0]] * 2)),
    ]
    grid = np.linspace(0.0, 1.0, n)
    start = time.perf_counter()
    algo.TOPPRA(
        limits, path, gridpoints=grid, parametrizer="ParametrizeConstAccel"
    ).compute_trajectory(0, 0)
    return time.perf_counter() - start


def lp_growth() -> dict[str, Any]:
    """The speed LP's time against its grid size, with toppra's as the peer."""
    curve = spiral(1.0)
    rows = []
    for n in LP_GRIDS:
        start = time.perf_counter()
        jerk = plan_speed(curve, 3.0, 5.0, 3.0, n=n)
        jerk_s = time.perf_counter() - start
        start = time.perf_counter()
        plan_speed(curve, 100.0, 5.0, None, n=n)
        free_s = time.perf_counter() - start
        rows.append(
            {
                "grid_points": n,
                "jerk_plan_s": jerk_s,
                "jerk_lp_s": jerk.solve_time,
                "jerk_lp_solves": jerk.lp_solves,
                "jerk_off_plan_s": free_s,
                "toppra_s": _toppra(curve, n),
            }
        )
    logn = np.log([r["grid_points"] for r in rows])

    def slope(key: str) -> float | None:
        if any(r[key] is None for r in rows):
            return None
        return float(np.polyfit(logn, np.log([r[key] for r in rows]), 1)[0])

    return {
        "rows": rows,
        "loglog_slope": {k: slope(k) for k in ("jerk_plan_s", "jerk_off_plan_s", "toppra_s")},
    }


def print_summary(out: dict[str, Any]) -> None:
    print(f"{'field':>8} {'path km':>8} {'plan s':>8} {'s/km':>6} {'LP s':>6} {'excess':>7}")
    for c in out["cases"]:
        median = c["planning"]["median_s"]
        km = c["path_length_m"] / 1e3
        lp = c["lp"]["solve_time_s"] if c["lp"] else float("nan")
        print(
            f"{c['hectares']:>6.1f}ha {km:>8.2f} {median:>8.2f} {median / km:>6.2f} "
            f"{lp:>6.2f} {c['max_excess']:>7.4f}"
        )
    print(f"log-log slope (1 = linear): {out['growth']['loglog_slope_time_vs_path_length']:.2f}")
    for r in out["lp_growth"]["rows"]:
        print(
            f"LP n={r['grid_points']:>5}: jerk {r['jerk_plan_s']:.2f} s, jerk off "
            f"{r['jerk_off_plan_s']:.3f} s, toppra {r['toppra_s'] or float('nan'):.3f} s"
        )
    print(f"LP log-log slopes: {out['lp_growth']['loglog_slope']}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="1 timed run per field")
    parser.add_argument("--out", type=Path, default=None, help="JSON output path")
    parser.add_argument(
        "--keepout-only", action="store_true", help="only the keep-out fields (merged)"
    )
    args = parser.parse_args(argv)
    runs = 1 if args.quick else RUNS
    out_path: Path = args.out or (QUICK_RESULTS if args.quick else RESULTS)
    wall = time.perf_counter()
    with threadpool_limits(limits=1):
        blas = threadpool_info()
        plan_coverage(box(0.0, 0.0, 100.0, 100.0), options())  # warm-up: imports, caches
        if args.keepout_only:
            return _keepout_only(out_path)
        cases = [field_case(ha, runs) for ha in HECTARES]
        keepout = keepout_cases()
        lp = lp_growth()
    out = {
        "schema": 1,
        "generated_utc": datetime.now(UTC).isoformat(timespec="seconds"),
        "quick": bool(args.quick),
        "total_wall_s": time.perf_counter() - wall,
        "machine": machine_info(("scipy", "highspy", "shapely")),
        "blas_threads_pinned_to": 1,
        "blas": blas,
        "problem": {
            "hectares": HECTARES,
            "width_m": WIDTH_M,
            "pattern": "spiral",
            "time_limit_s": TIME_LIMIT_S,
        },
        "targets": {"10ha_planning_s_below": TARGET_10HA_S},
        "cases": cases,
        "growth": growth(cases),
        "keepout": keepout,
        "lp_growth": lp,
    }
    out_path.parent.mkdir(parents=True, exist_ok=True)
    out_path.write_text(json.dumps(jsonable(out), indent=2) + "\n")
    print_summary(out)
    print(f"wrote {out_path} in {out['total_wall_s']:.1f} s")
    return 0


def _keepout_only(out_path: Path) -> int:
    """The keep-out fields alone, replacing their entry in an existing results file."""
    keepout = keepout_cases()
    out = json.loads(out_path.read_text()) if out_path.exists() else {"schema": 1}
    out["keepout"] = keepout
    out["keepout_generated_utc"] = datetime.now(UTC).isoformat(timespec="seconds")
    out["keepout_machine"] = machine_info(("scipy", "highspy", "shapely"))
    out_path.write_text(json.dumps(jsonable(out), indent=2) + "\n")
    print(f"wrote {out_path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
