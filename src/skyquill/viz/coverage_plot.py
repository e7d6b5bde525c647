"""The figure of a coverage plan: region, path and covered area; speed, acceleration, jerk.

:func:`draw_coverage` draws :func:`~skyquill.viz.sampled.sample_coverage`'s arrays with
numpy and matplotlib only, so that ``cover`` can hand them to the picture worker
(:mod:`skyquill.viz.worker`), which imported matplotlib while the command planned.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib

matplotlib.use("Agg")
from matplotlib.axes import Axes

from skyquill.viz.figures import figure_style, new_figure, save_png, stack_time_panels
from skyquill.viz.sampled import Area, CoverageSamples, sample_coverage

if TYPE_CHECKING:
    from skyquill.coverage.plan import CoveragePlan


def _fill(ax: Axes, areas: tuple[Area, ...], **style: object) -> None:
    for area in areas:
        ax.fill(*area.exterior.T, **style)  # type: ignore[arg-type]
        for hole in area.holes:
            ax.fill(*hole.T, color="white")


def plot_coverage(plan: CoveragePlan, path: str | Path) -> None:
    """Save a PNG of ``plan`` (:func:`draw_coverage` of its samples).

    Parameters
    ----------
    plan
        A :func:`~skyquill.coverage.plan.plan_coverage` result.
    path
        PNG file to write.
    """
    draw_coverage(sample_coverage(plan), path)


def draw_coverage(samples: CoverageSamples, path: str | Path) -> None:
    """Save a PNG of a coverage plan's ``samples``.

    Left: the region (grey outline), the covered area (light blue), what is
    left uncovered (red), the waypoints (dots) and the flown path coloured by
    speed. Right: speed, per-axis |acceleration| and |jerk| against time with
    their limits dashed.

    Parameters
    ----------
    samples
        :func:`~skyquill.viz.sampled.sample_coverage` of the plan.
    path
        PNG file to write.
    """
    # A fixed layout: constrained layout draws the figure twice to measure it.
    with figure_style():
        fig = new_figure((13, 6.5))
        grid = fig.add_gridspec(
            3, 2, width_ratios=(1.1, 1.0), left=0.06, right=0.98, bottom=0.08, top=0.9,
            hspace=0.45, wspace=0.18,
        )  # fmt: skip
        top = fig.add_subplot(grid[:, 0])
        # One time axis for the three stacked panels, ticked only at the bottom:
        # matplotlib's ticks are most of the picture's time (their marks above, 7 ms).
        panels = stack_time_panels(fig, grid[:, 1].get_position(fig).bounds, 3, hspace=0.45)
        for ax in panels[:-1]:
            ax.tick_params(bottom=False)
    _fill(top, samples.covered, color="#cfe3f7")
    _fill(top, samples.missed, color="#e4572e", alpha=0.8)
    for ring in samples.boundaries:  # shells and holes of every field
        top.plot(*ring.T, color="0.3", lw=1.2)
    x, y = samples.dots.T
    dots = top.scatter(x, y, c=samples.dot_speed, s=2, cmap="viridis", vmin=0.0)
    top.plot(*samples.waypoints.T, ".", ms=3, color="0.5")
    fig.colorbar(dots, ax=top, label="speed (m/s)", shrink=0.7)
    top.set_aspect("equal")
    top.set_xlabel("x (m)")
    top.set_ylabel("y (m)")
    top.set_title(samples.title)
    vmax, amax, jmax = samples.limits
    rows = (
        ("speed (m/s)", samples.speed[:, None], vmax),
        ("|acc| (m/s²)", samples.acceleration, amax),
        ("|jerk| (m/s³)", samples.jerk, jmax),
    )
    for ax, (label, values, limit) in zip(panels, rows, strict=True):
        for i in range(values.shape[1]):
            name = "" if values.shape[1] == 1 else "xyz"[i]
            ax.plot(samples.t, values[:, i], lw=0.9, label=name or None)
        ax.axhline(limit, ls="--", color="k", lw=0.8)
        ax.set_ylabel(label)
        if values.shape[1] > 1:
            ax.legend(loc="upper right", fontsize=8)
    panels[-1].set_xlabel("t (s)")
    save_png(fig, path, dpi=100)  # (110 before: 0.145 s for the L-shaped field, now 0.13 s)
