"""The studio's pre-plan estimate against the planned flight: the ratio's distribution.

For bundled characters (the first of ``BENCHMARK_HANZI``), a typed word and a few
drawings, at the limits 1x, 5x and 20x (speed / acceleration / jerk 1/2/10, 5/10/100
and 20/50/1000, the studio's defaults raised), each request is estimated
(:func:`skyquill.studio.estimate.estimate`: no solve) and planned as the studio plans
it (:func:`skyquill.studio.planner.run_plan` without the simulated flight), and
``planned / estimated`` is recorded with the planner's timing stretch. The estimate
is the planner's first timing, so the ratio is the stretch the planner needed: 1 when
none. Results: ``bench/results/studio_estimate.json``.

    .venv/bin/python bench/studio_estimate.py [--quick]
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path
from typing import Any

from rich.progress import track
from threadpoolctl import threadpool_limits

from common import jsonable, machine_info
from skyquill.strokes.hanzi import BENCHMARK_HANZI
from skyquill.studio.estimate import estimate
from skyquill.studio.models import PlanRequest
from skyquill.studio.planner import run_plan

RESULTS = Path(__file__).parent / "results" / "studio_estimate.json"
QUICK_RESULTS = Path(__file__).parent / "results" / "studio_estimate_quick.json"
#: The limits raised 1x, 5x and 20x: (vmax, amax, jmax).
LIMITS = {"1x": (1.0, 2.0, 10.0), "5x": (5.0, 10.0, 100.0), "20x": (20.0, 50.0, 1000.0)}
#: Drawings as the page sends them (canvas px, y up).
DRAWINGS: dict[str, list[list[list[float]]]] = {
    "cross": [[[100, 280], [460, 280]], [[280, 100], [280, 460]]],
    "V and bar": [
        [[112, 420], [196, 280], [280, 140], [364, 280], [448, 420]],
        [[140, 308], [280, 325], [420, 308]],
    ],
    "zigzag": [[[60, 100], [160, 460], [260, 100], [360, 460], [460, 100]]],
    "square": [[[100, 100], [460, 100], [460, 460], [100, 460], [100, 100]]],
}


def requests(quick: bool) -> list[tuple[str, dict[str, Any]]]:
    """What is measured: characters, a word, drawings."""
    chars = BENCHMARK_HANZI[: 3 if quick else 12]
    out: list[tuple[str, dict[str, Any]]] = [(c, {"text": c}) for c in chars]
    out.append(("Hi", {"text": "Hi"}))
    out += [(name, {"strokes": s}) for name, s in DRAWINGS.items()][: 2 if quick else None]
    return out


def measure(name: str, body: dict[str, Any], limits: str) -> dict[str, Any]:
    """One request estimated and planned: the two durations and their ratio."""
    vmax, amax, jmax = LIMITS[limits]
    request = PlanRequest.model_validate(body | {"vmax": vmax, "amax": amax, "jmax": jmax})
    request = request.model_copy(update={"fly": False})
    start = time.perf_counter()
    guess = estimate(request)
    estimate_s = time.perf_counter() - start
    start = time.perf_counter()
    output = run_plan(request, progress=lambda *_, **__: None, file_url=str, plan_id="0123456789ab")
    planned = output.result.duration_s
    return {
        "input": name,
        "limits": limits,
        "estimated_s": guess.flight_time_s,
        "planned_s": planned,
        "ratio": planned / guess.flight_time_s,
        "estimate_wall_s": estimate_s,
        "plan_wall_s": time.perf_counter() - start,
    }


def summarise(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Per limits: the ratio's min, median, max and the share within a factor 2."""
    out = {}
    for limits in LIMITS:
        ratios = [r["ratio"] for r in rows if r["limits"] == limits]
        out[limits] = {
            "n": len(ratios),
            "ratio_min": min(ratios),
            "ratio_median": statistics.median(ratios),
            "ratio_max": max(ratios),
            "within_2x": sum(0.5 <= r <= 2.0 for r in ratios) / len(ratios),
        }
    every = [r["ratio"] for r in rows]
    out["all"] = {
        "n": len(every),
        "ratio_min": min(every),
        "ratio_median": statistics.median(every),
        "ratio_max": max(every),
        "within_2x": sum(0.5 <= r <= 2.0 for r in every) / len(every),
        "estimate_wall_s_max": max(r["estimate_wall_s"] for r in rows),
    }
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    opts = parser.parse_args()
    cases = [(n, b, lim) for n, b in requests(opts.quick) for lim in LIMITS]
    with threadpool_limits(1):
        rows = [measure(*case) for case in track(cases, description="estimate vs plan")]
    result = {
        "what": __doc__.split("\n\n")[1].replace("\n", " "),
        "machine": machine_info(("scipy", "piqp", "clarabel", "threadpoolctl")),
        "summary": summarise(rows),
        "cases": rows,
    }
    (QUICK_RESULTS if opts.quick else RESULTS).write_text(
        json.dumps(jsonable(result), indent=2, ensure_ascii=False) + "\n", encoding="utf-8"
    )
    print(json.dumps(jsonable(result["summary"]), indent=2))


if __name__ == "__main__":
    main()
