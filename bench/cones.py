"""Exact norm limits (second-order cones) against inscribed polytopes.

Run from the repository root::

    .venv/bin/python bench/cones.py           # full run, a few minutes
    .venv/bin/python bench/cones.py --quick   # smoke test -> bench/results/cones_quick.json

It writes ``bench/results/cones.json`` and prints one table per problem. BLAS
is pinned to one thread (``threadpoolctl.threadpool_limits(1)``) for the whole
run. Each problem is solved with its speed, acceleration and jerk norms held
three ways (docs/architecture.md, "The meaning of each limit"):

* ``cone``: ``NormLimit(sides=None)``, one second-order cone per derivative
  hull point, Clarabel;
* ``globe8`` / ``globe16``: ``NormLimit(sides=8 / 16)``, the polyhedron
  inscribed in the ball (32 / 128 facets; its largest inner ball is 0.863 /
  0.963 of the radius), the default QP backend (PIQP).

Per variant: the cost, the solve time (``solve(problem)``, median over
repeats, 2 warm-up calls, collector off), the dense check's largest excess,
and the shortest feasible duration: bisection on a factor that scales all
times (samples or waypoint times, and the duration) together, the tightest
factor at which ``solve`` does not raise ``InfeasibleError``. The ball
contains every inscribed polytope, so the cone's cost and shortest duration
can only be lower or equal; the JSON says by how much.

Problems:

1. ``helix_fit_1e3``: bench/engine.py case 1 (a 1 m helix, 1 turn, 0.5 m
   rise, 10 s, 1,000 samples, 1 cm noise, ``default_rng(0)``; degree 5, jerk
   cost, point weight 1e4, rest to rest, 100 spans) with the three norms at
   0.7 x the unconstrained fit's peak norms.
2. ``waypoints_6``: 6 waypoints in a 10 m cube (``default_rng(1)``), rest to
   rest, passing through every waypoint at the times of
   ``allocate_segment_times(wp, vmax=2, amax=2)``; degree 5, jerk cost, 8
   spans per segment; norms vmax = 2 m/s, amax = 2 m/s^2, jmax = 4 m/s^3. The
   costs are compared at 1.05 x the slowest variant's shortest scale (where
   all are feasible).
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Callable
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from rich.console import Console
from rich.table import Table
from threadpoolctl import threadpool_info, threadpool_limits

from common import jsonable, machine_info, time_calls, time_stats
from skyquill.errors import InfeasibleError, SolverError
from skyquill.limits import NormLimit, VehicleLimits
from skyquill.optimize import (
    Boundary,
    FitResult,
    Interpolation,
    PointDeviation,
    SmoothingProblem,
    solve,
)
from skyquill.optimize.timing import allocate_segment_times

RESULTS = Path(__file__).resolve().parent / "results" / "cones.json"
QUICK_RESULTS = RESULTS.with_name("cones_quick.json")
VARIANTS: dict[str, int | None] = {"cone": None, "globe8": 8, "globe16": 16}
WARMUP = 2
#: Timed runs: about this much wall time per measurement, within [MIN_RUNS, MAX_RUNS].
BUDGET_S = 3.0
MIN_RUNS, MAX_RUNS = 5, 30
BISECTION_STEPS = 10
LIMIT_FRACTION = 0.7

#: A problem: the time scale -> the SmoothingProblem for given limits.
Builder = Callable[[float, VehicleLimits, int | None], SmoothingProblem]


@dataclass(frozen=True)
class Case:
    """One benchmark problem."""

    id: str
    what: str
    build: Builder
    limits: VehicleLimits
    #: Time scale at which costs are compared; None: 1.05 x the slowest
    #: variant's shortest scale. A soft fit has no shortest duration worth the
    #: name (it cuts corners instead), so it is not bisected.
    cost_scale: float | None
    bisect: bool = True


def helix_case() -> Case:
    """bench/engine.py case 1 with norm limits at 0.7 x the free fit's peaks."""
    n, duration = 1_000, 10.0
    t = np.linspace(0.0, duration, n)
    u = t / duration
    s = 10 * u**3 - 15 * u**4 + 6 * u**5
    angle = 2 * np.pi * s
    p = np.column_stack([np.cos(angle), np.sin(angle), 0.5 * s])
    p += 0.01 * np.random.default_rng(0).standard_normal(p.shape)

    def build(scale: float, vl: VehicleLimits, sides: int | None) -> SmoothingProblem:
        return SmoothingProblem(
            dim=3,
            degree=5,
            n_ctrl=105,
            duration=duration * scale,
            smoothness={3: 1.0},
            deviations=(PointDeviation(t * scale, p, 1e4),),
            boundary=Boundary.rest(p[0], p[-1], 3),
            limits=vl.derivative_limits(3, sides=sides),
        )

    free = solve(build(1.0, VehicleLimits(), None)).trajectory
    peaks = [
        float(np.linalg.norm(x, axis=1).max()) for x in free.dense_derivatives([1, 2, 3]).values()
    ]
    limits = VehicleLimits(*(LIMIT_FRACTION * x for x in peaks))
    return Case(
        "helix_fit_1e3",
        "noisy 3-D helix, 1,000 samples, 100 spans; norms at 0.7 x the free fit's peaks",
        build,
        limits,
        1.0,
        bisect=False,
    )


def waypoint_case() -> Case:
    """Rest to rest through 6 random waypoints under tight norm limits."""
    wp = np.random.default_rng(1).uniform(0.0, 10.0, (6, 3))
    return _through(
        "waypoints_6",
        "rest to rest through 6 waypoints in a 10 m cube, 40 spans; vmax 2, amax 2, jmax 4",
        wp,
        8,
    )


def helix_path_case() -> Case:
    """Rest to rest through 21 points of a climbing helix (a fixed path)."""
    s = np.linspace(0.0, 1.0, 21)
    wp = np.column_stack([np.cos(2 * np.pi * s), np.sin(2 * np.pi * s), 2.0 * s])
    return _through(
        "helix_path_21",
        "rest to rest through 21 points of a 1 m helix rising 2 m, 80 spans; vmax 2, amax 2, "
        "jmax 4",
        wp,
        4,
    )


def _through(name: str, what: str, wp: np.ndarray, spans_per_segment: int) -> Case:
    """Pass through every waypoint at ``allocate_segment_times(wp, 2, 2)``, rest to rest."""
    times = allocate_segment_times(wp, vmax=2.0, amax=2.0)
    spans = spans_per_segment * (wp.shape[0] - 1)

    def build(scale: float, vl: VehicleLimits, sides: int | None) -> SmoothingProblem:
        return SmoothingProblem(
            dim=3,
            degree=5,
            n_ctrl=spans + 5,
            duration=float(times[-1]) * scale,
            smoothness={3: 1.0},
            interpolation=(Interpolation(times[1:-1] * scale, wp[1:-1]),),
            boundary=Boundary.rest(wp[0], wp[-1], 3),
            limits=vl.derivative_limits(3, sides=sides),
        )

    return Case(name, what, build, VehicleLimits(2.0, 2.0, 4.0), None)


def shortest_scale(
    case: Case, sides: int | None, steps: int, cone: dict[str, Any] | None = None
) -> dict[str, Any]:
    """Tightest time-scale factor at which ``solve`` succeeds, by bisection.

    The cone is bracketed by doubling / halving from [0.5, 1] and bisected
    ``steps`` times. A polytope inscribed with fraction ``f`` is bracketed
    without solving: below the cone's infeasible scale it is infeasible too
    (a smaller set), and at the cone's feasible scale divided by ``f`` it is
    feasible (the cone's solution slowed down by ``1 / f`` has every
    derivative norm at most ``f`` times the radius, inside the polytope); it
    is then bisected to the cone's final bracket width. (This also spares
    the slow infeasibility diagnosis of large polytope LPs, ~1 min each.)
    """
    calls = {"feasible": 0, "infeasible": 0, "solver_error": 0}

    def feasible(scale: float) -> bool:
        try:
            solve(case.build(scale, case.limits, sides))
        except InfeasibleError:
            calls["infeasible"] += 1
            return False
        except SolverError:  # near the boundary a backend may fail: counted apart
            calls["solver_error"] += 1
            return False
        calls["feasible"] += 1
        return True

    start = time.perf_counter()
    if cone is None:
        lo, hi = 0.5, 1.0
        while not feasible(hi):
            lo, hi = hi, 2.0 * hi
        while feasible(lo):
            hi, lo = lo, lo / 2.0
        for _ in range(steps):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if feasible(mid) else (mid, hi)
    else:
        width = cone["scale"] - cone["infeasible_below"]
        lo, hi = (
            cone["infeasible_below"],
            cone["scale"] / NormLimit(1, 1.0, sides).inscribed_fraction,
        )
        if not feasible(hi):
            raise RuntimeError(f"{case.id}: {sides}-gon infeasible at {hi:g}, above its bracket")
        while hi - lo > width * (1 + 1e-9):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if feasible(mid) else (mid, hi)
    return {
        "scale": hi,
        "infeasible_below": lo,
        "bisection_wall_s": time.perf_counter() - start,
        "solve_calls": calls,
    }


def timed_solve(problem: SmoothingProblem, quick: bool) -> tuple[dict[str, Any], FitResult]:
    """Solve with warm-up and repeats; timing statistics and the last result."""
    first = time.perf_counter()
    fit = solve(problem)
    once = time.perf_counter() - first
    runs = 3 if quick else int(np.clip(BUDGET_S / max(once, 1e-6), MIN_RUNS, MAX_RUNS))
    for _ in range(WARMUP - 1):
        solve(problem)
    times, fit = time_calls(lambda: solve(problem), runs)
    return time_stats(times, WARMUP), fit


def run_case(case: Case, quick: bool) -> dict[str, Any]:
    """Every variant of ``case``: shortest scale first, then cost and time at a common scale."""
    steps = 6 if quick else BISECTION_STEPS
    shortest: dict[str, dict[str, Any] | None] = dict.fromkeys(VARIANTS)
    if case.bisect:
        cone = shortest["cone"] = shortest_scale(case, None, steps)
        for name, sides in VARIANTS.items():
            if sides is not None:
                shortest[name] = shortest_scale(case, sides, steps, cone)
    scale = case.cost_scale or 1.05 * max(v["scale"] for v in shortest.values() if v is not None)
    variants: dict[str, Any] = {}
    for name, sides in VARIANTS.items():
        timing, fit = timed_solve(case.build(scale, case.limits, sides), quick)
        limit = NormLimit(1, 1.0, sides)
        best = shortest[name]
        base_duration = case.build(1.0, case.limits, sides).duration
        variants[name] = {
            "sides": sides,
            "inscribed_fraction": limit.inscribed_fraction,
            "cost": fit.cost,
            "solved_by": fit.solver,
            "margin": fit.margin,
            "max_excess": fit.verification.max_excess,
            "n_samples_checked": fit.verification.n_samples,
            "n_cones": fit.n_cones,
            "n_inequalities": fit.n_inequalities,
            **timing,
            "shortest_scale": best,
            "shortest_duration_s": best["scale"] * base_duration if best else None,
        }
    cone = variants["cone"]
    for name in VARIANTS:
        if name != "cone":
            v = variants[name]
            v["cost_vs_cone"] = v["cost"] / cone["cost"] - 1.0
            v["time_ratio_vs_cone"] = v["median_s"] / cone["median_s"]
            if case.bisect:
                v["shortest_duration_vs_cone"] = (
                    v["shortest_duration_s"] / cone["shortest_duration_s"] - 1.0
                )
    return {
        "id": case.id,
        "what": case.what,
        "limits": case.limits.as_dict(),
        "cost_compared_at_scale": scale,
        "variants": variants,
        # The cone's infeasible end is below every polytope's feasible end.
        "cone_never_worse": all(
            cone["cost"] <= variants[n]["cost"] * (1 + 1e-6)
            and (
                not case.bisect
                or cone["shortest_scale"]["infeasible_below"]
                <= variants[n]["shortest_scale"]["scale"]
            )
            for n in VARIANTS
            if n != "cone"
        ),
    }


def print_case(console: Console, entry: dict[str, Any]) -> None:
    table = Table(title=f"{entry['id']}: {entry['what']}")
    for col in ("variant", "cost", "vs cone", "median solve", "shortest T", "vs cone", "excess"):
        table.add_column(col, justify="right")
    for name, v in entry["variants"].items():
        table.add_row(
            name,
            f"{v['cost']:.6g}",
            f"{100 * v.get('cost_vs_cone', 0.0):+.2f} %",
            f"{1e3 * v['median_s']:.1f} ms",
            f"{v['shortest_duration_s']:.3f} s" if v["shortest_duration_s"] else "-",
            f"{100 * v['shortest_duration_vs_cone']:+.2f} %"
            if "shortest_duration_vs_cone" in v
            else "-",
            f"{v['max_excess']:.1e}",
        )
    console.print(table)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="3 timed runs, 6 bisection steps")
    parser.add_argument("--out", type=Path, default=None, help="JSON path")
    args = parser.parse_args(argv)
    out_path = args.out or (QUICK_RESULTS if args.quick else RESULTS)
    console = Console()
    with threadpool_limits(limits=1):
        blas = threadpool_info()
        started = datetime.now(UTC).isoformat()
        entries = []
        for make in (helix_case, helix_path_case, waypoint_case):
            entry = run_case(make(), args.quick)
            print_case(console, entry)
            entries.append(entry)
    out = {
        "benchmark": "cones",
        "started_utc": started,
        "machine": machine_info(("scipy", "clarabel", "piqp")),
        "blas": blas,
        "timing": {
            "warmup_runs": WARMUP,
            "runs": "3 (--quick)" if args.quick else f"{MIN_RUNS}-{MAX_RUNS}, ~{BUDGET_S:g} s",
            "bisection_steps": 6 if args.quick else BISECTION_STEPS,
        },
        "problems": entries,
    }
    out_path.parent.mkdir(parents=True, exist_ok=True)
    out_path.write_text(json.dumps(jsonable(out), indent=2) + "\n")
    console.print(f"wrote {out_path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
