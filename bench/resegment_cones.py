"""Re-segmentation with exact norm limits (cones) against per-axis boxes.

Run from the repository root::

    .venv/bin/python bench/resegment_cones.py           # ~1 minute
    .venv/bin/python bench/resegment_cones.py --quick   # -> resegment_cones_quick.json

It writes ``bench/results/resegment_cones.json`` and prints one line per
case. BLAS is pinned to one thread (``threadpoolctl.threadpool_limits(1)``).
Timings: ``time.perf_counter`` around one call, 2 warm-up calls, collector
off, medians (p10 / p90) over 20 runs for gradients and solves, 5 for plans
(3 each with ``--quick``). Read ratios, not absolute times.

Cases:

* ``spiral50``: the drawn spiral (``examples/spiral.csv``) subsampled to 50
  points, degree 5, jerk cost, weight 1e4, rest to rest, 40 control points;
  limits at 0.8 / 0.7 / 0.7 of the unconstrained fit's peak speed /
  acceleration / jerk, either per-axis boxes (of the per-axis peaks, PIQP)
  or ``NormLimit`` cones (of the peak norms, Clarabel). Per variant: one
  solve, one analytic gradient given the solve (what a descent step pays),
  the active rows / cones, and the gradient's relative error against central
  differences (step 1e-5 x mean segment) of the polished cost.
* ``yong``: :func:`plan_writing` of the strokes of 永 (``hanzi_strokes``)
  with the default options (re-segmentation ``"fixed"``, 8 steps), the limits
  of ``WritingOptions.limits()`` replaced by ``NormLimit`` cones on speed,
  acceleration and jerk; at the default limits (1 / 2 / 10; none active on
  this plan) and at 0.25 / 0.45 / 2.5 (active). Per variant: the plan's wall
  time, the re-segmentation's own time, gradient time and solves, one
  gradient at the final times, the dense check's largest excess.
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from threadpoolctl import threadpool_info, threadpool_limits

import skyquill.calligraphy.planning as planning_module
from common import jsonable, machine_info, time_calls, time_stats
from skyquill.calligraphy.mission import WritingOptions, plan_writing
from skyquill.io.points import read_points_csv
from skyquill.limits import BoxLimit, DerivativeLimit, NormLimit
from skyquill.optimize import SmoothingProblem, solve
from skyquill.optimize.resegment import (
    ResegmentResult,
    finite_difference_gradient,
    point_fit_factory,
    time_gradient,
)
from skyquill.strokes import hanzi_strokes

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results" / "resegment_cones.json"
QUICK_RESULTS = ROOT / "bench" / "results" / "resegment_cones_quick.json"
WARMUP = 2


def _timed(fn: Callable[[], Any], runs: int) -> tuple[dict[str, Any], Any]:
    for _ in range(WARMUP):
        fn()
    times, out = time_calls(fn, runs)
    return time_stats(times, WARMUP), out


def spiral_case(kind: str, runs: int) -> dict[str, Any]:
    pts, t = read_points_csv(ROOT / "examples" / "spiral.csv")
    assert t is not None
    idx = np.linspace(0, pts.shape[0] - 1, 50).round().astype(int)
    pts, times = pts[idx], t[idx] - t[idx[0]]
    sample = solve(point_fit_factory(pts, 40)(times)).trajectory.sample(500.0)
    peaks = [
        (x, 0.8 if order == 1 else 0.7)
        for order, x in ((1, sample.v), (2, sample.a), (3, sample.j))
    ]
    limits: list[DerivativeLimit] = []
    for order, (x, frac) in enumerate(peaks, start=1):
        if kind == "boxes":
            limits.append(
                BoxLimit(order, -frac * np.abs(x).max(axis=0), frac * np.abs(x).max(axis=0))
            )
        else:
            limits.append(NormLimit(order, frac * float(np.linalg.norm(x, axis=1).max()), dim=2))
    make = point_fit_factory(pts, 40, limits=limits)
    solve_stats, result = _timed(lambda: solve(make(times)), runs)
    grad_stats, grad = _timed(lambda: time_gradient(times, make, result=result), runs)
    exact = finite_difference_gradient(times, make, step=1e-5, polished=True)
    error = float(np.linalg.norm(grad.grad_segments - exact) / np.linalg.norm(exact))
    return {
        "case": f"spiral50/{kind}",
        "solver": result.solver,
        "solve": solve_stats,
        "gradient_given_solve": grad_stats,
        "n_active_rows": grad.n_active,
        "n_active_cones": grad.n_active_cones,
        "n_cones": result.n_cones,
        "n_inequalities": result.n_inequalities,
        "gradient_rel_error_vs_central_fd_polished": error,
    }


@dataclass(frozen=True)
class ConeWriting(WritingOptions):
    """The writing options with every limit an exact norm (a cone)."""

    def limits(self) -> tuple[DerivativeLimit, ...]:
        bounds = ((1, self.vmax), (2, self.amax), (3, self.jmax))
        return tuple(NormLimit(order, b, dim=3) for order, b in bounds)


def yong_case(kind: str, bounds: tuple[float, float, float], runs: int) -> dict[str, Any]:
    seen: list[tuple[Callable[[np.ndarray], SmoothingProblem], ResegmentResult]] = []
    original = planning_module.resegment

    def spy(*args: Any, **kwargs: Any) -> ResegmentResult:
        out = original(*args, **kwargs)
        seen.append((args[2], out))
        return out

    kw = dict(zip(("vmax", "amax", "jmax"), bounds, strict=True))
    opts = ConeWriting(**kw) if kind == "cones" else WritingOptions(**kw)
    strokes = hanzi_strokes("永")
    planning_module.resegment = spy  # type: ignore[assignment]
    try:
        plan_stats, mission = _timed(lambda: plan_writing(strokes, options=opts), runs)
    finally:
        planning_module.resegment = original
    make, rr = seen[-1]
    grad_stats, grad = _timed(lambda: time_gradient(rr.times, make, result=rr.result), 3 * runs)
    return {
        "case": f"yong/{kind}/{'/'.join(f'{b:g}' for b in bounds)}",
        "plan": plan_stats,
        "resegment": {
            "status": rr.status,
            "iterations": rr.iterations,
            "n_solves": rr.n_solves,
            "elapsed_s": rr.elapsed_s,
            "gradient_time_s": rr.gradient_time_s,
        },
        "gradient_at_final_times": grad_stats,
        "n_active_rows": grad.n_active,
        "n_active_cones": grad.n_active_cones,
        "duration_s": mission.trajectory.duration,
        "max_excess": mission.verification.max_excess,
        "max_deviation_m": mission.deviation.max_m,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="3 timed runs")
    args = parser.parse_args(argv)
    runs, plan_runs = (3, 3) if args.quick else (20, 5)
    with threadpool_limits(limits=1):
        blas = threadpool_info()
        started = datetime.now(UTC).isoformat()
        entries = [spiral_case(kind, runs) for kind in ("boxes", "cones")]
        for bounds in ((1.0, 2.0, 10.0), (0.25, 0.45, 2.5)):
            entries += [yong_case(kind, bounds, plan_runs) for kind in ("boxes", "cones")]
    for e in entries:
        timing = e.get("plan", e.get("solve"))
        grad = e.get("gradient_given_solve", e.get("gradient_at_final_times"))
        print(
            f"{e['case']:<28} {'plan' if 'plan' in e else 'solve'} "
            f"{1e3 * timing['median_s']:8.1f} ms  gradient {1e3 * grad['median_s']:6.1f} ms  "
            f"active rows {e['n_active_rows']:5d}  cones {e['n_active_cones']:4d}"
        )
    out = {
        "benchmark": "resegment_cones",
        "started_utc": started,
        "machine": machine_info(("scipy", "clarabel", "piqp")),
        "blas": blas,
        "cases": entries,
    }
    path = QUICK_RESULTS if args.quick else RESULTS
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(jsonable(out), indent=2) + "\n")
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
