"""Benchmark: time re-segmentation, analytic gradient vs. the paper's finite differences.

Run from the repository root::

    .venv/bin/python bench/resegment.py            # full run, about 1-2 minutes
    .venv/bin/python bench/resegment.py --quick    # smoke test, 3 timed runs, < 30 s

It writes ``bench/results/resegment.json`` (``resegment_quick.json`` with
``--quick``) and prints a table. BLAS is pinned to one thread
(``threadpoolctl.threadpool_limits(1)``) for the whole run. Every timing is
``time.perf_counter`` around one call, 2 warm-up calls first, the garbage
collector off while timing; medians (and p10 / p90) over >= 20 timed runs
for the analytic gradient and >= 5 for finite differences (3 with
``--quick``). Read ratios, not absolute times.

The problem: the hand-drawn spiral of ``examples/spiral.csv`` (400 points
with their drawing times) subsampled evenly to 50 and 200 points, fitted as
in paper 000 §5.2-5.3 / ``skyquill fit``: degree 5, jerk cost, point
deviation weight 1e4, rest to rest (position, velocity, acceleration), knot
interval 0.1 s (``n_ctrl`` fixed from the initial duration). Two routes:

* ``closed_form``: no limits.
* ``qp``: per-axis speed / acceleration / jerk limits at 0.8 / 0.7 / 0.7 of
  the unconstrained fit's maxima (so they are active).

Measured per size and route:

* ``analytic``: :func:`time_gradient` end to end (the solve at the current
  times included, as every finite-difference scheme needs it too), and
  ``analytic_given_solve`` (the gradient from an existing solve: what a
  descent step pays, since the line search already solved there).
* ``solve_only``: one ``solve(make_problem(times))``, for scale.
* ``forward_fd``: paper 000 eq. (56): the base solve plus one solve per
  segment, ``h = 1e-6`` s (the paper's level).
* ``speedup`` = median forward FD / median analytic (end to end).
* Agreement (relative 2-norm error of the analytic gradient) against the
  paper's forward differences and against central differences (``h = 1e-5``
  x mean segment); on the QP route also against central differences of the
  polished cost (:attr:`TimeGradient.polished_cost`), which is what the
  analytic gradient differentiates exactly.
* Full re-segmentation (:func:`resegment`, at most 1000 iterations) in fixed
  mode and in free mode with ``rho = 5 E_jerk / D`` at the initial times (the
  price at which the drawn total time is optimal for the drawn shape along
  pure time scaling), with both first-trial step rules (Barzilai-Borwein and
  doubling): status, iterations, solves, objective and smoothing cost before /
  after, total time before / after, RMS deviation before / after, wall time;
  and the solves the paper's finite-difference descent would need for the
  same iterations.
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import time
from collections.abc import Callable
from datetime import UTC, datetime
from pathlib import Path
from typing import Any, Literal

import numpy as np
from threadpoolctl import threadpool_info, threadpool_limits

from common import machine_info, time_calls, time_stats
from skyquill.io.points import read_points_csv
from skyquill.limits import vehicle_limits
from skyquill.optimize import SmoothingProblem, solve
from skyquill.optimize.resegment import (
    finite_difference_gradient,
    point_fit_factory,
    resegment,
    time_gradient,
)

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results" / "resegment.json"
SPIRAL = ROOT / "examples" / "spiral.csv"
SIZES = (50, 200)
KNOT_INTERVAL = 0.1
DEGREE = 5
WEIGHT = 1e4
WARMUP = 2
BUDGET_S = 1.0
PAPER_STEP_S = 1e-6
CENTRAL_STEP = 1e-5
MAX_ITER = 1000
MODES: tuple[Literal["fixed", "free"], ...] = ("fixed", "free")
STEP_RULES: tuple[Literal["bb", "double"], ...] = ("bb", "double")


# ----------------------------------------------------------------------- timing
def measure(fn: Callable[[], Any], min_runs: int, quick: bool) -> dict[str, Any]:
    """``WARMUP`` calls, then timed calls (about ``BUDGET_S`` of work, >= ``min_runs``)."""
    for _ in range(WARMUP):
        fn()
    start = time.perf_counter()
    fn()
    first = time.perf_counter() - start
    runs = 3 if quick else max(min_runs, min(200, int(BUDGET_S / max(first, 1e-6))))
    return time_stats(time_calls(fn, runs)[0], WARMUP)


# --------------------------------------------------------------------- problems
def spiral(n: int) -> tuple[np.ndarray, np.ndarray]:
    """``n`` points of the drawn spiral, evenly subsampled, times from 0."""
    pts, t = read_points_csv(SPIRAL)
    assert t is not None
    idx = np.linspace(0, pts.shape[0] - 1, n).round().astype(int)
    return pts[idx], t[idx] - t[idx[0]]


def factories(
    pts: np.ndarray, times: np.ndarray
) -> dict[str, tuple[Callable[[np.ndarray], SmoothingProblem], dict[str, float]]]:
    """The two routes' ``make_problem`` and the limits used (empty for the closed form)."""
    n_ctrl = math.ceil(times[-1] / KNOT_INTERVAL) + DEGREE
    free = point_fit_factory(pts, n_ctrl, degree=DEGREE, weight=WEIGHT)
    samples = solve(free(times)).trajectory.sample(1000.0)
    vmax, amax, jmax = (float(np.abs(x).max()) for x in (samples.v, samples.a, samples.j))
    bounds = {"vmax": 0.8 * vmax, "amax": 0.7 * amax, "jmax": 0.7 * jmax}
    limits = vehicle_limits(2, bounds["vmax"], bounds["amax"], bounds["jmax"])
    limited = point_fit_factory(pts, n_ctrl, degree=DEGREE, weight=WEIGHT, limits=limits)
    return {"closed_form": (free, {}), "qp": (limited, bounds)}


def rel_err(a: np.ndarray, b: np.ndarray) -> float:
    """``||a - b|| / ||b||``."""
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


def rms_deviation(pts: np.ndarray, times: np.ndarray, traj: Any) -> float:
    """RMS of ``||p(t_i) - points_i||``, m."""
    err = np.linalg.norm(traj.evaluate(times) - pts, axis=1)
    return float(np.sqrt(np.mean(err**2)))


# ------------------------------------------------------------------------ cases
def gradient_case(
    n: int,
    route: str,
    make: Callable[[np.ndarray], SmoothingProblem],
    times: np.ndarray,
    *,
    bounds: dict[str, float],
    quick: bool,
) -> dict[str, Any]:
    """Time and compare the analytic and finite-difference gradients."""
    grad = time_gradient(times, make)
    result = grad.result
    solve_only = measure(lambda: solve(make(times)), 20, quick)
    analytic = measure(lambda: time_gradient(times, make), 20, quick)
    given = measure(lambda: time_gradient(times, make, result=result), 20, quick)
    step = PAPER_STEP_S / float(np.diff(times).mean())  # h = 1e-6 s absolute

    def forward() -> np.ndarray:
        return finite_difference_gradient(times, make, step=step, scheme="forward")

    fd_timing = measure(forward, 5, quick)
    paper = forward()
    central = finite_difference_gradient(times, make, step=CENTRAL_STEP)
    entry: dict[str, Any] = {
        "id": f"gradient_{route}_{n}",
        "points": n,
        "segments": n - 1,
        "route": route,
        "n_ctrl": result.problem.n_ctrl,
        "limits": bounds,
        "active_rows": grad.n_active,
        "stationarity_residual": grad.stationarity_residual,
        "cost": grad.cost,
        "solve_only": solve_only,
        "analytic": analytic,
        "analytic_given_solve": given,
        "forward_fd": fd_timing,
        "forward_fd_solves": n,
        "speedup": fd_timing["median_s"] / analytic["median_s"],
        "speedup_given_solve": fd_timing["median_s"] / given["median_s"],
        "rel_err_vs_forward_fd_paper": rel_err(grad.grad_segments, paper),
        "rel_err_vs_central_fd": rel_err(grad.grad_segments, central),
        "gradient_norm": float(np.linalg.norm(grad.grad_segments)),
    }
    if route == "qp":
        exact = finite_difference_gradient(times, make, step=CENTRAL_STEP, polished=True)
        entry["rel_err_vs_central_fd_polished"] = rel_err(grad.grad_segments, exact)
        entry["polished_cost"] = grad.polished_cost
        entry["backend_cost_excess_rel"] = (grad.cost - grad.polished_cost) / grad.polished_cost
    return entry


def resegment_case(
    n: int,
    route: str,
    make: Callable[[np.ndarray], SmoothingProblem],
    pts: np.ndarray,
    times: np.ndarray,
    *,
    mode: Literal["fixed", "free"],
    step_rule: Literal["bb", "double"],
    quick: bool,
) -> dict[str, Any]:
    """One full re-segmentation run."""
    start = solve(make(times))
    rho = 0.0
    if mode == "free":
        rho = 5.0 * start.cost_terms["smoothness"] / float(times[-1])
    out = resegment(
        pts,
        times,
        make,
        mode=mode,
        time_penalty=rho,
        max_iter=100 if quick else MAX_ITER,
        step_rule=step_rule,
    )
    return {
        "id": f"resegment_{mode}_{route}_{n}_{step_rule}",
        "points": n,
        "route": route,
        "mode": mode,
        "step_rule": step_rule,
        "max_iter": 100 if quick else MAX_ITER,
        "time_penalty": rho,
        "monotone": bool(np.all(np.diff(out.history) <= 0.0)),
        "status": out.status,
        "iterations": out.iterations,
        "solves": out.n_solves,
        "fd_descent_solves_same_iterations": out.iterations * (n - 1) + out.n_solves,
        "objective_before": float(out.history[0]),
        "objective_after": float(out.history[-1]),
        "cost_before": start.cost,
        "cost_after": out.cost,
        "smoothness_before": start.cost_terms["smoothness"],
        "smoothness_after": out.result.cost_terms["smoothness"],
        "total_time_before_s": float(times[-1]),
        "total_time_after_s": out.total_time,
        "rms_deviation_before_m": rms_deviation(pts, times, start.trajectory),
        "rms_deviation_after_m": rms_deviation(pts, out.times, out.result.trajectory),
        "min_segment_before_s": float(np.diff(times).min()),
        "min_segment_after_s": float(np.diff(out.times).min()),
        "gradient_norm_after": out.gradient_norm,
        "elapsed_s": out.elapsed_s,
        "gradient_time_s": out.gradient_time_s,
        "max_excess": out.result.verification.max_excess,
    }


# ------------------------------------------------------------------------- main
def main(argv: list[str] | None = None) -> int:
    """Run every case and write the JSON."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="3 timed runs, short descents")
    parser.add_argument("--out", type=Path, default=None, help="output JSON path")
    args = parser.parse_args(argv)
    out_path = args.out or (RESULTS.with_name("resegment_quick.json") if args.quick else RESULTS)
    gradients: list[dict[str, Any]] = []
    runs: list[dict[str, Any]] = []
    with threadpool_limits(limits=1):
        blas = threadpool_info()
        for n in SIZES:
            pts, times = spiral(n)
            for route, (make, bounds) in factories(pts, times).items():
                entry = gradient_case(n, route, make, times, bounds=bounds, quick=args.quick)
                gradients.append(entry)
                print(
                    f"gradient {route:11s} N={n:3d}: analytic "
                    f"{1e3 * entry['analytic']['median_s']:8.2f} ms, forward FD "
                    f"{1e3 * entry['forward_fd']['median_s']:8.1f} ms, speed-up "
                    f"{entry['speedup']:6.1f}x; rel. err vs central FD "
                    f"{entry['rel_err_vs_central_fd']:.1e}, vs paper FD "
                    f"{entry['rel_err_vs_forward_fd_paper']:.1e}"
                )
                for mode, rule in itertools.product(MODES, STEP_RULES):
                    run = resegment_case(
                        n, route, make, pts, times, mode=mode, step_rule=rule, quick=args.quick
                    )
                    runs.append(run)
                    print(
                        f"resegment {mode:5s} {rule:6s} {route:11s} N={n:3d}: {run['status']}, "
                        f"{run['iterations']} it, {run['solves']} solves, cost "
                        f"{run['cost_before']:.4g} -> {run['cost_after']:.4g}, time "
                        f"{run['total_time_before_s']:.3f} -> {run['total_time_after_s']:.3f} s, "
                        f"{run['elapsed_s']:.2f} s"
                    )
    out = {
        "generated": datetime.now(UTC).isoformat(timespec="seconds"),
        "quick": args.quick,
        "machine": machine_info(("scipy", "piqp", "clarabel", "threadpoolctl")),
        "blas": blas,
        "timing": {
            "clock": "time.perf_counter",
            "warmup_runs": WARMUP,
            "statistic": "median (p10, p90)",
            "blas_threads": 1,
        },
        "problem": {
            "source": "examples/spiral.csv (hand drawn, 400 points with times)",
            "degree": DEGREE,
            "knot_interval_s": KNOT_INTERVAL,
            "weight": WEIGHT,
            "boundary": "rest to rest (position, velocity, acceleration)",
            "qp_limits": "per-axis speed/acc/jerk at 0.8/0.7/0.7 x the free fit's maxima",
            "paper_fd_step_s": PAPER_STEP_S,
            "central_fd_step_rel": CENTRAL_STEP,
        },
        "gradients": gradients,
        "resegment": runs,
    }
    out_path.parent.mkdir(parents=True, exist_ok=True)
    out_path.write_text(json.dumps(out, indent=2) + "\n", encoding="utf-8")
    print(f"wrote {out_path.relative_to(ROOT) if out_path.is_relative_to(ROOT) else out_path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
