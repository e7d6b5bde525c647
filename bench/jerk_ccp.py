"""The jerk rows' tangent (the convex-concave procedure) against the damped pseudo-jerk iteration.

A lead for issue 27's "jerk on at most 3x jerk off", measured in session 41, not shipped.
The grid's jerk constraint ``sqrt(b_i) |X_i(b)| <= jmax`` reads, in the LP's rows
(:func:`skyquill.coverage.speed.rows._jerk_matrix`), ``|J_i b| <= h_i(b_i) = sqrt(s_i / b_i)``:
a convex right-hand side. The pseudo-jerk iteration freezes it at a reference
(``|J_i b| <= h_i(ref_i)``), which is not a bound on the true row where ``b_i > ref_i``: its
iterates can break the limit, so it iterates to a fixed point (damped) and ends with a
certification LP. Its tangent instead, ``|J_i b| <= h_i(ref_i) + h_i'(ref_i) (b_i - ref_i)``,
lies below the convex ``h_i``: every answer keeps the true grid rows, and each LP's optimum
is at least the last one's (the convex-concave procedure, a majorisation-minimisation). The
rows then have a coefficient on ``b_i`` that changes with the reference, so they cannot be a
bound change of HiGHS's hot start; the banded interior point rebuilds its rows every solve.

This runs, on the issue's spiral of the 10 m square (per-axis limits, no refinement), the
planner's LP path (``method="lp"``) to its certified plan, and from its certified plan after
one pseudo-jerk iteration, tangent LPs (scipy's HiGHS, solved cold: their times are not
comparable, their counts and answers are) until ``sqrt(b)`` changes by less than the
iteration's own tolerance. Every answer's grid jerk over its limit is recorded.

Then the same in the banded interior point, timed (``method="banded"``, one BLAS thread, one
run after a warm-up): the tangent row ``|J_i b| + c_i b_i <= R_i`` (``c_i b_i >= 0``) is the
pair of symmetric rows ``|(J_i + c_i e_i) b| <= R_i`` and ``|(J_i - c_i e_i) b| <= R_i``
(each one's other side is implied), so the interior point takes it as it is, with ``q`` rows
more per node.

Run: ``.venv/bin/python bench/jerk_ccp.py`` -> ``bench/results/jerk_ccp.json`` (about a
minute).
"""

from __future__ import annotations

import json
import time
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from scipy import sparse
from scipy.optimize import linprog

from common import jsonable, machine_info, one_blas_thread
from coverage_lp import AMAX, JMAX, VMAX, spiral
from skyquill.coverage.speed import plan as speed_plan
from skyquill.coverage.speed.banded import BandedRows, solve_banded_lp
from skyquill.coverage.speed.banded_grid import row_bounds
from skyquill.coverage.speed.profile import _duration

RESULTS = Path(__file__).parent / "results" / "jerk_ccp.json"
GRIDS = (500, 2000, 8000)
#: Grids timed in the banded interior point.
BANDED_GRIDS = (2000, 8000, 32000)
TOLERANCE = 1e-3  # the pseudo-jerk iteration's default jerk_tol
MAX_STEPS = 10


def _certified(
    curve: Any, n: int, iterations: int, method: str = "lp"
) -> tuple[Any, Any, np.ndarray, Any]:
    """The plan by ``method`` after ``iterations`` pseudo-jerk LPs and its certification, the
    grid problem it solved, and the rows' bounds (captured from the planner)."""
    captured: dict[str, Any] = {}
    original = speed_plan._initial_solve

    def capture(lp: Any, bounds: Any, **kw: Any) -> Any:
        out = original(lp, bounds, **kw)
        captured.update(lp=lp, bounds=bounds, b=out[0])
        return out

    speed_plan._initial_solve = capture
    try:
        plan = speed_plan.plan_speed(curve, VMAX, AMAX, JMAX, n=n, method=method, refine_rounds=0,
                                     max_excess=None, jerk_iterations=iterations)  # fmt: skip
    finally:
        speed_plan._initial_solve = original
    return plan, captured["lp"], captured["b"], captured["bounds"]


def _tangent(scale: np.ndarray, b: np.ndarray, ub: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The tangent of each jerk row's bound ``h(b) = sqrt(scale / b)`` at ``b`` (a column at
    0 taken at 1e-12 of the largest bound ``ub``): its value at ``b = 0``, ``1.5 h``, and
    the slope ``-h' = h / (2 b)`` that multiplies ``b_i`` on the row's side."""
    ref = np.maximum(b, 1e-12 * float(ub.max()))
    height = np.sqrt(scale / ref)
    return 1.5 * height, 0.5 * height / ref


def _change(new: np.ndarray, old: np.ndarray) -> float:
    """How far ``sqrt(b)`` moved, relative to its largest: the pseudo-jerk iteration's own
    stop criterion (:data:`TOLERANCE`)."""
    return float(np.max(np.abs(np.sqrt(new) - np.sqrt(old))) / np.sqrt(new).max())


def tangent_steps(n: int) -> dict[str, Any]:
    curve = spiral(1.0)
    full, lp, b_full, bounds = _certified(curve, n, 20)
    first, _, b, _ = _certified(curve, n, 1)
    h = 1.0 / (n - 1)
    a = sparse.csr_array(lp.a)
    n_acc = 2 * bounds.d * (n - 1)
    acc, jerk = a[:n_acc], a[n_acc:]
    r_acc = bounds.rows(None)[:n_acc]
    ub = bounds.cols()
    node = np.tile(np.arange(1, n - 1), bounds.d)  # the node of each jerk row
    scale = bounds.jerk_ref[node]

    def over(x: np.ndarray) -> float:
        """The largest grid jerk over its limit, ``sqrt(b_i / s_i) |J_i b|``."""
        return float(np.max(np.sqrt(x[node] / scale) * np.abs(jerk @ x)))

    steps = []
    for _ in range(MAX_STEPS):
        top, c = _tangent(scale, b[node], ub)
        slope = sparse.csr_array((c, (np.arange(node.size), node)), shape=(node.size, n))
        rows = sparse.vstack([acc, -acc, jerk + slope, -jerk + slope], format="csr")
        bound = np.concatenate([r_acc, r_acc, top, top])
        res = linprog(-np.ones(n), A_ub=rows, b_ub=bound,
                      bounds=np.column_stack([np.zeros(n), ub]), method="highs")  # fmt: skip
        change = _change(res.x, b)
        b = res.x
        steps.append({"duration_s": _duration(b, h, jerk=True), "change": change,
                      "grid_jerk_over_limit": over(b)})  # fmt: skip
        if change < TOLERANCE:
            break
    return {
        "grid_points": n,
        "pseudo_jerk": {"iterations": full.iterations, "lp_solves": full.lp_solves,
                        "duration_s": full.duration, "grid_jerk_over_limit": over(b_full)},
        "one_pseudo_jerk_then_tangents": {"lp_solves_before": first.lp_solves,
                                          "tangent_steps": steps},
        "duration_ratio_tangents_over_pseudo_jerk": steps[-1]["duration_s"] / full.duration,
    }  # fmt: skip


def _tangent_rows(grid: Any, bounds: Any, b: np.ndarray) -> tuple[BandedRows, np.ndarray]:
    """The banded rows and per-node bounds of the tangent LP at ``b``: the acceleration
    rows, then the jerk rows with ``+ c_i b_i``, then with ``- c_i b_i``."""
    rows, q, n = grid.rows, grid.q, b.size
    top, c = _tangent(bounds.jerk_ref, b, bounds.cols())
    slope = np.zeros((q, n))
    slope[:, 1:-1] = c[1:-1]
    acc, jerk = slice(0, 2 * q), slice(2 * q, 3 * q)
    tangent = BandedRows(
        lower=np.vstack([rows.lower[acc], rows.lower[jerk], rows.lower[jerk]]),
        centre=np.vstack([rows.centre[acc], rows.centre[jerk] + slope, rows.centre[jerk] - slope]),
        upper=np.vstack([rows.upper[acc], rows.upper[jerk], rows.upper[jerk]]),
    )
    jerk_bound = np.full((q, n), np.inf)
    jerk_bound[:, 1:-1] = top[1:-1]
    acc_bound = row_bounds(bounds.rows(None), n, q)[acc]
    return tangent, np.vstack([acc_bound, jerk_bound, jerk_bound])


def banded_timing(n: int) -> dict[str, Any]:
    """The banded method to its tolerance against one pseudo-jerk LP, its certification and
    tangent LPs in the same interior point, timed (no refinement)."""
    curve = spiral(1.0)
    _certified(curve, n, 20, "banded")  # warm-up
    start = time.perf_counter()
    full, _, _, _ = _certified(curve, n, 20, "banded")
    full_s = time.perf_counter() - start
    start = time.perf_counter()
    _, grid, b, bounds = _certified(curve, n, 1, "banded")
    ub, steps = bounds.cols(), 0
    while steps < MAX_STEPS:
        rows, bound = _tangent_rows(grid, bounds, b)
        x = solve_banded_lp(rows, bound, ub, np.ones(n)).b
        steps += 1
        change = _change(x, b)
        b = x
        if change < TOLERANCE:
            break
    tangents_s = time.perf_counter() - start
    return {
        "grid_points": n,
        "banded_pseudo_jerk": {"seconds": full_s, "iterations": full.iterations,
                               "duration_s": full.duration},
        "banded_one_then_tangents": {"seconds": tangents_s, "tangent_steps": steps,
                                     "duration_s": _duration(b, 1.0 / (n - 1), jerk=True)},
        "time_ratio_tangents_over_pseudo_jerk": tangents_s / full_s,
    }  # fmt: skip


def main() -> None:
    start = time.perf_counter()
    with one_blas_thread():
        cases = [tangent_steps(n) for n in GRIDS]
        banded = [banded_timing(n) for n in BANDED_GRIDS]
    result = {
        "schema": 1,
        "generated_utc": datetime.now(UTC).isoformat(timespec="seconds"),
        "total_wall_s": time.perf_counter() - start,
        "machine": machine_info(("scipy", "highspy")),
        "cases": cases,
        "banded": banded,
    }
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(json.dumps(jsonable(result), indent=2) + "\n")
    for c in cases:
        pj, steps = c["pseudo_jerk"], c["one_pseudo_jerk_then_tangents"]["tangent_steps"]
        print(f"{c['grid_points']:>6} points: pseudo-jerk {pj['iterations']} iterations "
              f"({pj['lp_solves']} LPs) {pj['duration_s']:.4f} s; one iteration, its "
              f"certification, then {len(steps)} tangent LPs {steps[-1]['duration_s']:.4f} s "
              f"(x{c['duration_ratio_tangents_over_pseudo_jerk']:.5f})")  # fmt: skip
    for c in banded:
        pj, tg = c["banded_pseudo_jerk"], c["banded_one_then_tangents"]
        print(f"{c['grid_points']:>6} points, banded: pseudo-jerk {pj['seconds']:.3f} s "
              f"{pj['duration_s']:.4f} s; one, certification, {tg['tangent_steps']} tangents "
              f"{tg['seconds']:.3f} s {tg['duration_s']:.4f} s "
              f"({c['time_ratio_tangents_over_pseudo_jerk']:.2f}x the time)")  # fmt: skip
    print(f"wrote {RESULTS}")


if __name__ == "__main__":
    main()
