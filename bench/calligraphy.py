"""Calligraphy benchmark: planning time and ink fidelity per character, tip against path.

Issue 15: the brush tip is fitted by default (``follow="tip"``); the
vehicle-path mode (``follow="path"``, paper 000) is its peer, run in the same
process on the same character in turn, so the machine's noise falls on both.

Every bundled Make Me a Hanzi character and ``--kanjivg N`` characters of the
``kanjivg`` package's SVGs (a fixed list of common kanji not in the bundled
set; the package is in the dev extra) is planned as ``skyquill write`` plans
it: a 0.5 m horizontal board at 1 m, the vehicle taking off from the ground
1 m in front, default options (limits 1 m/s, 2 m/s^2, 10 m/s^3 as norms,
re-segmentation with the total time fixed). Planning is timed ``--runs``
times, and also without the home (the flight starting and ending at rest
above the first and last stroke: ``plan_writing``'s default, which the
issue's 0.3 s target was measured on); BLAS pinned to one thread with
threadpoolctl, the collector off, one warm-up call first, the median kept.
Each plan is then flown once in the closed-loop simulator over the brush's
contact board, and its ink measured
(:func:`skyquill.calligraphy.ink.measure_ink`: two-sided distance in the
board's plane, ink strokes against input strokes, IoU with the input drawn
at the planned width).

Reported per character and mode: median planning time, writing time, the
plan's own deviation and limit excess, and the simulated ink; per set: the
medians, how many inks are within 1 % of the size and whole, and the writing
time of tip over path. Written to ``bench/results/calligraphy.json``.

Run: ``.venv/bin/python bench/calligraphy.py`` (about 10 minutes);
``--quick`` plans 8 bundled and 5 KanjiVG characters once each and writes
``calligraphy_quick.json`` instead.
"""

from __future__ import annotations

import argparse
import json
import sysconfig
import time
from pathlib import Path
from typing import Any

import numpy as np

from common import gc_off, jsonable, machine_info, one_blas_thread

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results" / "calligraphy.json"
QUICK_RESULTS = ROOT / "bench" / "results" / "calligraphy_quick.json"
TARGET_S = 0.3
#: The ink must lie within this fraction of the character's size (1 %).
INK_TOLERANCE = 0.01
SIZE_M = 0.5
#: Where ``skyquill write`` puts the vehicle's home for one drone (calligraphy.show.layout).
HOME = np.array([0.5 * SIZE_M, -1.0, 0.0])
MODES = ("tip", "path")
#: Common kanji (school grades 1-3), none of them in the bundled hanzi set.
KANJIVG = "語書海話間読朝運動教室電線歌鳥魚船橋漢様親新聞館駅顔曜黒楽園遠"


def kanjivg_dir() -> Path | None:
    """The ``kanji`` folder the ``kanjivg`` package installs, or ``None``."""
    folder = Path(sysconfig.get_paths()["purelib"]) / "kanji"
    return folder if (folder / "06c38.svg").is_file() else None


def inputs(n_bundled: int | None, n_kanjivg: int) -> tuple[list[dict[str, Any]], str | None]:
    """The characters to plan and a note on KanjiVG."""
    from skyquill.strokes.hanzi import BENCHMARK_HANZI

    chars = sorted(BENCHMARK_HANZI)[:n_bundled]
    items = [{"set": "bundled", "char": c, "source": "hanzi"} for c in chars]
    folder = kanjivg_dir()
    if folder is None:
        return items, "the kanjivg package is not installed: no KanjiVG characters"
    for c in KANJIVG[:n_kanjivg]:
        path = folder / f"{ord(c):05x}.svg"
        items.append({"set": "kanjivg", "char": c, "source": "svg", "path": str(path)})
    return items, None


def strokes_of(item: dict[str, Any]) -> Any:
    from skyquill.strokes import hanzi_strokes, load_svg

    return hanzi_strokes(item["char"]) if item["source"] == "hanzi" else load_svg(item["path"])


def plan_timed(
    strokes: Any, follow: str, runs: int, home: np.ndarray | None = HOME
) -> tuple[Any, float]:
    """The mission and the median planning time (s) of ``runs`` calls."""
    from skyquill.calligraphy.board import Board
    from skyquill.calligraphy.mission import WritingOptions, plan_writing

    options = WritingOptions(size_m=SIZE_M, follow=follow)  # type: ignore[arg-type]
    times, mission = [], None
    for _ in range(runs):
        with gc_off():
            start = time.perf_counter()
            mission = plan_writing(strokes, Board(), options, home=home)
            times.append(time.perf_counter() - start)
    return mission, float(np.median(times))


def flown_ink(mission: Any) -> dict[str, Any]:
    """Fly ``mission`` over its contact board; the ink's fidelity (``InkFidelity.as_dict``)."""
    from skyquill.calligraphy.ink import flight_ink
    from skyquill.calligraphy.show import fly_mission

    fidelity = flight_ink(fly_mission(mission), mission)
    assert fidelity is not None  # a horizontal board
    return fidelity.as_dict()


def measure(item: dict[str, Any], runs: int) -> dict[str, Any]:
    """Both modes of one character: planning time, the plan, the simulated ink."""
    strokes = strokes_of(item)
    row: dict[str, Any] = {"set": item["set"], "char": item["char"], "strokes": len(strokes.paths)}
    for follow in MODES:
        mission, median_s = plan_timed(strokes, follow, runs)
        _, hovering_s = plan_timed(strokes, follow, runs, None)
        ink = flown_ink(mission)
        whole = ink["ink_strokes"] == ink["input_strokes"]
        within = ink["max_deviation_m"] is not None
        within = within and ink["max_deviation_m"] <= INK_TOLERANCE * SIZE_M
        row[follow] = {
            "planning_s": median_s,
            "planning_from_hover_s": hovering_s,
            "writing_time_s": mission.trajectory.duration,
            "time_scale": mission.time_scale,
            "deviation_max_m": mission.deviation.max_m,
            "faithful": mission.faithful,
            "max_excess": mission.verification.max_excess,
            "ink": ink,
            "ink_within_tolerance": within,
            "ink_whole": whole,
        }
    row["writing_time_ratio"] = row["tip"]["writing_time_s"] / row["path"]["writing_time_s"]
    row["planning_ratio"] = row["tip"]["planning_s"] / row["path"]["planning_s"]
    return row


def _median(rows: list[dict[str, Any]], key: str, follow: str) -> float:
    return float(np.median([r[follow][key] for r in rows]))


def summarise(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Per set and mode: medians, ink counts, the target check; tip over path."""
    out: dict[str, Any] = {}
    for name in ("bundled", "kanjivg"):
        chosen = [r for r in rows if r["set"] == name]
        if not chosen:
            continue
        entry: dict[str, Any] = {"n_characters": len(chosen)}
        for follow in MODES:
            inks = [r[follow]["ink"] for r in chosen]
            deviations = [i["max_deviation_m"] for i in inks if i["max_deviation_m"] is not None]
            entry[follow] = {
                "median_planning_s": _median(chosen, "planning_s", follow),
                "median_planning_from_hover_s": _median(chosen, "planning_from_hover_s", follow),
                "max_planning_s": float(max(r[follow]["planning_s"] for r in chosen)),
                "median_writing_time_s": _median(chosen, "writing_time_s", follow),
                "all_faithful": all(r[follow]["faithful"] for r in chosen),
                "max_excess": float(max(r[follow]["max_excess"] for r in chosen)),
                "ink_within_tolerance": sum(r[follow]["ink_within_tolerance"] for r in chosen),
                "ink_whole": sum(r[follow]["ink_whole"] for r in chosen),
                "median_ink_max_deviation_m": float(np.median(deviations)),
                "max_ink_max_deviation_m": float(max(deviations)),
                "median_ink_iou": float(np.median([i["iou"] for i in inks])),
            }
        ratios = [r["writing_time_ratio"] for r in chosen]
        entry["writing_time_tip_over_path"] = {
            "median": float(np.median(ratios)),
            "max": float(max(ratios)),
        }
        entry["planning_tip_over_path_median"] = float(
            np.median([r["planning_ratio"] for r in chosen])
        )
        entry["meets_target"] = {
            "from_home": entry["tip"]["median_planning_s"] <= TARGET_S,
            "from_hover": entry["tip"]["median_planning_from_hover_s"] <= TARGET_S,
        }
        out[name] = entry
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--kanjivg", type=int, default=30)
    parser.add_argument("--quick", action="store_true")
    opts = parser.parse_args()
    runs = 1 if opts.quick else opts.runs
    items, note = inputs(8 if opts.quick else None, 5 if opts.quick else opts.kanjivg)
    rows = []
    with one_blas_thread():
        plan_timed(strokes_of(items[0]), "tip", 1)  # warm-up: imports, caches
        for i, item in enumerate(items):
            rows.append(measure(item, runs))
            r = rows[-1]
            print(
                f"{i + 1:3d}/{len(items)} {item['char']} "
                + " ".join(
                    f"{f} {r[f]['planning_s']:.3f} s {r[f]['writing_time_s']:.1f} s ink "
                    f"{1e3 * (r[f]['ink']['max_deviation_m'] or float('nan')):.1f} mm "
                    f"{r[f]['ink']['ink_strokes']}/{r[f]['ink']['input_strokes']} "
                    f"IoU {r[f]['ink']['iou']:.2f} |"
                    for f in MODES
                ),
                flush=True,
            )
    result = {
        "what": (
            "plan_writing per character as `skyquill write` plans it (0.5 m horizontal board, "
            "home on the ground, default options), fitting the brush tip (default) and the "
            "vehicle's path (paper 000) in turn in one process, BLAS pinned to 1 thread, median "
            "planning time; each plan flown once in closed loop over the brush's contact board "
            "and its ink measured (calligraphy.ink)"
        ),
        "runs": runs,
        "target_median_s": TARGET_S,
        "ink_tolerance_m": INK_TOLERANCE * SIZE_M,
        "machine": machine_info(("scipy", "piqp", "clarabel", "threadpoolctl", "shapely")),
        "note": note,
        "summary": summarise(rows),
        "characters": rows,
    }
    (QUICK_RESULTS if opts.quick else RESULTS).write_text(
        json.dumps(jsonable(result), indent=2, ensure_ascii=False) + "\n", encoding="utf-8"
    )
    print(json.dumps(jsonable(result["summary"]), indent=2, ensure_ascii=False))


if __name__ == "__main__":
    main()
