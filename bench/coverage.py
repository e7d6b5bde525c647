"""Coverage benchmark: paper 001 §4 reproduced, time against coverage, a table of shapes.

Issue 5: "Paper 001 §4 reproduced: the 10 m x 10 m square, v_max 3 m/s, a_max
5 m/s², j_max 3 m/s³, coverage diameter 2 m. The paper: spiral 29.3 s, zigzag
34.7 s. Our goal: the spiral in <= 25.0 s at >= 97% coverage. Report time
against coverage (a Pareto plot) for spiral, smoothed zigzag and stop-and-go
zigzag" -- and "regions of several shapes: every pattern plans, covers >= 97%,
and the table says which pattern is faster where"; "the 10 m x 10 m plan end
to end: target <= 0.5 s".

Three parts, all with the paper's limits (per axis) and a 2 m swath:

1. ``paper``: the paper's own construction (homothetic rings, eq. 4 drift) and
   the stop-and-go zigzag, against the paper's 29.3 s and 34.7 s.
2. ``pareto``: every pattern over a grid of the density factor epsilon and the
   corner distance delta; duration against coverage, the non-dominated points
   marked; written to ``bench/results/coverage.png``.
3. ``shapes``: each pattern tuned to >= 97 % coverage (``plan_tuned``: the fastest planned
   flight reaching it) on seven regions; which pattern is fastest on each.
4. ``size_growth`` (issue 16): the default plan (spiral tuned to 99 %, a 5 m
   swath, the norms' defaults) of squares of 1 to 10 ha: planning time against
   path length, and its log-log slope (1 = linear).

The jerk-zigzag (issue 16 part 5: turns that are Ruckig's time-optimal
motions) joins the Pareto study over its own tuning grid (lane spacing,
inset, turn depth; :func:`~skyquill.coverage.jerk_zigzag.tuning_shapes`).

Plus the end-to-end planning time of the default 10 m square plan (median of
5). BLAS is pinned to one thread. Run: ``.venv/bin/python bench/coverage.py``
(``--quick``: parts 1-3 only).
"""

from __future__ import annotations

import itertools
import json
import math
import os
import platform
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from rich.console import Console
from rich.progress import track
from rich.table import Table
from shapely.geometry import LineString, Polygon
from threadpoolctl import threadpool_limits

from skyquill.coverage.jerk_zigzag import (
    AxisLimits,
    plan_jerk_zigzag,
    sampled_path,
    tuning_shapes,
)
from skyquill.coverage.plan import (
    CoverageOptions,
    CoveragePlan,
    coverage_limits,
    plan_coverage,
    plan_tuned,
)
from skyquill.coverage.regions import coverage_fraction, region_from_vertices
from skyquill.errors import SkyquillError
from skyquill.limits import VehicleLimits
from skyquill.verify import verify

RESULTS = Path(__file__).resolve().parent / "results"
PAPER = {"spiral_s": 29.3, "zigzag_s": 34.7}
GOAL = {"spiral_s": 25.0, "coverage": 0.97}
LIMITS = CoverageOptions(
    width=2.0, limits=VehicleLimits(vmax=3.0, amax_axis=5.0, jmax_axis=3.0)
)  # paper 001 §4: per axis
SQUARE = region_from_vertices([[0, 0], [10, 0], [10, 10], [0, 10]])
SHAPES = {
    "square 10 m": SQUARE,
    "long rectangle 30 x 12 m": region_from_vertices([[0, 0], [30, 0], [30, 12], [0, 12]]),
    "triangle 20 m": region_from_vertices([[0, 0], [20, 0], [10, 17.32]]),
    "irregular convex": region_from_vertices(
        [[0, 0], [13, -2], [20, 5], [17, 15], [6, 17], [-2, 10]]
    ),
    "L 12 m": region_from_vertices([[0, 0], [12, 0], [12, 4], [4, 4], [4, 12], [0, 12]]),
    "U 15 x 12 m": region_from_vertices(
        [[0, 0], [15, 0], [15, 12], [11, 12], [11, 4], [4, 4], [4, 12], [0, 12]]
    ),
    "concave field": region_from_vertices(
        [[0, 0], [18, 0], [20, 9], [12, 7], [9, 16], [2, 14], [-2, 7]]
    ),
}
PATTERNS = ("spiral", "zigzag", "zigzag-stop", "zigzag-jerk")
#: Patterns of the epsilon x delta grid (the jerk-zigzag has its own grid).
LP_PATTERNS = ("spiral", "zigzag", "zigzag-stop")
#: Field sizes of the growth study, ha, and its swath, m.
HECTARES = (1.0, 2.5, 5.0, 7.5, 10.0)
GROWTH_WIDTH = 5.0
EPSILONS = (1.0, 0.9, 0.8, 0.7)
DELTAS = (0.15, 0.3, 0.6, 1.0, 1.5, 2.0)


def _row(region: Polygon, options: CoverageOptions) -> dict[str, Any]:
    """One plan's numbers, or its options and the error it raised."""
    try:
        plan = plan_coverage(region, options)
    except SkyquillError as exc:
        return {"pattern": options.pattern, "epsilon": options.epsilon,
                "delta": options.delta, "error": str(exc)}  # fmt: skip
    return _numbers(plan)


def _numbers(plan: CoveragePlan) -> dict[str, Any]:
    """What the results keep of a plan: its options and measured numbers."""
    options = plan.options
    return {
        "pattern": options.pattern,
        "contours": options.contours,
        "drift": options.drift,
        "epsilon": options.epsilon,
        "perimeter": options.perimeter,
        "delta": options.delta,
        "duration_s": plan.duration,
        "coverage": plan.coverage,
        "path_length_m": plan.path_length,
        "max_excess": plan.limits["max_excess"],
        "planning_time_s": plan.planning_time,
    }


def paper_rows() -> list[dict[str, Any]]:
    """The paper's construction (homothetic rings, eq. 4 drift) and the stop-and-go zigzag."""
    rows = [
        _row(SQUARE, replace(LIMITS, contours="homothetic", drift="lap", delta=d)) for d in DELTAS
    ]
    rows.append(_row(SQUARE, replace(LIMITS, pattern="zigzag-stop")))
    return rows


def pareto_rows() -> list[dict[str, Any]]:
    """Every pattern over the epsilon x delta grid on the square."""
    grid = [
        (p, e, d)
        for p, e, d in itertools.product(LP_PATTERNS, EPSILONS, DELTAS)
        if p != "zigzag-stop" or d == DELTAS[0]  # stop-and-go has no corner rounding
    ]
    rows = []
    for pattern, eps, delta in track(grid, description="time vs coverage"):
        options = replace(LIMITS, pattern=pattern, epsilon=eps, delta=delta)  # type: ignore[arg-type]
        row = _row(SQUARE, options)
        if "error" not in row:
            rows.append(row)
    rows += jerk_rows()
    for row in rows:
        row["pareto"] = not any(
            o["pattern"] == row["pattern"]
            and o["duration_s"] <= row["duration_s"]
            and o["coverage"] >= row["coverage"]
            and (o["duration_s"], o["coverage"]) != (row["duration_s"], row["coverage"])
            for o in rows
        )
    return rows


def jerk_rows() -> list[dict[str, Any]]:
    """The jerk-zigzag over its tuning grid on the square (what plan_tuned picks from)."""
    limits = AxisLimits.from_limits(3.0, 5.0, 3.0, per_axis=True)
    rows = []
    for shape in track(tuning_shapes(SQUARE, LIMITS.width), description="jerk-zigzag grid"):
        start = time.perf_counter()
        try:
            flight = plan_jerk_zigzag(SQUARE, shape, limits, LIMITS.altitude)
        except SkyquillError:
            continue
        path = sampled_path(flight.trajectory, limits.vmax)
        if not SQUARE.buffer(1e-9).contains(LineString(path)):
            continue
        check = verify(flight.trajectory, coverage_limits(LIMITS), guaranteed=False)
        rows.append({
            "pattern": "zigzag-jerk", "lane_angle_deg": math.degrees(shape.angle),
            "spacing_m": shape.spacing, "side_inset_m": shape.side_inset,
            "edge_gap_m": shape.edge_gap, "turn_speed_m_s": flight.turn_speed,
            "duration_s": flight.trajectory.duration,
            "coverage": coverage_fraction(SQUARE, path, LIMITS.width),
            "path_length_m": float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum()),
            "max_excess": check.max_excess, "planning_time_s": time.perf_counter() - start,
        })  # fmt: skip
    return rows


def size_rows() -> dict[str, Any]:
    """The default plan's planning time against field size, and the growth's slope."""
    rows = []
    for hectares in track(HECTARES, description="field sizes"):
        side = math.sqrt(hectares * 1e4)
        region = region_from_vertices([[0, 0], [side, 0], [side, side], [0, side]])
        start = time.perf_counter()
        plan = plan_tuned(region, CoverageOptions(width=GROWTH_WIDTH))
        rows.append({
            "hectares": hectares, "side_m": side, "planning_s": time.perf_counter() - start,
            "path_length_m": plan.path_length, "duration_s": plan.duration,
            "coverage": plan.coverage, "max_excess": plan.limits["max_excess"],
        })  # fmt: skip
    x = np.log([r["path_length_m"] for r in rows])
    y = np.log([r["planning_s"] for r in rows])
    return {
        "width_m": GROWTH_WIDTH,
        "options": "defaults (spiral tuned to 99 %, norms 3 m/s, 5 m/s², 3 m/s³)",
        "rows": rows,
        "loglog_slope_planning_vs_path_length": float(np.polyfit(x, y, 1)[0]),
        "s_per_km": [1e3 * r["planning_s"] / r["path_length_m"] for r in rows],
        "loadavg_at_start": list(os.getloadavg()),
    }


def shape_rows() -> list[dict[str, Any]]:
    """Each pattern tuned to >= 97 % coverage on every shape."""
    rows = []
    jobs = list(itertools.product(SHAPES.items(), PATTERNS))
    for (name, region), pattern in track(jobs, description="shapes"):
        base = replace(LIMITS, pattern=pattern)
        try:
            row = _numbers(plan_tuned(region, base, GOAL["coverage"]))
        except SkyquillError as exc:
            row = {"pattern": pattern, "error": str(exc)}
        rows.append({"shape": name, **row})
    for name in SHAPES:
        done = [r for r in rows if r["shape"] == name and "duration_s" in r]
        fastest = min(done, key=lambda r: r["duration_s"]) if done else None
        for r in rows:
            if r["shape"] == name:
                r["fastest"] = fastest is not None and r is fastest
    return rows


def end_to_end_time(runs: int = 5) -> dict[str, float]:
    """Median wall time of the default spiral plan of the square, s."""
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        plan_coverage(SQUARE, LIMITS)
        times.append(time.perf_counter() - start)
    return {"median_s": statistics.median(times), "min_s": min(times), "runs": runs}


def plot(pareto: list[dict[str, Any]], paper: list[dict[str, Any]], path: Path) -> None:
    """Duration against coverage per pattern, Pareto front joined, the paper's points."""
    fig, ax = plt.subplots(figsize=(8, 5.5), layout="constrained")
    for k, pattern in enumerate(PATTERNS):
        pts = [r for r in pareto if r["pattern"] == pattern]
        front = sorted((r for r in pts if r["pareto"]), key=lambda r: r["coverage"])
        color = f"C{k}"
        ax.scatter([100 * r["coverage"] for r in pts], [r["duration_s"] for r in pts],
                   s=14, color=color, alpha=0.35)  # fmt: skip
        ax.plot([100 * r["coverage"] for r in front], [r["duration_s"] for r in front],
                "o-", color=color, label=pattern)  # fmt: skip
    lap = [r for r in paper if r["pattern"] == "spiral"]
    label = "paper's spiral (homothetic, eq. 4 drift)"
    ax.scatter([100 * r["coverage"] for r in lap], [r["duration_s"] for r in lap],
               marker="x", color="C3", label=label)  # fmt: skip
    ax.axhline(PAPER["spiral_s"], color="C3", ls=":", lw=1, label="paper: spiral 29.3 s")
    ax.axhline(PAPER["zigzag_s"], color="C2", ls=":", lw=1, label="paper: zigzag 34.7 s")
    ax.axvline(100 * GOAL["coverage"], color="0.5", ls="--", lw=0.8)
    ax.axhline(GOAL["spiral_s"], color="0.5", ls="--", lw=0.8, label="goal: 25 s at 97 %")
    ax.set_xlabel("coverage (%)")
    ax.set_ylabel("flight time (s)")
    ax.set_title("10 m x 10 m, swath 2 m, v 3 m/s, a 5 m/s², j 3 m/s³ (per axis)")
    ax.legend(fontsize=8)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _print(console: Console, title: str, rows: list[dict[str, Any]], keys: tuple[str, ...]) -> None:
    table = Table(title=title)
    for key in keys:
        table.add_column(key)
    for r in rows:
        table.add_row(
            *(f"{r[k]:.4g}" if isinstance(r.get(k), float) else str(r.get(k, "")) for k in keys)
        )
    console.print(table)


def main() -> None:
    """Run the three parts, print tables, write coverage.json and coverage.png."""
    console = Console()
    quick = "--quick" in sys.argv
    with threadpool_limits(1):
        growth = None if quick else size_rows()
        paper = paper_rows()
        pareto = pareto_rows()
        shapes = shape_rows()
        e2e = end_to_end_time()
    best = [r for r in pareto if r["pattern"] == "spiral" and r["coverage"] >= GOAL["coverage"]]
    fastest_spiral = min(best, key=lambda r: r["duration_s"]) if best else None
    reaching = [r for r in pareto if r["coverage"] >= GOAL["coverage"]]
    fastest = min(reaching, key=lambda r: r["duration_s"]) if reaching else None
    keys = ("pattern", "contours", "drift", "epsilon", "delta", "duration_s", "coverage",
            "path_length_m", "max_excess", "planning_time_s")  # fmt: skip
    _print(console, "paper 001 §4: its construction", paper, keys)
    _print(console, "Pareto front (square)", [r for r in pareto if r["pareto"]], keys)
    _print(console, "shapes, tuned to >= 97 %", shapes, ("shape", "fastest", *keys))
    console.print(f"fastest spiral at >= 97 %: {fastest_spiral}")
    console.print(f"fastest plan at >= 97 %: {fastest}")
    if growth is not None:
        _print(console, "planning time against field size (5 m swath, defaults)",
               growth["rows"], tuple(growth["rows"][0]))  # fmt: skip
        console.print(f"log-log slope: {growth['loglog_slope_planning_vs_path_length']:.2f}")
    console.print(f"end to end (default spiral plan of the square): {e2e}")
    RESULTS.mkdir(exist_ok=True)
    plot(pareto, paper, RESULTS / "coverage.png")
    out = {
        "machine": platform.platform(),
        "limits": {"vmax": 3.0, "amax": 5.0, "jmax": 3.0, "width": 2.0},
        "paper": PAPER,
        "goal": GOAL,
        "paper_construction": paper,
        "pareto": pareto,
        "fastest_spiral_at_goal_coverage": fastest_spiral,
        "fastest_at_goal_coverage": fastest,
        "size_growth": growth,
        "shapes": shapes,
        "end_to_end": e2e,
    }
    (RESULTS / "coverage.json").write_text(json.dumps(out, indent=2) + "\n")
    console.print(f"wrote {RESULTS / 'coverage.json'} and coverage.png")


if __name__ == "__main__":
    main()
