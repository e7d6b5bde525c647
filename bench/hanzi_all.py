"""Every bundled Chinese character planned as ``skyquill write CHAR`` plans it (issue 17).

All 9,574 characters of hanzi-writer-data 2.0.1 that ship with skyquill
(:func:`skyquill.strokes.bundled_hanzi`) are planned one at a time with the
CLI's default options, read from the signature of ``skyquill write`` itself
(a 0.5 m horizontal board at 1 m, limits 1 m/s, 2 m/s^2, 10 m/s^3, the brush
tip followed, no target, no closed-loop flight), through the same path:
:func:`~skyquill.strokes.typed_strokes` then
:func:`~skyquill.calligraphy.show.plan_show`. A character passes when the plan
is returned and its pen-down deviation (``summary.json``'s
``deviation.max_m``) is within its tolerance (``tolerance_m``, 1 % of the
size); the planner raises ``InfeasibleError`` otherwise.

The characters are spread over at most two worker processes (the machine has
two cores), each with BLAS pinned to one thread (threadpoolctl). Every result
is appended to a JSON-lines file as it arrives (``--resume`` skips the
characters already there; ``--report-only`` writes the report of what it
holds, planning nothing), and the summary is rewritten every
``--flush-every`` characters, marked ``"partial": true`` until all are done,
so an interrupted run still leaves its numbers.

Written to ``bench/results/hanzi_all.json``: the machine, counts passed and
failed, planning time (median, p90, max: wall time per character in a
worker, two workers sharing the machine), the deviation distribution (in mm
and as a fraction of the tolerance), and every failure with its character,
code point, number of strokes and error, grouped by cause.

Run: ``.venv/bin/python bench/hanzi_all.py`` (about 30 minutes on two free
cores: 0.36 s of CPU per character on average; hours on a loaded machine);
``--sample N`` plans N characters drawn with a fixed seed and writes
``hanzi_all_sample.json`` instead.
"""

from __future__ import annotations

import argparse
import inspect
import json
import re
import tempfile
import time
import traceback
from collections import defaultdict
from collections.abc import Iterable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

import numpy as np
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from threadpoolctl import threadpool_info, threadpool_limits

from common import jsonable, machine_info

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results" / "hanzi_all.json"
SAMPLE_RESULTS = ROOT / "bench" / "results" / "hanzi_all_sample.json"
#: One JSON line per character planned, for --resume (not committed).
PROGRESS_FILE = Path(tempfile.gettempdir()) / "skyquill_hanzi_all.jsonl"
#: The test over a sample uses the same seed (tests/strokes/test_hanzi_all_plan.py).
SEED = 17
#: The machine has two cores (and other jobs): never more workers than that.
MAX_WORKERS = 2

#: Why a failure of each cause happens, filled in from the failures the full run found
#: (keys: :func:`cause`). A cause not listed here is reported as "not yet explained".
EXPLANATIONS: dict[str, str] = {}


def cli_options() -> Any:
    """The :class:`WritingOptions` of ``skyquill write CHAR --out DIR`` with every default."""
    from skyquill.cli.write_cmd import default_writing_options

    return default_writing_options()


def cli_show_kwargs() -> dict[str, Any]:
    """``plan_show``'s board arguments as ``skyquill write`` passes them by default."""
    from skyquill.cli.write_cmd import write

    d = {k: p.default for k, p in inspect.signature(write).parameters.items()}
    return {"board_kind": d["board"], "board_height_m": d["board_height"], "lift_m": d["lift"]}


def plan_char(char: str) -> dict[str, Any]:
    """Plan ``char`` as the CLI does; its numbers, or its error."""
    from skyquill.calligraphy.show import plan_show
    from skyquill.strokes import hanzi_strokes, typed_strokes

    medians = hanzi_strokes(char)
    row: dict[str, Any] = {
        "char": char,
        "code_point": f"U+{ord(char):04X}",
        "strokes": len(medians.paths),
        "points": medians.n_points,
    }
    # Every BLAS loaded so far on one thread (threadpoolctl limits only the libraries
    # loaded when it is called; scipy's own comes with the first plan). Not timed.
    threadpool_limits(limits=1)
    start, cpu = time.perf_counter(), time.process_time()
    try:
        show = plan_show([typed_strokes(char)], cli_options(), **cli_show_kwargs())
    except Exception as exc:  # every failure is reported, whatever its kind
        row |= {
            "passed": False,
            "time_s": time.perf_counter() - start,
            "cpu_s": time.process_time() - cpu,
            "error_type": type(exc).__name__,
            "error": str(exc),
        }
        if not type(exc).__module__.startswith("skyquill"):
            row["traceback"] = traceback.format_exc(limit=-4)
        return row
    summary = show.missions[0].summary()
    deviation = summary["deviation"]["max_m"]
    tolerance = summary["tolerance_m"]
    return row | {
        "passed": deviation <= tolerance,
        "time_s": time.perf_counter() - start,
        "cpu_s": time.process_time() - cpu,
        "planning_time_s": summary["planning_time_s"],
        "deviation_m": deviation,
        "tolerance_m": tolerance,
        "faithful": summary["faithful"],
        "max_excess": summary["max_excess"],
        "duration_s": summary["duration_s"],
        "time_scale": summary["time_scale"],
    }


def _pin_blas() -> None:
    """Worker initializer: one BLAS thread per process (two workers on two cores)."""
    threadpool_limits(limits=1)


def cause(row: dict[str, Any]) -> str:
    """A failure's cause: its error type and message with the numbers and character masked."""
    if "error" not in row:
        return "deviation above tolerance (plan returned)"
    message = row["error"].replace(row["char"], "<char>")
    message = re.sub(r"U\+[0-9A-F]{4,5}", "<U+>", message)
    return f"{row['error_type']}: " + re.sub(r"\d[\d.,e+-]*", "#", message)


def characters(sample: int | None, seed: int = SEED) -> list[str]:
    """The sorted bundled set, or ``sample`` of it drawn with ``seed`` (sorted again)."""
    from skyquill.strokes import bundled_hanzi

    chars = sorted(bundled_hanzi())
    if sample is None:
        return chars
    picked = np.random.default_rng(seed).choice(len(chars), size=sample, replace=False)
    return sorted(chars[i] for i in picked)


def _stats(values: Sequence[float]) -> dict[str, Any]:
    if not values:
        return {}
    v = np.asarray(values, dtype=float)
    return {
        "median": float(np.median(v)),
        "p90": float(np.percentile(v, 90)),
        "p99": float(np.percentile(v, 99)),
        "max": float(v.max()),
        "min": float(v.min()),
    }


def failures_by_cause(rows: Iterable[dict[str, Any]]) -> list[dict[str, Any]]:
    """The failed rows grouped by :func:`cause`, the largest group first."""
    groups: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for row in rows:
        if not row["passed"]:
            groups[cause(row)].append(row)
    keep = ("char", "code_point", "strokes", "points", "error_type", "error", "deviation_m")
    out = [
        {
            "cause": key,
            "explanation": EXPLANATIONS.get(key, "not yet explained"),
            "count": len(group),
            "failures": [{k: r[k] for k in keep if k in r} | _trace(r) for r in group],
        }
        for key, group in groups.items()
    ]
    return sorted(out, key=lambda g: -g["count"])


def _trace(row: dict[str, Any]) -> dict[str, Any]:
    return {"traceback": row["traceback"]} if "traceback" in row else {}


def report(
    rows: list[dict[str, Any]], total: int, meta: dict[str, Any], elapsed_s: float
) -> dict[str, Any]:
    """The results file's content for the rows done so far (``total`` asked for)."""
    ok = [r for r in rows if "deviation_m" in r]
    ratio = [r["deviation_m"] / r["tolerance_m"] for r in ok]
    passed = sum(r["passed"] for r in rows)
    return meta | {
        "partial": len(rows) < total,
        "done": len(rows),
        "total": total,
        "passed": passed,
        "failed": len(rows) - passed,
        "wall_time_s": elapsed_s,
        "resumed_rows": meta["resumed_rows"],
        "worker_time_sum_s": float(sum(r["time_s"] for r in rows)),
        "planning_time_s": _stats([r["time_s"] for r in rows]),
        # CPU time of the worker process (one BLAS thread): what one free core would take.
        "planning_cpu_s": _stats([r["cpu_s"] for r in rows if "cpu_s" in r])
        | {"rows": sum("cpu_s" in r for r in rows)},
        "planning_time_note": (
            "wall time of typed_strokes + plan_show per character in a worker, "
            f"{meta['workers']} workers sharing the machine with other jobs (see the load "
            "average); planning_cpu_s is the worker's CPU time, what one free core takes "
            "(rows planned before it was recorded lack it)"
        ),
        "deviation_mm": _stats([1e3 * r["deviation_m"] for r in ok]),
        "deviation_over_tolerance": _stats(ratio)
        | {
            "histogram_edges": [0.0, 0.25, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, np.inf],
            "histogram_counts": np.histogram(
                ratio, bins=[0.0, 0.25, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, np.inf]
            )[0].tolist(),
        },
        "tolerance_mm": sorted({1e3 * r["tolerance_m"] for r in ok}),
        "not_faithful_but_within_tolerance": [r["char"] for r in ok if not r["faithful"]],
        "max_excess": max((r["max_excess"] for r in ok), default=None),
        "strokes": _stats([r["strokes"] for r in rows]),
        "slowest": [
            {k: r[k] for k in ("char", "code_point", "strokes", "time_s")}
            for r in sorted(rows, key=lambda r: -r["time_s"])[:10]
        ],
        "failures_by_cause": failures_by_cause(rows),
    }


def _progress_default(sample: int | None) -> Path:
    """The JSON-lines file of the full run, or of a ``--sample N`` run."""
    return (
        PROGRESS_FILE
        if sample is None
        else PROGRESS_FILE.with_stem(f"{PROGRESS_FILE.stem}_{sample}")
    )


def _read_done(path: Path) -> dict[str, dict[str, Any]]:
    if not path.is_file():
        return {}
    rows = [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines() if line]
    return {r["char"]: r for r in rows}


def _write(path: Path, content: dict[str, Any]) -> None:
    tmp = path.with_suffix(".tmp")
    tmp.write_text(
        json.dumps(jsonable(content), indent=1, ensure_ascii=False) + "\n", encoding="utf-8"
    )
    tmp.replace(path)


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Plan the characters asked for, writing results as they come; the final report."""
    chars = characters(args.sample)
    out = SAMPLE_RESULTS if args.sample is not None else RESULTS
    progress_file = Path(args.progress_file or _progress_default(args.sample))
    done = _read_done(progress_file) if args.resume or args.report_only else {}
    if not (args.resume or args.report_only):
        progress_file.write_text("", encoding="utf-8")
    rows = [done[c] for c in chars if c in done]
    todo = [c for c in chars if c not in done]
    # In a random (fixed) order: a run stopped early has planned a sample of the whole set,
    # not its first code points.
    todo = [todo[i] for i in np.random.default_rng(SEED).permutation(len(todo))]
    workers = min(args.workers, MAX_WORKERS)
    with threadpool_limits(limits=1):
        meta = {
            "benchmark": "every bundled hanzi planned as `skyquill write CHAR` plans it",
            "machine": machine_info(("scipy", "clarabel", "threadpoolctl")),
            "blas_in_worker": [
                {k: i.get(k) for k in ("internal_api", "num_threads", "version")}
                for i in threadpool_info()
            ],
            "workers": workers,
            "sample": args.sample,
            "seed": SEED if args.sample is not None else None,
            "options": repr(cli_options()),
            "show_kwargs": cli_show_kwargs(),
            "resumed_rows": len(rows),
            "pass_rule": "plan returned and summary deviation.max_m <= tolerance_m",
        }
    if args.report_only:
        # No planning: the report of what the progress file holds (partial if not all).
        rows.sort(key=lambda r: r["char"])
        final = report(rows, len(chars), meta | {"report_only": True}, 0.0)
        _write(out, final)
        return final
    start = time.perf_counter()
    with (
        ProcessPoolExecutor(max_workers=workers, initializer=_pin_blas) as pool,
        progress_file.open("a", encoding="utf-8") as log,
        Progress(
            TextColumn("[bold]hanzi"),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn("{task.fields[failed]} failed"),
            TimeElapsedColumn(),
            TimeRemainingColumn(),
        ) as bar,
    ):
        task = bar.add_task("plan", total=len(chars), completed=len(rows), failed=0)
        futures = [pool.submit(plan_char, c) for c in todo]
        for future in as_completed(futures):
            row = future.result()
            rows.append(row)
            log.write(json.dumps(jsonable(row), ensure_ascii=False) + "\n")
            log.flush()
            failed = sum(not r["passed"] for r in rows)
            bar.update(task, completed=len(rows), failed=failed)
            if len(rows) % args.flush_every == 0:
                _write(out, report(rows, len(chars), meta, time.perf_counter() - start))
    rows.sort(key=lambda r: r["char"])
    final = report(rows, len(chars), meta, time.perf_counter() - start)
    _write(out, final)
    return final


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sample", type=int, default=None, help="plan N characters only")
    parser.add_argument("--workers", type=int, default=MAX_WORKERS, help="processes (<= 2)")
    parser.add_argument("--resume", action="store_true", help="skip characters already done")
    parser.add_argument(
        "--report-only", action="store_true", help="write the report of the progress file only"
    )
    parser.add_argument("--progress-file", default=None, help="JSON lines of the results")
    parser.add_argument("--flush-every", type=int, default=200, help="rewrite the summary")
    args = parser.parse_args()
    final = run(args)
    print(
        f"{final['passed']} passed, {final['failed']} failed of {final['total']}; "
        f"median {final['planning_time_s'].get('median', float('nan')):.2f} s per character"
    )
    for group in final["failures_by_cause"]:
        chars = "".join(f["char"] for f in group["failures"])
        print(f"  {group['count']:5d}  {group['cause'][:100]}  {chars[:40]}")


if __name__ == "__main__":
    main()
