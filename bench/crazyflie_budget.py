"""Crazyflie budget benchmark: every bundled character against 31 pieces per upload.

Issue 14: "A table in bench/results/ and the README: for each bundled
character, pieces and deviation with each way of fitting the budget."

Each bundled Make Me a Hanzi character is planned on a 0.5 m horizontal board
with the default limits (1 m/s, 2 m/s^2, 10 m/s^3 as norms), starting and
ending hovering above the first and last stroke (as bench/calligraphy.py),
tolerance 1 % of the size (5 mm), in four ways:

* ``default``: no target (degree 5, a knot span every 0.05 s). Cut into
  uploads of 31 pieces as they come, the uploads change mid-motion: the
  largest speed at such a cut is reported (the firmware stops and holds there).
* ``one-upload``: ``target_strategies=("one-upload",)``: one degree-7 spline of
  at most 31 knot spans.
* ``split``: ``target_strategies=("split",)``: split at pen-up points into
  uploads flown with 1 s hovers between.
* ``target``: what ``--target crazyflie`` does (one upload if it fits, else
  split), derived from the two runs above: its planning time is the sum when
  the one upload did not fit.

The targeted runs use ``best_effort`` so that a way that does not fit still
reports the deviation it reached (``fits`` false); ``infeasible`` means the
limits could not be met at all. BLAS pinned to one thread; planning times are
medians over :data:`RUNS` runs.

Run: ``.venv/bin/python bench/crazyflie_budget.py`` (~5 min on an idle machine) ->
``bench/results/crazyflie_budget.json``; ``--readme`` prints the README tables,
``--summarize`` recomputes the summary from the stored rows (no planning).
"""

from __future__ import annotations

import argparse
import json
import math
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
from rich.console import Console
from rich.progress import track
from threadpoolctl import threadpool_info, threadpool_limits

from common import jsonable, machine_info
from skyquill.calligraphy.mission import Mission, WritingOptions, plan_writing
from skyquill.errors import InfeasibleError
from skyquill.strokes import Strokes, hanzi_strokes
from skyquill.strokes.hanzi import BENCHMARK_HANZI
from skyquill.targets import CRAZYFLIE, plan_uploads

RESULTS = Path(__file__).resolve().parent / "results" / "crazyflie_budget.json"
RUNS = 3
DEFAULT = WritingOptions()
TARGETED = replace(DEFAULT, target=CRAZYFLIE, best_effort=True)
WAYS: dict[str, WritingOptions] = {
    "one-upload": replace(TARGETED, target_strategies=("one-upload",)),
    "split": replace(TARGETED, target_strategies=("split",)),
}


def _timed(strokes: Strokes, options: WritingOptions) -> tuple[Mission | None, float]:
    """The mission (``None``: infeasible) and the median planning time over RUNS, s."""
    times, mission = [], None
    for _ in range(RUNS):
        start = time.perf_counter()
        try:
            mission = plan_writing(strokes, options=options)
        except InfeasibleError:
            mission = None
        times.append(time.perf_counter() - start)
    return mission, float(np.median(times))


def _common(mission: Mission, plan_s: float) -> dict[str, Any]:
    return {
        "deviation_mm": 1e3 * mission.deviation.max_m,
        "flight_s": mission.trajectory.duration,
        "plan_s": plan_s,
        "max_excess": mission.verification.max_excess,
    }


def _default(strokes: Strokes) -> dict[str, Any]:
    """No target: pieces as they come, uploads of 31, the speed where they change."""
    mission, plan_s = _timed(strokes, DEFAULT)
    assert mission is not None  # the default plans every bundled character
    traj = mission.trajectory
    pieces = len(traj.breakpoints) - 1
    uploads = math.ceil(pieces / CRAZYFLIE.max_pieces)
    cuts = traj.breakpoints[CRAZYFLIE.max_pieces : pieces : CRAZYFLIE.max_pieces]
    speeds = np.linalg.norm(traj.evaluate(cuts, 1), axis=1) if cuts.size else np.zeros(1)
    return {
        "pieces": pieces,
        "uploads": uploads,
        "fits": uploads == 1,
        "max_join_speed_m_s": float(speeds.max()),
        **_common(mission, plan_s),
    }


def _targeted(strokes: Strokes, options: WritingOptions) -> dict[str, Any]:
    mission, plan_s = _timed(strokes, options)
    if mission is None or mission.target is None:
        return {"infeasible": True, "fits": False, "plan_s": plan_s}
    uploads = plan_uploads(mission.trajectory, CRAZYFLIE)  # what the exporter writes
    return {
        "pieces": sum(u.pieces for u in uploads),
        "uploads": len(uploads),
        "max_upload_pieces": max(u.pieces for u in uploads),
        "fits": mission.faithful,
        **_common(mission, plan_s),
    }


def _chosen(one: dict[str, Any], split: dict[str, Any]) -> dict[str, Any]:
    """What ``--target crazyflie`` returns: one upload if it fits, else the split."""
    if one["fits"]:
        return {"strategy": "one-upload", **one}
    return {"strategy": "split", **split, "plan_s": one["plan_s"] + split["plan_s"]}


def _character(char: str) -> dict[str, Any]:
    strokes = hanzi_strokes(char)
    row: dict[str, Any] = {"char": char, "strokes": len(strokes.paths)}
    row["default"] = _default(strokes)
    for way, options in WAYS.items():
        row[way] = _targeted(strokes, options)
    row["target"] = _chosen(row["one-upload"], row["split"])
    return row


def _faithful(entry: dict[str, Any]) -> bool:
    return bool(entry["deviation_mm"] <= 1e3 * DEFAULT.tolerance)


def _summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Counts over all characters; deviation, flight and pieces over the faithful plans."""
    out: dict[str, Any] = {"n_characters": len(rows), "tolerance_mm": 1e3 * DEFAULT.tolerance}
    for way in ("default", "one-upload", "split", "target"):
        entries = [r[way] for r in rows if not r[way].get("infeasible")]
        good = [e for e in entries if _faithful(e)]
        out[way] = {
            "fits": sum(bool(e["fits"]) for e in entries),
            "faithful": len(good),
            "infeasible": len(rows) - len(entries),
            "max_uploads": max(e["uploads"] for e in entries),
            "max_deviation_mm": max(e["deviation_mm"] for e in entries),
            "median_plan_s": float(np.median([r[way]["plan_s"] for r in rows])),
            "max_excess": max(e["max_excess"] for e in entries),
            # Medians over the faithful plans: best effort stretches the others up to 6x.
            "median_pieces": float(np.median([e["pieces"] for e in good])),
            "median_deviation_mm": float(np.median([e["deviation_mm"] for e in good])),
            "median_flight_s": float(np.median([e["flight_s"] for e in good])),
        }
    out["default"]["max_join_speed_m_s"] = max(r["default"]["max_join_speed_m_s"] for r in rows)
    out["target"]["strategies"] = {
        s: sum(r["target"]["strategy"] == s for r in rows) for s in ("one-upload", "split")
    }
    ratio = [r["target"]["flight_s"] / r["default"]["flight_s"] for r in rows]
    out["target"]["median_flight_ratio_to_default"] = float(np.median(ratio))
    return out


def _cell(entry: dict[str, Any]) -> str:
    if entry.get("infeasible"):
        return "infeasible"
    mark = "" if _faithful(entry) else " ✗"
    return f"{entry['pieces']} / {entry['uploads']} / {entry['deviation_mm']:.2f}{mark}"


def readme_tables(data: dict[str, Any]) -> str:
    """The summary table and the per-character table (Markdown) the README quotes."""
    s = data["summary"]
    lines = [
        "| way | fits (31 pieces/upload, within 5 mm, uploads change at rest) "
        "| median pieces | most uploads | median / max deviation (mm) | median flight (s) "
        "| median planning (s) |",
        "|---|---|---|---|---|---|---|",
    ]
    for way in ("default", "one-upload", "split", "target"):
        e = s[way]
        fits = f"{e['fits']} of {s['n_characters']}"
        if way == "default":
            fits += f" (uploads change mid-motion, up to {e['max_join_speed_m_s']:.2f} m/s)"
        elif e["faithful"] < s["n_characters"]:
            fits += f" ({s['n_characters'] - e['faithful']} beyond 5 mm)"
        lines.append(
            f"| {way} | {fits} | {e['median_pieces']:.0f} | {e['max_uploads']} | "
            f"{e['median_deviation_mm']:.2f} / {e['max_deviation_mm']:.2f} | "
            f"{e['median_flight_s']:.1f} | {e['median_plan_s']:.2f} |"
        )
    lines += [
        "",
        "<details><summary>Per character: pieces / uploads / deviation (mm); ✗ beyond 5 mm"
        "</summary>",
        "",
        "| char | strokes | default | one-upload | split | --target crazyflie | flight (s) "
        "default → target |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in data["characters"]:
        t = r["target"]
        lines.append(
            f"| {r['char']} | {r['strokes']} | {_cell(r['default'])} | {_cell(r['one-upload'])} "
            f"| {_cell(r['split'])} | {t['strategy']}: {_cell(t)} | "
            f"{r['default']['flight_s']:.1f} → {t['flight_s']:.1f} |"
        )
    lines += ["", "</details>"]
    return "\n".join(lines)


def main() -> None:
    """Plan every bundled character each way, print the summary, write the JSON."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--readme", action="store_true", help="print the README tables only")
    parser.add_argument(
        "--summarize", action="store_true", help="recompute the summary from the stored rows"
    )
    args = parser.parse_args()
    if args.readme or args.summarize:
        data = json.loads(RESULTS.read_text(encoding="utf-8"))
        if args.summarize:
            data["summary"] = _summary(data["characters"])
            _write(data)
        print(readme_tables(data))
        return
    info = machine_info(("scipy", "clarabel", "threadpoolctl"))
    with threadpool_limits(1):
        blas = threadpool_info()
        rows = [_character(c) for c in track(sorted(BENCHMARK_HANZI), description="characters")]
    data = {
        "machine": info,
        "blas": blas,
        "runs": RUNS,
        "target": {"name": CRAZYFLIE.name, "max_pieces": CRAZYFLIE.max_pieces},
        "summary": _summary(rows),
        "characters": rows,
    }
    _write(data)
    Console().print(data["summary"])


def _write(data: dict[str, Any]) -> None:
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps(jsonable(data), indent=2, ensure_ascii=False) + "\n"
    RESULTS.write_text(text, encoding="utf-8")


if __name__ == "__main__":
    main()
