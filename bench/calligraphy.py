"""Calligraphy benchmark: planning time per character, this tree against a base revision.

Issue 15 (item 3): "median <= 0.3 s per character including re-segmentation,
with the same fidelity", on the bundled characters and on KanjiVG ones.

Every bundled Make Me a Hanzi character, and ``--kanjivg N`` characters of
the ``kanjivg`` package's SVGs (a fixed list of common kanji not in the
bundled set; skipped with a note when the package is not installed), is
planned as a writing mission on a 0.5 m horizontal board with the default
options (limits 1 m/s, 2 m/s^2, 10 m/s^3 as norms), with the default
re-segmentation (total time fixed, 8 gradient steps) and without it
(``resegment="off"``).

Old against new in the same run: the base revision (default :data:`BASE`,
the last commit before the re-use work) is exported with ``git archive``;
two worker processes, one per tree (same interpreter and dependencies),
plan the same character in turn, old then new, ``--runs`` times, so that
the machine's noise falls on both. Each worker pins BLAS to one thread
(threadpoolctl) and times one ``plan_writing`` call with the collector off;
the first call of each worker is a warm-up. Reported per character: median
planning times, the ratio new / old, and how far the two plans are apart
(largest control-point difference relative to the largest coordinate, and
the relative cost difference), with the writing time, the deviation from the
input and the limit excess of the new plan. Written to
``bench/results/calligraphy.json``.

Run: ``.venv/bin/python bench/calligraphy.py`` (about 10 minutes);
``--quick`` plans 8 bundled and 5 KanjiVG characters once each and writes
``calligraphy_quick.json`` instead.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import sysconfig
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from common import export_base, gc_off, jsonable, machine_info

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results" / "calligraphy.json"
QUICK_RESULTS = ROOT / "bench" / "results" / "calligraphy_quick.json"
#: The last commit before the solve re-use of issue 15, item 3.
BASE = "7f8a408"
TARGET_S = 0.3
#: Common kanji (school grades 1-3), none of them in the bundled hanzi set.
KANJIVG = "語書海話間読朝運動教室電線歌鳥魚船橋漢様親新聞館駅顔曜黒楽園遠"


def kanjivg_dir() -> Path | None:
    """The ``kanji`` folder the ``kanjivg`` package installs, or ``None``."""
    folder = Path(sysconfig.get_paths()["purelib"]) / "kanji"
    return folder if (folder / "06c38.svg").is_file() else None


# --- worker: runs inside one tree, answers one request per line -------------------------


def worker() -> None:
    """Plan what each stdin line asks (JSON) and answer with one JSON line."""
    from threadpoolctl import threadpool_limits

    from skyquill.calligraphy.mission import WritingOptions, plan_writing
    from skyquill.strokes import hanzi_strokes, load_svg

    with threadpool_limits(1):
        for line in sys.stdin:
            req = json.loads(line)
            if req["source"] == "hanzi":
                strokes = hanzi_strokes(req["char"])
            else:
                strokes = load_svg(req["path"])
            options = WritingOptions(resegment=req["resegment"])
            with gc_off():
                start = time.perf_counter()
                mission = plan_writing(strokes, options=options)
                elapsed = time.perf_counter() - start
            # the old tree's Mission has one ``fit``; the new one ``fits`` (several uploads)
            fit = mission.fits[0] if hasattr(mission, "fits") else mission.fit
            answer = {
                "time_s": elapsed,
                "control_points": fit.trajectory.control_points.tolist(),
                "cost": fit.cost,
                "writing_time_s": mission.trajectory.duration,
                "deviation_max_m": mission.deviation.max_m,
                "max_excess": fit.verification.max_excess,
                "faithful": mission.faithful,
                "time_scale": mission.time_scale,
                "strokes": len(strokes.paths),
            }
            print(json.dumps(answer), flush=True)


class Worker:
    """A worker process on one source tree."""

    def __init__(self, src: Path) -> None:
        env = os.environ | {"PYTHONPATH": f"{src}{os.pathsep}{ROOT / 'bench'}"}
        self.proc = subprocess.Popen(
            [sys.executable, str(Path(__file__).resolve()), "--worker"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            env=env,
            text=True,
        )

    def ask(self, request: dict[str, Any]) -> dict[str, Any]:
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self.proc.stdin.write(json.dumps(request) + "\n")
        self.proc.stdin.flush()
        answer: dict[str, Any] = json.loads(self.proc.stdout.readline())
        return answer

    def close(self) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.close()
        self.proc.wait()


# --- driver -------------------------------------------------------------------------------


def inputs(n_bundled: int | None, n_kanjivg: int) -> tuple[list[dict[str, Any]], str | None]:
    """The characters to plan (requests without the mode) and a note on KanjiVG."""
    from skyquill.strokes import bundled_hanzi

    chars = sorted(bundled_hanzi())[:n_bundled]
    items = [{"set": "bundled", "char": c, "source": "hanzi"} for c in chars]
    folder = kanjivg_dir()
    if folder is None:
        return items, "the kanjivg package is not installed: no KanjiVG characters"
    for c in KANJIVG[:n_kanjivg]:
        path = folder / f"{ord(c):05x}.svg"
        items.append({"set": "kanjivg", "char": c, "source": "svg", "path": str(path)})
    return items, None


def compare(old: dict[str, Any], new: dict[str, Any]) -> dict[str, float]:
    """How far apart the two plans are (NaN when their shapes differ)."""
    a, b = np.array(old["control_points"]), np.array(new["control_points"])
    if a.shape != b.shape:
        return {"control_points_rel": float("nan"), "cost_rel": float("nan")}
    scale = max(float(np.abs(a).max()), 1e-300)
    return {
        "control_points_rel": float(np.abs(a - b).max()) / scale,
        "cost_rel": abs(new["cost"] - old["cost"]) / abs(old["cost"]),
    }


def measure(workers: dict[str, Worker], item: dict[str, Any], runs: int) -> dict[str, Any]:
    """Both modes of one character, old and new in turn; medians and agreement."""
    row: dict[str, Any] = {"set": item["set"], "char": item["char"]}
    for mode in ("fixed", "off"):
        request = item | {"resegment": mode}
        times: dict[str, list[float]] = {"old": [], "new": []}
        last: dict[str, dict[str, Any]] = {}
        for _ in range(runs):
            for which in ("old", "new"):
                last[which] = workers[which].ask(request)
                times[which].append(last[which]["time_s"])
        key = "with_resegment" if mode == "fixed" else "without_resegment"
        old_s, new_s = float(np.median(times["old"])), float(np.median(times["new"]))
        row[key] = {
            "old_s": old_s,
            "new_s": new_s,
            "ratio": new_s / old_s,
            **compare(last["old"], last["new"]),
        }
        if mode == "fixed":
            new = last["new"]
            row |= {
                k: new[k]
                for k in (
                    "strokes",
                    "writing_time_s",
                    "deviation_max_m",
                    "max_excess",
                    "faithful",
                    "time_scale",
                )
            }
            row["old_writing_time_s"] = last["old"]["writing_time_s"]
            row["old_deviation_max_m"] = last["old"]["deviation_max_m"]
    return row


def summarise(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Medians per set and mode, the target check and the worst disagreement."""
    out: dict[str, Any] = {}
    for name in ("bundled", "kanjivg"):
        chosen = [r for r in rows if r["set"] == name]
        if not chosen:
            continue
        entry: dict[str, Any] = {"n_characters": len(chosen)}
        for key in ("with_resegment", "without_resegment"):
            old = float(np.median([r[key]["old_s"] for r in chosen]))
            new = float(np.median([r[key]["new_s"] for r in chosen]))
            entry[key] = {
                "median_old_s": old,
                "median_new_s": new,
                "median_ratio": float(np.median([r[key]["ratio"] for r in chosen])),
                "max_new_s": float(max(r[key]["new_s"] for r in chosen)),
                "max_control_points_rel": float(max(r[key]["control_points_rel"] for r in chosen)),
                "max_cost_rel": float(max(r[key]["cost_rel"] for r in chosen)),
            }
        entry["meets_target"] = entry["with_resegment"]["median_new_s"] <= TARGET_S
        entry["all_faithful"] = all(r["faithful"] for r in chosen)
        entry["all_zero_excess"] = all(r["max_excess"] <= 1e-9 for r in chosen)
        entry["max_deviation_m"] = max(r["deviation_max_m"] for r in chosen)
        entry["median_writing_time_s"] = float(np.median([r["writing_time_s"] for r in chosen]))
        out[name] = entry
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--base", default=BASE)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--kanjivg", type=int, default=20)
    parser.add_argument("--quick", action="store_true")
    opts = parser.parse_args()
    if opts.worker:
        worker()
        return
    n_bundled = 8 if opts.quick else None
    runs = 1 if opts.quick else opts.runs
    items, note = inputs(n_bundled, 5 if opts.quick else opts.kanjivg)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        workers = {"old": Worker(export_base(opts.base, Path(tmp))), "new": Worker(ROOT / "src")}
        try:
            for which in workers.values():  # warm-up: imports, caches
                which.ask(items[0] | {"resegment": "fixed"})
            for i, item in enumerate(items):
                rows.append(measure(workers, item, runs))
                r = rows[-1]["with_resegment"]
                print(
                    f"{i + 1:3d}/{len(items)} {item['char']} old {r['old_s']:.3f} s "
                    f"new {r['new_s']:.3f} s ratio {r['ratio']:.2f} "
                    f"dC {r['control_points_rel']:.1e}",
                    flush=True,
                )
        finally:
            for which in workers.values():
                which.close()
    result = {
        "what": (
            "plan_writing per character, default options, with and without the default "
            "re-segmentation; old (base) and new tree in turn in two worker processes, "
            "BLAS pinned to 1 thread, medians"
        ),
        "base": opts.base,
        "runs": runs,
        "target_median_s": TARGET_S,
        "machine": machine_info(("scipy", "piqp", "clarabel", "threadpoolctl")),
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
