"""The figure of a writing flight: input against the pen-down path; derivatives against limits.

Four panels, however many drones write: every drone's board side by side in one
panel (input strokes grey, pen-down path red, pen-up dots pale; the boards in a
nearly square grid, each in its own board coordinates), then speed, acceleration
and jerk norms of every drone against time with the limits dashed. Each panel is a
handful of collections, not one line per drone and axis, and the layout is fixed,
not solved: the figure costs the same for one drone or a hundred (the previous
one row of four panels per drone took 3 s for ten drones, most of it laying out
forty panels).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection

from skyquill.calligraphy.mission import Mission
from skyquill.limits import BoxLimit
from skyquill.validation import FloatArray
from skyquill.viz.figures import figure_style, new_figure, save_png, stack_time_panels

#: Samples per drone of the board view and of the derivative panels.
BOARD_SAMPLES = 4000
CURVE_SAMPLES = 1500
#: Gap between two boards of the board view, in units of the board's size.
BOARD_GAP = 0.25
DPI = 100


def plot_missions(missions: list[Mission], path: str | Path, title: str = "") -> None:
    """Save the board view of every drone and the speed, acceleration and jerk norms.

    Parameters
    ----------
    missions
        Planned missions (one per drone).
    path
        PNG file to write.
    title
        Figure title.
    """
    fig = new_figure((16, 6), dpi=DPI)
    with figure_style():
        boards = fig.add_axes((0.04, 0.08, 0.44, 0.8))
        # One shared time axis: its tick labels drawn once, on the bottom panel.
        panels = stack_time_panels(fig, (0.55, 0.08, 0.43, 0.8), 3, hspace=0.5)
    _board_view(boards, missions)
    names = ("speed [m/s]", "acceleration [m/s²]", "jerk [m/s³]")
    for ax, order, name in zip(panels, (1, 2, 3), names, strict=True):
        _norms(ax, missions, order, name)
    panels[-1].set_xlabel("t [s]")
    worst = max(m.deviation.max_m for m in missions)
    fig.suptitle(
        f"{title}  {len(missions)} drone(s), max deviation {1e3 * worst:.2f} mm, max excess "
        f"{max(m.verification.max_excess for m in missions):.1e}"
    )
    save_png(fig, path, dpi=DPI)


def _board_view(ax: Axes, missions: list[Mission]) -> None:
    """Every drone's board in one panel, board ``k`` at its cell of a nearly square grid."""
    columns = math.ceil(math.sqrt(len(missions)))
    size = max(m.options.size_m for m in missions)
    pitch = size * (1.0 + BOARD_GAP)
    inputs: list[FloatArray] = []
    downs: list[FloatArray] = []
    ups: list[FloatArray] = []
    for k, mission in enumerate(missions):
        shift = pitch * np.array([k % columns, -(k // columns)])
        traj = mission.trajectory
        t = np.linspace(0.0, traj.duration, BOARD_SAMPLES)
        uv = mission.board.to_board(traj.evaluate(t))[:, :2] + shift
        down = mission.pen(t) > 0
        ups.append(uv[~down])
        inputs.extend(mission.board.to_board(s)[:, :2] + shift for s in mission.strokes_world)
        downs.append(np.where(down[:, None], uv, np.nan))  # NaN breaks the line at pen-up
    ax.add_collection(
        LineCollection(inputs, colors="0.75", linewidths=5, capstyle="round", label="input")
    )
    up = np.concatenate(ups) if ups else np.empty((0, 2))
    ax.plot(up[:, 0], up[:, 1], ",", color="0.8", label="pen up")
    ax.add_collection(LineCollection(downs, colors="C3", linewidths=1.2, label="pen down"))
    rows = math.ceil(len(missions) / columns)
    margin = 0.1 * size  # the boards, not the take-off transits
    ax.set_xlim(-margin, (columns - 1) * pitch + size + margin)
    ax.set_ylim(-(rows - 1) * pitch - margin, size + margin)
    ax.set(aspect="equal", xlabel="u [m] (board after board)", ylabel="v [m]")
    ax.set_title(
        f"boards: {max(m.trajectory.duration for m in missions):.1f} s, deviation "
        f"{1e3 * max(m.deviation.max_m for m in missions):.1f} mm"
    )
    ax.legend(fontsize=7, loc="upper right")


def _norms(ax: Axes, missions: list[Mission], order: int, name: str) -> None:
    """Derivative ``order`` of every drone against time, with the limit dashed.

    Its norm, or its largest component where the limit is per axis (a box).
    """
    limits = [lim for lim in missions[0].options.derivative_limits() if lim.order == order]
    per_axis = any(isinstance(lim, BoxLimit) for lim in limits)
    curves = []
    for mission in missions:
        traj = mission.trajectory
        t = np.linspace(0.0, traj.duration, CURVE_SAMPLES)
        values = traj.evaluate(t, order)
        size = np.abs(values).max(axis=1) if per_axis else np.linalg.norm(values, axis=1)
        curves.append(np.column_stack([t, size]))
    ax.add_collection(LineCollection(curves, colors="k", linewidths=0.7, alpha=0.7))
    bounds = [
        float(lim.upper.max()) if isinstance(lim, BoxLimit) else float(lim.radius) for lim in limits
    ]
    for bound in bounds:
        ax.axhline(bound, color="C3", ls="--", lw=0.8)
    top = max([float(c[:, 1].max()) for c in curves] + bounds)
    ax.set_xlim(0.0, max(m.trajectory.duration for m in missions))
    ax.set_ylim(0.0, 1.1 * top if top > 0 else 1.0)
    ax.set_ylabel(name)
    measure = "largest component" if per_axis else "norm"
    what = name.split(" ", maxsplit=1)[0]
    ax.set_title(f"{what}: {measure} of every drone (dashed: the limit)", fontsize=9, pad=3)
