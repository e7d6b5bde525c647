"""Paper 002 reproduced (Tables 1 and 2, robust vs SVD, order) and the joint estimator beyond it.

Run from the repository root::

    .venv/bin/python bench/painting.py            # 10 seeds, ~40 minutes on an idle 2-core box
    .venv/bin/python bench/painting.py --quick    # 5 seeds -> bench/results/painting_quick.json
    .venv/bin/python bench/painting.py --only joint early   # some sections only (merged into
                                                            # the existing JSON)

It writes ``bench/results/painting.json`` and prints the tables.

What is measured (every number is a mean +- sample standard deviation over the seeds, each
seed one whole mission with its own hover errors, IMU noise, drift and faults):

* Table 1 -- the 140-dot, 3.5 m x 2.1 m drawing (:func:`paper_drawing`), flat wall,
  ``delta = [0, -1.1, 0]``, ``gamma`` in {0, +10, -10, +15, -15} deg, the paper's order (right
  to left, top to bottom). Columns as the paper's: "with estimation, onboard localization"
  (``svd``/``onboard``), "with estimation, truth" (``svd``/``truth``), "without estimation,
  truth" (``none``/``truth``); two more: ``none``/``onboard`` (the fair partner of the first
  column) and ``svd-paper``/``truth`` (eq. 10 taken literally for ``delta_x``, see
  ``RigidEstimator``). RMSE in cm of the painted dots against the reference in the wall frame.
* Table 2 -- the same dots and placement (``gamma = 0``) on the four 3-segment walls
  (segment widths: the drawing's width in thirds); the estimator is the segment line model
  (eq. 13-15) with the depth-only update (eq. 15); errors in the front view, as eq. 15 means
  them. Extra columns: the fresco update (normal projection) with and without estimation,
  errors measured on the wall against the normal projection of each dot.
* Robustness -- 10 % false contacts (the IMU firing before the wall), ``gamma`` in
  {+10, -10, +15, -15}, truth and onboard localization: RMSE of ``svd`` and ``robust`` clean
  and with faults; ``ratio = faulty / clean`` per estimator.
* Contact cross-check -- :func:`skyquill.painting.crosscheck.simulated_touch`: the closed-loop
  simulator flown into the same bumper at several approach speeds, IMU detection (delay,
  squeeze) against the reduced :class:`ContactModel` (no IMU noise on either side).
* Order -- ``shortest`` (nearest neighbour + 2-opt) against ``paper``: total flight time,
  transit length and RMSE, ``gamma = 10``, ``svd``/``onboard``; ratio shortest / paper.
* Joint (issue 29) -- every wall (flat; three segments -10|0|+10 and +10|0|+10; a 20 m
  cylinder; a 10 cm recess from x = 0.6 to 1.4 m) x ``gamma`` in {0, +10, -10} x truth /
  onboard localization x estimator: ``none`` (shortest order), ``paper`` (paper 002's
  estimator for that wall -- SVD on the flat wall, the segment lines elsewhere -- with the
  paper's order and §4.1 point) and ``joint`` (placement and wall together, a probing pass
  every 0.4 m, then a short tour from the middle). Per cell: RMSE (mean, sd) and the largest
  dot error over the seeds, the worst per-seed max / RMSE, the aim error (the estimate's own
  share: where each dot lands flying the plan exactly), flight time, landings, battery use
  and, for ``joint``, how often the wall fitted its model.
* Vehicle -- the three-segment wall at ``gamma = 10`` with true localization and a 1 cm hover
  error instead of 3 cm (every other setting the same): what the estimator achieves when the
  vehicle does not hide it.
* Early -- information early, for ``joint`` on the three-segment wall at ``gamma = 10`` and
  the flat wall at ``gamma = 10``: the paper's order, the shortest tour, ``spread`` (the first
  dots 0.4 m apart) and the probing pass at 0.4 and 0.6 m before the shortest tour; RMSE,
  worst dot, aim error and flight time.
* Joint robustness -- 10 % false and 5 % missed contacts, flat and three-segment walls,
  ``gamma = 10``: ``robust`` (paper's order) against ``joint``.

BLAS is pinned to one thread (``threadpoolctl``); wall time per section is recorded.
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import statistics
import sys
import time
from collections.abc import Callable
from dataclasses import asdict
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table
from threadpoolctl import threadpool_limits

from painting_joint import JOINT_SECTIONS, show_joint
from skyquill.painting.crosscheck import simulated_touch
from skyquill.painting.dots import paper_drawing
from skyquill.painting.estimate import RigidEstimator
from skyquill.painting.mission import MissionConfig, MissionResult, run_mission
from skyquill.painting.wall import Placement, Wall

RESULTS = Path(__file__).resolve().parent / "results" / "painting.json"
QUICK_RESULTS = RESULTS.with_name("painting_quick.json")
DELTA = np.array([0.0, -1.1, 0.0])
GAMMAS = (0.0, 10.0, -10.0, 15.0, -15.0)
WALLS = ((-10.0, 0.0, 10.0), (-15.0, 0.0, 15.0), (10.0, 0.0, 10.0), (-10.0, 0.0, -10.0))
#: Paper 002's Table 1 and 2 (cm): PTAM with estimation, GT with, GT without.
PAPER_TABLE1 = {
    0.0: (8.09, 5.67, 4.81),
    10.0: (15.71, 4.67, 15.79),
    -10.0: (15.51, 7.71, 14.49),
    15.0: (22.68, 7.71, 18.89),
    -15.0: (23.37, 11.49, 17.34),
}
PAPER_TABLE2 = {
    WALLS[0]: (3.74, 4.96, 4.68),
    WALLS[1]: (6.75, 5.91, 4.59),
    WALLS[2]: (7.70, 5.85, 5.03),
    WALLS[3]: (5.01, 5.72, 4.63),
}
TABLE1_COLUMNS = {
    "est_onboard": ("svd", "onboard"),
    "est_truth": ("svd", "truth"),
    "none_truth": ("none", "truth"),
    "none_onboard": ("none", "onboard"),
    "svd_paper_delta_x_truth": ("svd-paper", "truth"),
}
TABLE2_COLUMNS = {
    "est_onboard": ("svd", "onboard", "depth"),
    "est_truth": ("svd", "truth", "depth"),
    "none_truth": ("none", "truth", "depth"),
    "fresco_est_truth": ("svd", "truth", "normal"),
    "fresco_none_truth": ("none", "truth", "normal"),
}


def mission(
    *,
    wall: Wall,
    gamma: float,
    estimator: str,
    localization: str,
    seed: int,
    update: str = "depth",
    order: str = "paper",
    false_rate: float = 0.0,
) -> MissionResult:
    """One mission of the paper's drawing; ``svd-paper`` is eq. 10 literally (delta_x too)."""
    dots = paper_drawing()
    config = MissionConfig(false_contact_rate=false_rate)
    truth = Placement(DELTA, math.radians(gamma))
    rng = np.random.default_rng(seed)
    chosen: str | RigidEstimator = estimator
    if estimator == "svd-paper":
        chosen = RigidEstimator(config.prior, along_wall="paper")
    return run_mission(
        dots,
        wall=wall,
        truth=truth,
        estimator=chosen,
        localization=localization,
        order=order,
        update="normal" if update == "normal" else "depth",
        config=config,
        rng=rng,
    )


def stats(values: list[float]) -> dict[str, Any]:
    """Mean, sample sd, min, max and the values (cm when given cm)."""
    return {
        "mean": statistics.fmean(values),
        "sd": statistics.stdev(values) if len(values) > 1 else 0.0,
        "min": min(values),
        "max": max(values),
        "values": values,
    }


def table1(seeds: list[int], tick: Callable[[], None]) -> list[dict[str, Any]]:
    """Rows of Table 1: RMSE (cm) per column."""
    rows = []
    for gamma in GAMMAS:
        row: dict[str, Any] = {"gamma_deg": gamma, "paper_cm": dict(zip(
            ("est_onboard", "est_truth", "none_truth"), PAPER_TABLE1[gamma], strict=True
        ))}  # fmt: skip
        for column, (estimator, loc) in TABLE1_COLUMNS.items():
            values = []
            for seed in seeds:
                result = mission(
                    wall=Wall.flat(), gamma=gamma, estimator=estimator, localization=loc, seed=seed
                )
                values.append(100 * result.rmse_m)
                tick()
            row[column] = stats(values)
        means = {c: row[c]["mean"] for c in TABLE1_COLUMNS}
        row["estimation_wins"] = (
            None
            if gamma == 0.0
            else means["est_truth"] < means["none_truth"]
            and means["est_onboard"] < means["none_truth"]
            and means["est_onboard"] < means["none_onboard"]
        )
        rows.append(row)
    return rows


def table2(seeds: list[int], tick: Callable[[], None]) -> list[dict[str, Any]]:
    """Rows of Table 2: RMSE (cm) per column, segment line model."""
    dots = paper_drawing()
    span = (float(dots[:, 0].min()), float(dots[:, 0].max()))
    rows = []
    for angles in WALLS:
        wall = Wall.segmented(angles, span)
        row: dict[str, Any] = {
            "wall_angles_deg": list(angles),
            "paper_cm": dict(zip(
                ("est_onboard", "est_truth", "none_truth"), PAPER_TABLE2[angles], strict=True
            )),
        }  # fmt: skip
        for column, (estimator, loc, update) in TABLE2_COLUMNS.items():
            values = []
            for seed in seeds:
                result = mission(
                    wall=wall,
                    gamma=0.0,
                    estimator=estimator,
                    localization=loc,
                    seed=seed,
                    update=update,
                )
                values.append(100 * result.rmse_m)
                tick()
            row[column] = stats(values)
        rows.append(row)
    return rows


def robustness(seeds: list[int], tick: Callable[[], None]) -> list[dict[str, Any]]:
    """SVD and robust, clean and with 10 % false contacts."""
    rows = []
    for loc in ("truth", "onboard"):
        for gamma in (10.0, -10.0, 15.0, -15.0):
            row: dict[str, Any] = {"gamma_deg": gamma, "localization": loc}
            for estimator in ("svd", "robust"):
                for label, rate in (("clean", 0.0), ("false10", 0.1)):
                    values, false = [], []
                    for seed in seeds:
                        result = mission(
                            wall=Wall.flat(),
                            gamma=gamma,
                            estimator=estimator,
                            localization=loc,
                            seed=seed,
                            false_rate=rate,
                        )
                        values.append(100 * result.rmse_m)
                        false.append(result.false_contacts)
                        tick()
                    row[f"{estimator}_{label}"] = stats(values) | {
                        "false_contacts_mean": statistics.fmean(false)
                    }
                clean = row[f"{estimator}_clean"]["mean"]
                row[f"{estimator}_ratio"] = row[f"{estimator}_false10"]["mean"] / clean
            row["robust_within_1_2x"] = row["robust_ratio"] <= 1.2
            rows.append(row)
    return rows


def ordering(seeds: list[int], tick: Callable[[], None]) -> dict[str, Any]:
    """Flight time, transit and RMSE of the paper's order and the shortest order."""
    out: dict[str, Any] = {"gamma_deg": 10.0, "estimator": "svd", "localization": "onboard"}
    for order in ("paper", "shortest"):
        t, m, e, landings = [], [], [], []
        for seed in seeds:
            result = mission(
                wall=Wall.flat(),
                gamma=10.0,
                estimator="svd",
                localization="onboard",
                seed=seed,
                order=order,
            )
            t.append(result.flight_time_s)
            m.append(result.transit_m)
            e.append(100 * result.rmse_m)
            landings.append(result.landings)
            tick()
        out[order] = {
            "flight_time_s": stats(t),
            "transit_m": stats(m),
            "rmse_cm": stats(e),
            "landings_mean": statistics.fmean(landings),
        }
    out["flight_time_ratio_shortest_over_paper"] = (
        out["shortest"]["flight_time_s"]["mean"] / out["paper"]["flight_time_s"]["mean"]
    )
    out["transit_ratio_shortest_over_paper"] = (
        out["shortest"]["transit_m"]["mean"] / out["paper"]["transit_m"]["mean"]
    )
    return out


CROSSCHECK_SPEEDS = (0.08, 0.1, 0.12, 0.15, 0.2, 0.3)


def crosscheck(seeds: list[int], tick: Callable[[], None]) -> list[dict[str, Any]]:
    """The reduced contact model against the simulator, one approach per speed."""
    del seeds
    rows = []
    for speed in CROSSCHECK_SPEEDS:
        rows.append({"approach_speed_mps": speed} | simulated_touch(approach_speed_mps=speed))
        tick()
    return rows


def cell(entry: dict[str, Any]) -> str:
    """``mean +- sd``."""
    return f"{entry['mean']:.2f} ± {entry['sd']:.2f}"


def show(console: Console, data: dict[str, Any]) -> None:
    """Print the tables."""
    t1 = Table(title="Table 1: RMSE (cm), flat wall; paper's value in brackets")
    for name in ("gamma", *TABLE1_COLUMNS, "wins"):
        t1.add_column(name)
    for row in data["table1"]:
        paper = row["paper_cm"]
        t1.add_row(
            f"{row['gamma_deg']:+g}",
            *(cell(row[c]) + (f" [{paper[c]:.2f}]" if c in paper else "") for c in TABLE1_COLUMNS),
            str(row["estimation_wins"]),
        )
    console.print(t1)
    t2 = Table(title="Table 2: RMSE (cm), 3-segment walls, gamma = 0; paper's value in brackets")
    for name in ("walls", *TABLE2_COLUMNS):
        t2.add_column(name)
    for row in data["table2"]:
        paper = row["paper_cm"]
        t2.add_row(
            " | ".join(f"{a:+g}" for a in row["wall_angles_deg"]),
            *(cell(row[c]) + (f" [{paper[c]:.2f}]" if c in paper else "") for c in TABLE2_COLUMNS),
        )
    console.print(t2)
    t3 = Table(title="10 % false contacts: RMSE (cm) and faulty / clean")
    for name in ("loc", "gamma", "svd clean", "svd 10%", "svd ratio", "robust clean",
                 "robust 10%", "robust ratio"):  # fmt: skip
        t3.add_column(name)
    for row in data["robustness"]:
        t3.add_row(
            row["localization"],
            f"{row['gamma_deg']:+g}",
            cell(row["svd_clean"]),
            cell(row["svd_false10"]),
            f"{row['svd_ratio']:.2f}",
            cell(row["robust_clean"]),
            cell(row["robust_false10"]),
            f"{row['robust_ratio']:.2f}",
        )
    console.print(t3)
    o = data["order"]
    console.print(
        f"order, gamma = 10, svd/onboard: flight time paper "
        f"{o['paper']['flight_time_s']['mean'] / 60:.1f} min, shortest "
        f"{o['shortest']['flight_time_s']['mean'] / 60:.1f} min, ratio "
        f"{o['flight_time_ratio_shortest_over_paper']:.3f}; transit ratio "
        f"{o['transit_ratio_shortest_over_paper']:.3f}"
    )
    for row in data["contact_crosscheck"]:
        sim, model = row["sim"], row["model"]
        console.print(
            f"contact at {row['touch_speed_mps']:.3f} m/s: simulator "
            f"{'detected' if sim['detected'] else 'missed'} after {1e3 * sim['delay_s']:.0f} ms, "
            f"squeeze {1e3 * sim['squeeze_m']:.2f} mm; model "
            f"{'detected' if model['detected'] else 'missed'} after "
            f"{1e3 * model['delay_s']:.0f} ms, squeeze {1e3 * model['squeeze_m']:.2f} mm"
        )


#: name -> (function, missions per seed, or None for a fixed count)
PAPER_SECTIONS: dict[str, tuple[Callable[[list[int], Callable[[], None]], Any], int]] = {
    "table1": (table1, len(GAMMAS) * len(TABLE1_COLUMNS)),
    "table2": (table2, len(WALLS) * len(TABLE2_COLUMNS)),
    "robustness": (robustness, 2 * 4 * 4),
    "order": (ordering, 2),
    "contact_crosscheck": (crosscheck, 0),
}


def main() -> None:
    """Run the sections asked for (all by default), print, write the JSON."""
    sections = PAPER_SECTIONS | JOINT_SECTIONS
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10, help="seeds per cell (>= 5)")
    parser.add_argument("--quick", action="store_true", help="5 seeds, painting_quick.json")
    parser.add_argument("--out", type=Path, default=None)
    parser.add_argument(
        "--only", nargs="+", choices=list(sections), default=None,
        help="run these sections only; the others are kept from the existing JSON",
    )  # fmt: skip
    args = parser.parse_args()
    n_seeds = 5 if args.quick else max(args.seeds, 5)
    out = args.out or (QUICK_RESULTS if args.quick else RESULTS)
    seeds = list(range(n_seeds))
    chosen = args.only or list(sections)
    console = Console()
    total = sum(n_seeds * sections[name][1] for name in chosen)
    total += len(CROSSCHECK_SPEEDS) if "contact_crosscheck" in chosen else 0
    data: dict[str, Any] = json.loads(out.read_text()) if args.only and out.exists() else {}
    data.setdefault("wall_time_s", {})
    data |= {
        "command": " ".join(["python", *sys.argv]),
        "date": datetime.now(UTC).isoformat(timespec="seconds"),
        "machine": {"platform": platform.platform(), "python": sys.version.split()[0]},
        "seeds": seeds,
        "config": asdict(MissionConfig()),
        "drawing": "paper_drawing(): 140 dots, 3.5 m x 2.1 m, ellipse + star",
        "delta_m": DELTA.tolist(),
    }
    with threadpool_limits(1), Progress(
        TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
        console=console,
    ) as progress:  # fmt: skip
        task = progress.add_task("missions", total=total)

        def tick() -> None:
            progress.advance(task)

        for name in chosen:
            progress.update(task, description=name)
            start = time.perf_counter()
            data[name] = sections[name][0](seeds, tick)
            data["wall_time_s"][name] = time.perf_counter() - start
            out.parent.mkdir(parents=True, exist_ok=True)
            out.write_text(json.dumps(data, indent=1) + "\n")  # each section as it ends
    if all(name in data for name in PAPER_SECTIONS):
        show(console, data)
    show_joint(console, data)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(data, indent=1) + "\n")
    console.print(f"wrote {out}")


if __name__ == "__main__":
    main()
