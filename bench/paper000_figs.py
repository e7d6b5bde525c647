"""Paper 000 Figs. 6-9 reproduced: the vortex and 光 (Guang), without and with re-segmentation.

The paper shows, for a hand-drawn vortex and the character 光, the B-spline
trajectory without and with time re-segmentation (§5.4): with it "the
resulted acceleration reference becomes smoother", "the time of the
trajectory has improved significantly" (vortex) and "the time
re-segmentation improves the interpolation accuracy" (光). It gives no numbers,
so we report ours: total time, peak acceleration (pen down and overall) and
fitting error (the two-sided pen-down deviation), for re-segmentation off,
with the total time fixed, and with it free (time penalty as in
:class:`skyquill.calligraphy.mission.WritingOptions`), 30 descent steps.

Run: ``.venv/bin/python bench/paper000_figs.py`` -> ``bench/results/paper000_figs.json``
and ``bench/results/paper000_figs.png``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from rich.console import Console
from rich.table import Table
from threadpoolctl import threadpool_limits

from skyquill.calligraphy.mission import Mission, WritingOptions, plan_writing
from skyquill.io.points import read_points_csv
from skyquill.strokes import Strokes, hanzi_strokes

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results"
MODES = ("off", "fixed", "free")


def inputs() -> dict[str, Strokes]:
    """The vortex (examples/spiral.csv, one stroke) and 光."""
    spiral, _ = read_points_csv(ROOT / "examples" / "spiral.csv")
    return {"vortex": Strokes(paths=(spiral,), source="spiral.csv"), "guang": hanzi_strokes("光")}


def measure(mission: Mission) -> dict[str, Any]:
    """Total time, peak acceleration norms (pen down, overall) and the fitting error."""
    traj = mission.trajectory
    t = traj.dense_times()
    acc = np.linalg.norm(traj.evaluate(t, 2), axis=1)
    down = mission.pen(t) > 0
    return {
        "total_time_s": traj.duration,
        "peak_acc_mps2": float(acc.max()),
        "peak_acc_pen_down_mps2": float(acc[down].max()),
        "rms_acc_pen_down_mps2": float(np.sqrt(np.mean(acc[down] ** 2))),
        "fitting_error_max_m": mission.deviation.max_m,
        "fitting_error_mean_m": mission.deviation.mean_m,
        "cost": mission.fits[0].cost,
        "max_excess": mission.verification.max_excess,
        "planning_time_s": mission.planning_time_s,
    }


def main() -> None:
    """Plan both inputs in the three modes; write JSON and the acceleration figure."""
    results: dict[str, dict[str, Any]] = {}
    missions: dict[tuple[str, str], Mission] = {}
    with threadpool_limits(1):
        for name, strokes in inputs().items():
            results[name] = {}
            for mode in MODES:
                # Paper 000 fits the vehicle's path (offset by the brush): its figures.
                options = WritingOptions(
                    resegment=mode,  # type: ignore[arg-type]
                    resegment_iterations=30,
                    follow="path",
                )
                missions[(name, mode)] = plan_writing(strokes, options=options)
                results[name][mode] = measure(missions[(name, mode)])
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "paper000_figs.json").write_text(json.dumps(results, indent=2) + "\n")
    figure(missions, RESULTS / "paper000_figs.png")
    table = Table(
        "input", "re-segmentation", "time s", "peak acc", "pen-down acc rms", "error max mm", "cost"
    )
    for name, by_mode in results.items():
        for mode, r in by_mode.items():
            table.add_row(
                name,
                mode,
                f"{r['total_time_s']:.2f}",
                f"{r['peak_acc_mps2']:.3f}",
                f"{r['rms_acc_pen_down_mps2']:.3f}",
                f"{1e3 * r['fitting_error_max_m']:.2f}",
                f"{r['cost']:.1f}",
            )
    Console().print(table)


def figure(missions: dict[tuple[str, str], Mission], path: Path) -> None:
    """Acceleration norm against time, without and with re-segmentation (paper's Figs. 7, 9)."""
    fig, axes = plt.subplots(1, 2, figsize=(13, 4), layout="constrained")
    for ax, name in zip(axes, ("vortex", "guang"), strict=True):
        for mode in MODES:
            traj = missions[(name, mode)].trajectory
            t = np.linspace(0, traj.duration, 3000)
            ax.plot(t, np.linalg.norm(traj.evaluate(t, 2), axis=1), lw=1, label=mode)
        ax.set(title=f"{name}: |acceleration|", xlabel="t [s]", ylabel="m/s²")
        ax.legend(title="re-segmentation")
    fig.savefig(path, dpi=100)
    plt.close(fig)


if __name__ == "__main__":
    main()
