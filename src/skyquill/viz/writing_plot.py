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

from pathlib import Path
from typing import TYPE_CHECKING

from matplotlib.axes import Axes
from matplotlib.collections import LineCollection

from skyquill.viz.figures import figure_style, new_figure, save_png, stack_time_panels
from skyquill.viz.sampled import NormPanel, WritingSamples, sample_missions

if TYPE_CHECKING:
    from skyquill.calligraphy.mission import Mission

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
    draw_missions(sample_missions(missions, title), path)


def draw_missions(samples: WritingSamples, path: str | Path) -> None:
    """Draw :func:`plot_missions`' figure of ``samples``
    (:func:`~skyquill.viz.sampled.sample_missions`).

    Parameters
    ----------
    samples
        The missions sampled.
    path
        PNG file to write.
    """
    fig = new_figure((16, 6), dpi=DPI)
    with figure_style():
        boards = fig.add_axes((0.04, 0.08, 0.44, 0.8))
        # One shared time axis: its tick labels drawn once, on the bottom panel.
        panels = stack_time_panels(fig, (0.55, 0.08, 0.43, 0.8), 3, hspace=0.5)
    _board_view(boards, samples)
    names = ("speed [m/s]", "acceleration [m/s²]", "jerk [m/s³]")
    for ax, norms, name in zip(panels, samples.norms, names, strict=True):
        _norms(ax, norms, name, samples.duration_s)
    panels[-1].set_xlabel("t [s]")
    fig.suptitle(samples.title)
    save_png(fig, path, dpi=DPI)


def _board_view(ax: Axes, samples: WritingSamples) -> None:
    """Every drone's board in one panel, board ``k`` at its cell of a nearly square grid."""
    ax.add_collection(
        LineCollection(
            list(samples.inputs), colors="0.75", linewidths=5, capstyle="round", label="input"
        )
    )
    up = samples.pen_up
    ax.plot(up[:, 0], up[:, 1], ",", color="0.8", label="pen up")
    ax.add_collection(
        LineCollection(list(samples.pen_down), colors="C3", linewidths=1.2, label="pen down")
    )
    ax.set_xlim(*samples.board_limits[0])
    ax.set_ylim(*samples.board_limits[1])
    ax.set(aspect="equal", xlabel="u [m] (board after board)", ylabel="v [m]")
    ax.set_title(samples.board_title)
    ax.legend(fontsize=7, loc="upper right")


def _norms(ax: Axes, panel: NormPanel, name: str, duration_s: float) -> None:
    """Derivative of every drone against time, with the limit dashed.

    Its norm, or its largest component where the limit is per axis (a box).
    """
    ax.add_collection(LineCollection(list(panel.curves), colors="k", linewidths=0.7, alpha=0.7))
    for bound in panel.bounds:
        ax.axhline(bound, color="C3", ls="--", lw=0.8)
    top = max([float(c[:, 1].max()) for c in panel.curves] + list(panel.bounds))
    ax.set_xlim(0.0, duration_s)
    ax.set_ylim(0.0, 1.1 * top if top > 0 else 1.0)
    ax.set_ylabel(name)
    measure = "largest component" if panel.per_axis else "norm"
    what = name.split(" ", maxsplit=1)[0]
    ax.set_title(f"{what}: {measure} of every drone (dashed: the limit)", fontsize=9, pad=3)
