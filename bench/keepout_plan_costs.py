"""Where a keep-out field's speed plans spend their time, and four changes measured against it.

Issue 27 asks a field with keep-outs to plan within 2x its outline; ``holes_1_3ha`` plans in
3.4x (``keepout_pieces.py``). This records the full speed plans ``cover`` makes for that
field (``plan_tuned`` as ``keepout_pieces.py`` runs it, here: one process) and re-runs them
alone, one BLAS thread, to split their time:

* ``split``: the whole plans, the banded interior point (the first pseudo-jerk LP, whose
  vertex HiGHS starts from), HiGHS's runs by simplex pivots, the reachability passes and the
  refinement's evaluation of the plan between the nodes.
* ``variants``: the same plans (a) on grids of at most 1,000 points, (b) with refinement
  rounds that are the certification alone (no pseudo-jerk iteration in a round), (c) with
  HiGHS started from the jerk-free optimum's vertex instead of the interior point's answer,
  (d) the pseudo-jerk iteration started from the profile of the tuning's coarse estimate of
  the same path (300 points, no refinement; interpolated, capped by the jerk-free optimum)
  and HiGHS from that profile's vertex, no interior point (the estimates' own time not
  counted: ``cover`` has made them already). Each: its time over the plans' own (medians of
  ``--runs``, each run right after one of the plans as they are) and the flights' change
  (none of them is shipped).

Run: ``.venv/bin/python bench/keepout_plan_costs.py`` -> ``bench/results/keepout_plan_costs.json``
(about two minutes).
"""

from __future__ import annotations

import argparse
import itertools
import json
import time
from collections import defaultdict
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from common import jsonable, machine_info, one_blas_thread
from skyquill.coverage import DEFAULT_MIN_COVERAGE
from skyquill.coverage.plan import CoverageOptions, plan_tuned
from skyquill.coverage.plan import timing as coverage_timing
from skyquill.coverage.regions import load_region
from skyquill.coverage.speed import iteration, plan_speed
from skyquill.coverage.speed import plan as speed_plan
from skyquill.coverage.speed.banded_grid import BandedGrid, row_bounds
from skyquill.coverage.speed.reach import ReachPass
from skyquill.coverage.speed.rows import _end_caps
from skyquill.parallel import Where
from skyquill.solvers import lp as lp_module

FIELD = Path(__file__).resolve().parents[1] / "examples" / "coverage" / "holes_1_3ha.geojson"
RESULTS = Path(__file__).parent / "results" / "keepout_plan_costs.json"
#: Pivot counts by which HiGHS's runs are grouped.
PIVOT_BINS = (0, 1, 10, 50, 200)

Call = tuple[Any, tuple[Any, ...], dict[str, Any]]


def recorded_plans() -> list[Call]:
    """The full speed plans ``cover`` makes for the field: (curve, args, kwargs) each."""
    calls: list[Call] = []
    original = coverage_timing.plan_speed

    def record(curve: Any, *args: Any, **kwargs: Any) -> Any:
        kwargs.pop("deadline", None)
        calls.append((curve, args, kwargs))
        return original(curve, *args, **kwargs)

    coverage_timing.plan_speed = record  # type: ignore[assignment]
    try:
        region = load_region(FIELD)
        plan_tuned(region, CoverageOptions(width=5.0, time_limit=300.0), DEFAULT_MIN_COVERAGE,
                   where=Where(workers=1))  # fmt: skip
    finally:
        coverage_timing.plan_speed = original  # type: ignore[assignment]
    return calls


@contextmanager
def patched(owner: Any, name: str, wrap: Callable[[Any], Any]) -> Iterator[None]:
    original = getattr(owner, name)
    setattr(owner, name, wrap(original))
    try:
        yield
    finally:
        setattr(owner, name, original)


def run_all(calls: list[Call]) -> tuple[float, list[float]]:
    """Wall time of every plan, s, and their flights, s."""
    start = time.perf_counter()
    flights = [float(plan_speed(c, *a, **k).duration) for c, a, k in calls]
    return time.perf_counter() - start, flights


def split(calls: list[Call]) -> dict[str, Any]:
    """The plans' time by where it goes."""
    spent: dict[str, float] = defaultdict(float)
    runs: list[tuple[float, int]] = []

    def timed(key: str) -> Callable[[Any], Any]:
        def wrap(fn: Any) -> Any:
            def inner(*a: Any, **k: Any) -> Any:
                t0 = time.perf_counter()
                try:
                    return fn(*a, **k)
                finally:
                    spent[key] += time.perf_counter() - t0

            return inner

        return wrap

    def highs_run(fn: Any) -> Any:
        def inner(self: Any, *a: Any, **k: Any) -> Any:
            t0 = time.perf_counter()
            status = fn(self, *a, **k)
            runs.append((time.perf_counter() - t0, self.highs.getInfo().simplex_iteration_count))
            return status

        return inner

    with (
        patched(BandedGrid, "_interior", timed("interior_point_s")),
        patched(ReachPass, "solve", timed("reachability_passes_s")),
        patched(iteration, "_interval_excess", timed("refinement_evaluation_s")),
        patched(lp_module._HighsModel, "_run", highs_run),
    ):
        total, _ = run_all(calls)
    seconds = np.array([t for t, _ in runs])
    pivots = np.array([p for _, p in runs])
    edges = (*PIVOT_BINS, np.inf)
    by_pivots = []
    for lo, hi in itertools.pairwise(edges):
        held = (pivots >= lo) & (pivots < hi)
        if held.any():
            by_pivots.append({"pivots": [lo, hi], "runs": int(held.sum()),
                              "seconds": float(seconds[held].sum()),
                              "mean_ms": 1e3 * float(seconds[held].mean())})  # fmt: skip
    return {"plans_s": total, "highs_runs": len(runs), "highs_s": float(seconds.sum()),
            "highs_by_pivots": by_pivots, **spent}  # fmt: skip


def coarser(calls: list[Call]) -> list[Call]:
    return [(c, a, k | {"n": min(k["n"], 1000)}) for c, a, k in calls]


def certification_rounds(fn: Any) -> Any:
    """``_refine`` whose rounds are the certification LP alone (no iteration in a round)."""

    def inner(*a: Any, stop: tuple[int, float], **k: Any) -> Any:
        return fn(*a, stop=(0, stop[1]), **k)

    return inner


def from_the_estimate(estimates: dict[int, tuple[np.ndarray, np.ndarray]]) -> Any:
    """``_initial_solve`` whose pseudo-jerk iteration starts from the estimate's profile
    ``estimates[n]`` (its ``u`` and ``b``) for a grid of ``n`` points, which it hands
    :func:`from_a_guess` too."""

    def wrap(fn: Any) -> Any:
        def inner(lp: Any, bounds: Any, *, c1: Any, jmax: Any, stop: Any, log: Any) -> Any:
            _end_caps(bounds.ub, c1, jmax)
            start = lp.solve(bounds.rows(None), bounds.cols())
            u, b = estimates[start.size]
            guess = np.minimum(np.interp(np.linspace(0.0, 1.0, start.size), u, b), start)
            guess = np.maximum(guess, 1e-3 * start)  # (a reference must be positive)
            lp.guess = guess
            return iteration._pseudo_jerk(lp, bounds, guess, stop=stop, log=log)

        return inner

    return wrap


def from_a_guess(fn: Any) -> Any:
    """``BandedGrid.solve`` that hands HiGHS the vertex of its ``guess`` for the first
    pseudo-jerk LP, no interior point: the last jerk-free answer, unless the caller set
    another since (:func:`from_the_estimate`)."""

    def inner(self: Any, r: Any, ub: Any, *, rough: bool = False) -> Any:
        bound = row_bounds(r, ub.size, self.q)
        jerk_rows = np.any(np.isfinite(bound[2 * self.q :]))
        if self._lp is not None or not self.hand_over or not jerk_rows:
            b = fn(self, r, ub, rough=rough)
            if not jerk_rows:
                self.guess = b
            return b
        self._lp = self._build_lp(self._binding_rows(bound, self.guess))
        return self._lp.solve(r, ub, start=self.guess)

    return inner


def estimated(calls: list[Call]) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Each plan's coarse estimate as the tuning makes it (``u``, ``b``), by grid size
    (:func:`skyquill.coverage.plan.tuning._estimated_duration`)."""
    out = {}
    for curve, args, kwargs in calls:
        coarse = {k: v for k, v in kwargs.items() if k not in ("n", "grid", "control_period")}
        plan = plan_speed(curve, *args, **coarse, n=300, jerk_iterations=3, refine_rounds=0,
                          max_excess=None)  # fmt: skip
        out[kwargs["n"]] = (plan.u, plan.b)
    return out


def _from_estimates(calls: list[Call]) -> tuple[float, list[float]]:
    seconds, flights = 0.0, []
    for call in calls:  # one at a time: the estimate is looked up by the grid's size
        estimate = estimated([call])
        with (
            patched(speed_plan, "_initial_solve", from_the_estimate(estimate)),
            patched(BandedGrid, "solve", from_a_guess),
        ):
            t, f = run_all([call])
        seconds += t
        flights += f
    return seconds, flights


def variants(calls: list[Call], runs: int) -> dict[str, Any]:
    """Each variant's time over the plans' own (each run right after a run of the plans as
    they are, medians of ``runs``) and its flights against theirs."""
    out = {}
    cases: dict[str, Callable[[], tuple[float, list[float]]]] = {
        "grid_at_most_1000": lambda: run_all(coarser(calls)),
        "certification_only_rounds": lambda: _with(
            speed_plan, "_refine", certification_rounds, calls),
        "highs_from_the_jerk_free_vertex": lambda: _with(BandedGrid, "solve", from_a_guess, calls),
        "started_from_the_estimate": lambda: _from_estimates(calls),
    }  # fmt: skip
    for name, run in cases.items():
        pairs = [(run_all(calls), run()) for _ in range(runs)]
        base = float(np.median([b[0] for b, _ in pairs]))
        seconds = float(np.median([v[0] for _, v in pairs]))
        change = np.array(pairs[0][1][1]) / np.array(pairs[0][0][1]) - 1.0
        out[name] = {"time_ratio": seconds / base, "seconds": seconds, "base_seconds": base,
                     "flight_change_median": float(np.median(change)),
                     "flight_change_max": float(change.max()),
                     "flight_change_min": float(change.min())}  # fmt: skip
    return out


def _with(owner: Any, name: str, wrap: Callable[[Any], Any], calls: list[Call]) -> Any:
    with patched(owner, name, wrap):
        return run_all(calls)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    runs = parser.parse_args().runs
    with one_blas_thread():
        calls = recorded_plans()
        run_all(calls)  # warm-up
        base = run_all(calls)
        out = {
            "machine": machine_info(("numpy", "scipy", "highspy")),
            "field": FIELD.name,
            "plans": [{"grid_points": k["n"], "norm_sides": k.get("norm_sides"),
                       "flight_s": f} for (_, _, k), f in zip(calls, base[1], strict=True)],
            "plans_s": base[0],
            "split": split(calls),
            "runs": runs,
            "variants": variants(calls, runs),
        }  # fmt: skip
    print(json.dumps(jsonable({k: out[k] for k in ("plans_s", "split", "variants")}), indent=1))
    RESULTS.write_text(json.dumps(jsonable(out), indent=2) + "\n")


if __name__ == "__main__":
    main()
