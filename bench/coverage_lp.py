"""Coverage speed-LP benchmark: scipy ``linprog`` vs the hot-started HiGHS model, and toppra.

Run from the repository root::

    .venv/bin/python bench/coverage_lp.py           # full run, about 2-4 minutes
    .venv/bin/python bench/coverage_lp.py --quick   # smoke test, 3 timed runs

It writes ``bench/results/coverage_lp.json`` (``coverage_lp_quick.json`` with
``--quick``) and prints one table. BLAS is pinned to one thread
(``threadpoolctl.threadpool_limits(1)``) for the whole run. Every timing is
``time.perf_counter`` around one call, 2 warm-up calls first, the garbage
collector off while timing; medians, p10 and p90 over >= 10 timed runs (3 with
``--quick``, and 3 after 1 warm-up for the slow ``linprog`` plans). Read
ratios, not absolute times: the reference machine has 2 noisy cores.

The path is the issue's: the coverage spiral of a 10 m x 10 m square (contours
2 m apart, ``"offset"``, spiral transition ``delta`` 1.0 and 0.3), limits
vmax 3 m/s, amax 5 m/s^2, jmax 3 m/s^3 (the paper's), 2,000 grid points.
Issue targets: "max_excess <= 2 %; one LP solve with 2,000 points <= 100 ms;
whole 10 m x 10 m plan <= 0.5 s".

Cases (1-2 on the delta 1.0 spiral's 2,000-point grid, both the default
adaptive grid, which ``plan_speed`` solves, and a uniform one):

1. ``lp_cold``: one jerk-free LP (speed and acceleration rows, jerk rows
   free), from scratch: ``linprog`` vs a fresh HiGHS model
   (``_GridLP(...).solve``, model construction included).
2. ``lp_first_jerk``: the first pseudo-jerk LP, hot-started from the jerk-free
   optimum (the LP with the most pivots of a plan), highspy only.
   ``lp_hot``: one pseudo-jerk re-solve after a bound change (the linearisation
   point moved from the converged ``b`` to ``0.99 b``), hot-started from the
   previous basis, vs the same LP from scratch with ``linprog``.
3. ``plan``: the whole ``plan_speed`` with jerk limit: the default (uniform
   grid, refinement to 2 %, highspy), the opt-in adaptive grid, the default
   with ``lp_backend="linprog"``, and the previous configuration
   (``max_excess=None``, ``linprog``); each with its duration and the
   ``verify()`` excess.
4. ``toppra``: jerk off (toppra has no jerk limit) and vmax = 100 m/s (toppra's
   velocity constraint is per axis, ours on the norm; so only the per-axis
   acceleration limit binds), same 2,001-point uniform grid: duration ratio and
   solve-time ratio (``TOPPRA(...).compute_trajectory`` vs ``plan_speed``).
5. ``scaling`` (issue 27 part 3): ``plan_speed`` (default: the reachability
   passes without jerk, refinement on) against toppra on the same path and
   grid, 500 to 32,000 points, interleaved (toppra, ours, toppra, ...), medians
   of :data:`SCALE_RUNS`: ``speed_norm`` (vmax 3 m/s as the speed: toppra gets
   the equivalent per-axis bounds ``vmax |C'_i| / |C'|`` through
   ``JointVelocityConstraintVarying``; amax 5 m/s^2 per axis for both) and
   ``acceleration_only`` (vmax 100 m/s); the grid LP (``method="lp"``) as
   the reference up to :data:`LP_MAX_POINTS`; with jerk (jmax 3 m/s^3) the
   pseudo-jerk iteration solved by the banded interior point
   (``method="banded"``, to 32,000 points), by the HiGHS LP (``method="lp"``)
   and by the HiGHS LP warm-started at the interior point's first answer
   (``method="warm"``), both up to :data:`LP_JERK_MAX_POINTS`, interleaved;
   ``auto`` is whichever ``plan_speed`` picks at that size
   (``BANDED_FROM_POINTS``), and ``jerk_on.over_jerk_off`` its time over the
   jerk-free plan's.
   Log-log slopes from 2,000 to 32,000 points, time ratios ours / toppra,
   duration ratios.  Goals: ours <= toppra at 32,000 points, slope <= 1.1,
   jerk on <= 3x jerk off.
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Callable
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from rich.progress import track
from threadpoolctl import threadpool_info, threadpool_limits

from common import jsonable, machine_info, time_calls, time_stats, toppra_path
from skyquill.coverage.paths import contours, spiral_control_points, spiral_curve
from skyquill.coverage.regions import region_from_vertices
from skyquill.coverage.speed import SpeedPlan, plan_speed
from skyquill.coverage.speed.curve import _derivs3, _Reparam
from skyquill.coverage.speed.grid import _grid_map
from skyquill.coverage.speed.iteration import _pseudo_jerk
from skyquill.coverage.speed.rows import (
    _acc_matrix,
    _Bounds,
    _end_caps,
    _GridLP,
    _jerk_matrix,
    _ones,
    _speed_bounds,
)
from skyquill.coverage.speed.validate import BANDED_FROM_POINTS

RESULTS = Path(__file__).resolve().parent / "results" / "coverage_lp.json"
QUICK_RESULTS = RESULTS.with_name("coverage_lp_quick.json")
WARMUP = 2
MIN_RUNS = 10
VMAX, AMAX, JMAX = 3.0, 5.0, 3.0
N = 2000
DELTAS = (1.0, 0.3)
TARGETS = {"lp_s": 0.100, "plan_s": 0.5, "max_excess": 0.02}
SCALE_POINTS = (500, 1000, 2000, 4000, 8000, 16000, 32000)
SCALE_RUNS = 3
#: The grid LP is timed as the reference up to this many points (52 s at 32,000).
LP_MAX_POINTS = 8000
#: The jerk-limited plan through the HiGHS LP is timed up to this many points (85 s at
#: 32,000); through the banded interior point at every size.
LP_JERK_MAX_POINTS = 8000
SCALE_GOALS = {
    "time_ratio_ours_over_toppra_at_32000": 1.0,
    "slope_2000_32000": 1.1,
    "jerk_on_over_jerk_off": 3.0,
}


def spiral(delta: float) -> Any:
    """The issue's coverage spiral of the 10 m square."""
    square = region_from_vertices([[0, 0], [10, 0], [10, 10], [0, 10]])
    return spiral_curve(spiral_control_points(contours(square, 2.0, "offset"), delta))


def measure(fn: Callable[[], Any], runs: int, warmup: int = WARMUP) -> tuple[dict[str, Any], Any]:
    """``warmup`` untimed calls, then ``runs`` timed calls; median/p10/p90 in seconds."""
    for _ in range(warmup):
        fn()
    times, out = time_calls(fn, runs)
    return time_stats(times, warmup), out


def grid_lp(curve: Any, grid: str) -> tuple[Any, _Bounds]:
    """Rows and bounds of the grid LP with jerk rows, as ``plan_speed`` builds them."""
    u = np.linspace(0.0, 1.0, N)
    amax, jmax = np.full(2, AMAX), np.full(2, JMAX)
    if grid == "adaptive":
        curve = _Reparam(curve, _grid_map(curve, N, vmax=VMAX, amax=amax, jmax=jmax))
    c1, c2, c3 = _derivs3(curve, u)
    ub, vb = _speed_bounds(c1, c2, VMAX, chord_error=None, period=0.02)
    a_acc = _acc_matrix(u, (c1, c2), amax)
    a_jerk = _jerk_matrix((c1, c2, c3), jmax, vb)
    from scipy import sparse

    a = sparse.vstack([a_acc, a_jerk], format="csr")
    bounds = _Bounds(ub, vb, 2, *_ones(N))
    _end_caps(bounds.ub, c1, jmax)
    return a, bounds


def lp_cases(curve: Any, runs: int, grid: str) -> list[dict[str, Any]]:
    """Cases 1 and 2: one cold LP, one hot re-solve (highspy) vs linprog from scratch."""
    a, bounds = grid_lp(curve, grid)
    free = bounds.rows(None)
    entries = []
    cold: dict[str, dict[str, Any]] = {}
    for backend in ("linprog", "highspy"):

        def solve_cold(be: str = backend) -> Any:
            return _GridLP(a, backend=be).solve(free, bounds.cols())

        cold[backend], _ = measure(solve_cold, runs)
    entries.append(_pair(f"lp_cold_{grid}", cold, "one jerk-free LP from scratch, n=2000"))
    entries.append(first_jerk_lp(a, bounds, runs, grid))
    # Converge the pseudo-jerk iteration once, then time re-solves after a bound change.
    lp = _GridLP(a, backend="highspy")
    b, _ = _pseudo_jerk(lp, bounds, lp.solve(free, bounds.cols()), stop=(20, 1e-3), log=([], []))
    rows_a, rows_b = bounds.rows(b), bounds.rows(0.99 * b)
    flip = [False]

    def hot() -> Any:
        flip[0] = not flip[0]
        return lp.solve(rows_a if flip[0] else rows_b, bounds.cols())

    hot_stats, _ = measure(hot, max(runs, 20))
    ref = _GridLP(a, backend="linprog")
    scratch, _ = measure(lambda: ref.solve(rows_b, bounds.cols()), runs)
    what = "pseudo-jerk re-solve, n=2000"
    entries.append(_pair(f"lp_hot_{grid}", {"linprog": scratch, "highspy": hot_stats}, what))
    return entries


def first_jerk_lp(a: Any, bounds: _Bounds, runs: int, grid: str) -> dict[str, Any]:
    """The heaviest single LP: the first pseudo-jerk LP, hot-started from the jerk-free basis."""
    free = bounds.rows(None)
    times = []
    for _ in range(WARMUP + runs):
        lp = _GridLP(a, backend="highspy")
        b0 = lp.solve(free, bounds.cols())
        before = lp.time
        lp.solve(bounds.rows(b0), bounds.cols())
        times.append(lp.time - before)
    t = np.asarray(times[WARMUP:])
    return {
        "id": f"lp_first_jerk_{grid}",
        "what": "first pseudo-jerk LP after the jerk-free one (most pivots), highspy, n=2000",
        "highspy": {
            "median_s": float(np.median(t)),
            "p10_s": float(np.percentile(t, 10)),
            "p90_s": float(np.percentile(t, 90)),
            "runs": runs,
        },
        "meets_target": bool(np.median(t) <= TARGETS["lp_s"]),
    }


def _pair(name: str, stats: dict[str, dict[str, Any]], what: str) -> dict[str, Any]:
    ratio = stats["linprog"]["median_s"] / stats["highspy"]["median_s"]
    return {
        "id": name,
        "what": what,
        "linprog": stats["linprog"],
        "highspy": stats["highspy"],
        "speedup_linprog_over_highspy": ratio,
        "meets_target": stats["highspy"]["median_s"] <= TARGETS["lp_s"],
    }


PLAN_VARIANTS: dict[str, dict[str, Any]] = {
    "default_highspy": {},
    "adaptive_grid_highspy": {"grid": "adaptive"},
    "default_linprog": {"lp_backend": "linprog"},
    "previous_linprog": {"max_excess": None, "lp_backend": "linprog"},
}


def plan_case(curve: Any, delta: float, runs: int) -> list[dict[str, Any]]:
    """Case 3: whole ``plan_speed`` with jerk limit in three configurations."""
    entries = []
    for name, kwargs in PLAN_VARIANTS.items():
        slow = "linprog" in name  # seconds per call: 1 warm-up, 3 runs

        def run(kw: dict[str, Any] = kwargs) -> SpeedPlan:
            return plan_speed(curve, VMAX, AMAX, JMAX, n=N, **kw)

        stats, plan = measure(run, 3 if slow else runs, 1 if slow else WARMUP)
        ver = plan.verify()
        entries.append(
            {
                "id": f"plan_delta{delta:g}_{name}",
                "kwargs": kwargs,
                "timing": stats,
                "duration_s": plan.duration,
                "max_excess": ver.max_excess,
                "jerk_excess": ver.jerk_excess,
                "excess_estimate": plan.excess_estimate,
                "refinements": plan.refinements,
                "lp_solves": plan.lp_solves,
                "lp_time_s": plan.solve_time,
                "lp_time_per_solve_s": plan.solve_time / max(plan.lp_solves, 1),
                "meets_target": bool(
                    stats["median_s"] <= TARGETS["plan_s"]
                    and ver.max_excess <= TARGETS["max_excess"]
                ),
            }
        )
    return entries


def toppra_case(curve: Any, runs: int) -> dict[str, Any] | None:
    """Case 4: jerk-off plan vs toppra on the same path and grid."""
    path = toppra_path(curve)
    if path is None:
        return None
    import toppra.algorithm as algo
    from toppra import constraint

    vlim = np.array([[-100.0, 100.0]] * 2)
    alim = np.array([[-AMAX, AMAX]] * 2)

    def peer() -> Any:
        inst = algo.TOPPRA(
            [
                constraint.JointVelocityConstraint(vlim),
                constraint.JointAccelerationConstraint(alim),
            ],
            path,
            gridpoints=np.linspace(0.0, 1.0, N + 1),
            parametrizer="ParametrizeConstAccel",
        )
        return inst.compute_trajectory(0, 0)

    def ours() -> SpeedPlan:
        return plan_speed(curve, 100.0, AMAX, None, n=N + 1)

    t_peer, traj = measure(peer, runs)
    t_ours, plan = measure(ours, runs)
    return {
        "id": "toppra_jerk_off",
        "toppra": t_peer,
        "ours": t_ours,
        "toppra_duration_s": float(traj.duration),
        "ours_duration_s": plan.duration,
        "duration_ratio_ours_over_toppra": plan.duration / float(traj.duration),
        "time_ratio_toppra_over_ours": t_peer["median_s"] / t_ours["median_s"],
        "ours_max_excess": plan.verify().max_excess,
    }


def _toppra_solver(curve: Any, n: int, vmax: float) -> Callable[[], float] | None:
    """toppra on ``curve``'s ``n``-point grid: the speed norm ``vmax`` (as equivalent per-axis
    bounds along the path) and ``AMAX`` per axis; returns a call giving the duration."""
    path = toppra_path(curve)
    if path is None:
        return None
    import toppra.algorithm as algo
    from toppra import constraint

    def vlim(s: float) -> Any:
        c1 = np.asarray(curve(min(max(float(s), 0.0), 1.0), 1), dtype=float)
        bound = vmax * np.abs(c1) / max(float(np.linalg.norm(c1)), 1e-300) + 1e-9
        return np.column_stack([-bound, bound])

    speed = (
        constraint.JointVelocityConstraint(np.array([[-vmax, vmax]] * 2))
        if vmax >= 100.0
        else constraint.JointVelocityConstraintVarying(vlim)
    )
    accel = constraint.JointAccelerationConstraint(np.array([[-AMAX, AMAX]] * 2))
    grid = np.linspace(0.0, 1.0, n)

    def run() -> float:
        inst = algo.TOPPRA([speed, accel], path, gridpoints=grid,
                           parametrizer="ParametrizeConstAccel")  # fmt: skip
        return float(inst.compute_trajectory(0, 0).duration)

    return run


def _interleaved(calls: dict[str, Callable[[], Any]], runs: int) -> dict[str, Any]:
    """Each call once untimed, then ``runs`` rounds of one timed call each, in turn."""
    out = {name: fn() for name, fn in calls.items()}
    times: dict[str, list[float]] = {name: [] for name in calls}
    for _ in range(runs):
        for name, fn in calls.items():
            t, out[name] = time_calls(fn, 1)
            times[name].append(float(t[0]))
    return {"median_s": {k: float(np.median(v)) for k, v in times.items()}, "results": out}


def _slope(points: list[int], seconds: list[float], low: int = 2000) -> float:
    keep = [k for k, n in enumerate(points) if n >= low]
    x = np.log([points[k] for k in keep])
    return float(np.polyfit(x, np.log([seconds[k] for k in keep]), 1)[0])


def scaling_case(runs: int, points: tuple[int, ...]) -> dict[str, Any]:
    """Case 5: the default planner against toppra (and the LP, and with jerk) by grid size."""
    curve = spiral(1.0)
    rows: list[dict[str, Any]] = []
    for n in track(points, description="scaling"):
        row: dict[str, Any] = {"grid_points": n}
        for label, vmax in (("speed_norm", VMAX), ("acceleration_only", 100.0)):
            calls: dict[str, Callable[[], Any]] = {
                "ours": lambda v=vmax, k=n: plan_speed(curve, v, AMAX, None, n=k)
            }
            peer = _toppra_solver(curve, n, vmax)
            if peer is not None:
                calls["toppra"] = peer
            if n <= LP_MAX_POINTS:
                calls["lp"] = lambda v=vmax, k=n: plan_speed(curve, v, AMAX, None, n=k, method="lp")
            got = _interleaved(calls, runs)
            med, res = got["median_s"], got["results"]
            entry: dict[str, Any] = {"median_s": med, "ours_duration_s": res["ours"].duration,
                                     "ours_method": res["ours"].method}  # fmt: skip
            if "toppra" in med:
                entry["toppra_duration_s"] = res["toppra"]
                entry["time_ratio_ours_over_toppra"] = med["ours"] / med["toppra"]
                entry["duration_ratio_ours_over_toppra"] = res["ours"].duration / res["toppra"]
            if "lp" in med:
                entry["lp_duration_s"] = res["lp"].duration
                entry["duration_ratio_ours_over_lp"] = res["ours"].duration / res["lp"].duration
                entry["time_ratio_lp_over_ours"] = med["lp"] / med["ours"]
            row[label] = entry
        row["jerk_on"] = jerk_on(curve, n, runs, row["speed_norm"]["median_s"]["ours"])
        rows.append(row)
    ns = [r["grid_points"] for r in rows]
    slopes = {
        f"{label}_{who}": _slope(ns, [r[label]["median_s"][who] for r in rows])
        for label in ("speed_norm", "acceleration_only")
        for who in ("ours", "toppra")
        if all(who in r[label]["median_s"] for r in rows)
    }
    return {"id": "scaling", "goals": SCALE_GOALS, "rows": rows, "loglog_slope_2000_up": slopes}


def jerk_on(curve: Any, n: int, runs: int, jerk_off_s: float) -> dict[str, Any]:
    """The jerk-limited plan by the banded interior point and (to LP_JERK_MAX_POINTS) the LP
    and the warm-started LP."""
    calls: dict[str, Callable[[], Any]] = {
        "banded": lambda: plan_speed(curve, VMAX, AMAX, JMAX, n=n, method="banded")
    }
    if n <= LP_JERK_MAX_POINTS:
        calls["lp"] = lambda: plan_speed(curve, VMAX, AMAX, JMAX, n=n, method="lp")
        calls["warm"] = lambda: plan_speed(curve, VMAX, AMAX, JMAX, n=n, method="warm")
    got = _interleaved(calls, runs)
    med, res = got["median_s"], got["results"]
    auto = "banded" if n >= BANDED_FROM_POINTS else "warm"
    entry: dict[str, Any] = {
        "median_s": med,
        "duration_s": {k: v.duration for k, v in res.items()},
        "lp_solves": {k: v.lp_solves for k, v in res.items()},
        "auto": auto,
        "over_jerk_off": med[auto] / jerk_off_s if auto in med else None,
        "banded_over_jerk_off": med["banded"] / jerk_off_s,
    }
    if "lp" in med:
        entry["time_ratio_banded_over_lp"] = med["banded"] / med["lp"]
        entry["duration_ratio_banded_over_lp"] = res["banded"].duration / res["lp"].duration
        entry["time_ratio_warm_over_lp"] = med["warm"] / med["lp"]
        entry["duration_ratio_warm_over_lp"] = res["warm"].duration / res["lp"].duration
    return entry


def print_summary(out: dict[str, Any]) -> None:
    for e in out["cases"]:
        if e["id"] == "scaling":
            print_scaling(e)
        elif e["id"].startswith("lp_first_jerk"):
            print(f"{e['id']:<44} highspy {1e3 * e['highspy']['median_s']:8.1f} ms")
        elif e["id"].startswith("lp_"):
            print(
                f"{e['id']:<44} linprog {1e3 * e['linprog']['median_s']:8.1f} ms  highspy "
                f"{1e3 * e['highspy']['median_s']:8.1f} ms  "
                f"x{e['speedup_linprog_over_highspy']:.1f}"
            )
        elif e["id"].startswith("plan_"):
            print(
                f"{e['id']:<44} {1e3 * e['timing']['median_s']:8.1f} ms  duration "
                f"{e['duration_s']:.3f} s  max_excess {e['max_excess']:.4f}  "
                f"LPs {e['lp_solves']} ({1e3 * e['lp_time_per_solve_s']:.1f} ms each)"
            )
        else:
            print(
                f"{e['id']:<44} toppra {1e3 * e['toppra']['median_s']:8.1f} ms  ours "
                f"{1e3 * e['ours']['median_s']:8.1f} ms  duration ratio "
                f"{e['duration_ratio_ours_over_toppra']:.5f}  time ratio "
                f"{e['time_ratio_toppra_over_ours']:.2f}"
            )


def print_scaling(case: dict[str, Any]) -> None:
    """One line per grid size: ours and toppra, both cases; jerk on."""
    for r in case["rows"]:
        line = f"n={r['grid_points']:>6}"
        for label in ("speed_norm", "acceleration_only"):
            e = r[label]
            line += f"  {label}: ours {e['median_s']['ours']:.3f} s"
            if "toppra" in e["median_s"]:
                ratio = e["time_ratio_ours_over_toppra"]
                line += f" toppra {e['median_s']['toppra']:.3f} s (x{ratio:.2f})"
            if "lp" in e["median_s"]:
                line += f" lp {e['median_s']['lp']:.3f} s"
        if "jerk_on" in r:
            j = r["jerk_on"]
            line += f"  jerk on: banded {j['median_s']['banded']:.3f} s"
            if "lp" in j["median_s"]:
                line += f" lp {j['median_s']['lp']:.3f} s warm {j['median_s']['warm']:.3f} s"
            line += f" (auto = {j['auto']}: x{j['over_jerk_off'] or float('nan'):.1f} jerk off)"
        print(line)
    print(f"log-log slopes from 2,000 points: {case['loglog_slope_2000_up']}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="3 timed runs per measurement")
    parser.add_argument("--out", type=Path, default=None, help="JSON output path")
    parser.add_argument(
        "--scaling-only", action="store_true", help="only case 5 (merged into the JSON)"
    )
    args = parser.parse_args(argv)
    runs = 3 if args.quick else MIN_RUNS
    out_path: Path = args.out or (QUICK_RESULTS if args.quick else RESULTS)
    wall = time.perf_counter()
    entries: list[dict[str, Any]] = []
    points = SCALE_POINTS[:3] if args.quick else SCALE_POINTS
    with threadpool_limits(limits=1):
        blas = threadpool_info()
        if args.scaling_only:
            return _scaling_only(out_path, runs, points)
        entries.append(scaling_case(SCALE_RUNS if not args.quick else 1, points))
        for grid in ("adaptive", "uniform"):
            entries += lp_cases(spiral(1.0), runs, grid)
        for delta in DELTAS:
            entries += plan_case(spiral(delta), delta, runs)
        top = toppra_case(spiral(1.0), runs)
        if top is not None:
            entries.append(top)
    out = {
        "schema": 1,
        "generated_utc": datetime.now(UTC).isoformat(timespec="seconds"),
        "quick": bool(args.quick),
        "total_wall_s": time.perf_counter() - wall,
        "machine": machine_info(("scipy", "highspy", "toppra")),
        "blas_threads_pinned_to": 1,
        "blas": blas,
        "problem": {"n": N, "vmax": VMAX, "amax": AMAX, "jmax": JMAX, "deltas": DELTAS},
        "targets": TARGETS,
        "cases": entries,
    }
    out_path.parent.mkdir(parents=True, exist_ok=True)
    out_path.write_text(json.dumps(jsonable(out), indent=2) + "\n")
    print_summary(out)
    print(f"wrote {out_path} in {out['total_wall_s']:.1f} s")
    return 0


def _scaling_only(out_path: Path, runs: int, points: tuple[int, ...]) -> int:
    """Case 5 alone, replacing its entry in an existing results file."""
    case = scaling_case(min(runs, SCALE_RUNS), points)
    out = json.loads(out_path.read_text()) if out_path.exists() else {"schema": 1, "cases": []}
    out["cases"] = [c for c in out["cases"] if c.get("id") != "scaling"] + [case]
    out["scaling_generated_utc"] = datetime.now(UTC).isoformat(timespec="seconds")
    out["scaling_machine"] = machine_info(("scipy", "highspy", "toppra"))
    out_path.write_text(json.dumps(jsonable(out), indent=2) + "\n")
    print_scaling(case)
    print(f"wrote {out_path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
