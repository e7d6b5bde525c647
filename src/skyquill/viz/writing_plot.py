"""The figure of a writing mission: input against the pen-down path; derivatives against limits."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes

from skyquill.calligraphy.mission import Mission
from skyquill.limits import BoxLimit


def plot_missions(missions: list[Mission], path: str | Path, title: str = "") -> None:
    """Save one row per drone: board view, then speed, acceleration and jerk norms with limits.

    Parameters
    ----------
    missions
        Planned missions (one per drone).
    path
        PNG file to write.
    title
        Figure title.
    """
    rows = len(missions)
    fig, axes = plt.subplots(
        rows,
        4,
        figsize=(17, 4.2 * rows),
        layout="constrained",
        squeeze=False,
        gridspec_kw={"width_ratios": [1.4, 1, 1, 1]},
    )
    for row, mission in zip(axes, missions, strict=True):
        _board_view(row[0], mission)
        _derivatives(row[1:], mission)
    worst = max(m.deviation.max_m for m in missions)
    fig.suptitle(
        f"{title}  max deviation {1e3 * worst:.2f} mm, max excess "
        f"{max(m.verification.max_excess for m in missions):.1e}"
    )
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _board_view(ax: Axes, mission: Mission) -> None:
    traj = mission.trajectory
    t = np.linspace(0.0, traj.duration, 6000)
    uvh = mission.board.to_board(traj.evaluate(t))
    down = mission.pen(t) > 0
    ax.plot(uvh[~down, 0], uvh[~down, 1], ".", ms=0.5, color="0.8", label="pen up")
    for i, stroke in enumerate(mission.strokes_world):
        s = mission.board.to_board(stroke)
        ax.plot(
            s[:, 0],
            s[:, 1],
            "-",
            lw=5,
            color="0.75",
            solid_capstyle="round",
            label="input" if i == 0 else None,
        )
    ax.plot(
        np.where(down, uvh[:, 0], np.nan),
        np.where(down, uvh[:, 1], np.nan),
        "-",
        lw=1.2,
        color="C3",
        label="pen down",
    )
    margin = 0.1 * mission.options.size_m  # the board, not the take-off transit
    ax.set_xlim(-margin, mission.options.size_m + margin)
    ax.set_ylim(-margin, mission.options.size_m + margin)
    ax.set(
        aspect="equal",
        xlabel="u [m]",
        ylabel="v [m]",
        title=f"{mission.trajectory.duration:.1f} s, deviation "
        f"{1e3 * mission.deviation.max_m:.1f} mm",
    )
    ax.legend(fontsize=7, loc="best")


def _derivatives(axes: np.ndarray, mission: Mission) -> None:
    traj = mission.trajectory
    t = np.linspace(0.0, traj.duration, 3000)
    for ax, order, name in zip(axes, (1, 2, 3), ("speed", "acceleration", "jerk"), strict=True):
        values = traj.evaluate(t, order)
        for i, axis in enumerate("xyz"):
            ax.plot(t, values[:, i], lw=0.8, label=axis)
        ax.plot(t, np.linalg.norm(values, axis=1), lw=1.0, color="k", label="norm")
        for lim in mission.options.derivative_limits():
            if lim.order == order:
                bound = lim.upper.max() if isinstance(lim, BoxLimit) else lim.radius
                ax.axhline(bound, color="k", ls="--", lw=0.8)
                ax.axhline(-bound, color="k", ls="--", lw=0.8)
        ax.fill_between(t, *ax.get_ylim(), where=mission.pen(t) > 0, color="C3", alpha=0.08)
        ax.set(xlabel="t [s]", title=f"{name} (shaded: pen down)")
        ax.legend(fontsize=7, loc="upper right")
