"""The figure of a point fit: path over input, and each derivative against its limit."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from skyquill.viz.figures import figure_style, new_figure, save_png, stack_time_panels
from skyquill.viz.sampled import FitSamples, sample_fit

if TYPE_CHECKING:
    from skyquill.optimize.fit import PointFit

AXES = "xyz"


def plot_fit(fit: PointFit, path: str | Path, title: str = "") -> None:
    """Save the top view beside velocity, acceleration and jerk against time with limits.

    Parameters
    ----------
    fit
        The fit to show.
    path
        PNG file to write.
    title
        Figure title.
    """
    draw_fit(sample_fit(fit, title), path)


def draw_fit(samples: FitSamples, path: str | Path) -> None:
    """Draw :func:`plot_fit`'s figure of ``samples`` (:func:`~skyquill.viz.sampled.sample_fit`).

    The three derivative panels are stacked on one shared time axis (one set of time
    tick labels, one legend): most of a panel's drawing time is its ticks and text.

    Parameters
    ----------
    samples
        The fit sampled.
    path
        PNG file to write.
    """
    # A fixed layout: constrained layout draws the figure twice to measure it (half the time).
    fig = new_figure((11, 8))
    with figure_style():
        top = fig.add_axes((0.07, 0.07, 0.4, 0.83))
        panels = stack_time_panels(fig, (0.56, 0.07, 0.42, 0.83), 3)
    points, p, t = samples.points, samples.path, samples.t
    top.plot(points[:, 0], points[:, 1], ".", ms=2, color="0.6", label="input")
    top.plot(p[:, 0], p[:, 1], "-", lw=1.2, color="C0", label="trajectory")
    top.set(xlabel="x [m]", ylabel="y [m]", aspect="equal", title="path (top view)")
    top.legend(loc="upper right", fontsize=8)  # "best" tests every point of the path
    names = ("velocity [m/s]", "acceleration [m/s²]", "jerk [m/s³]")
    for panel, values, marks, name in zip(
        panels, samples.derivatives, samples.limits, names, strict=True
    ):
        for i in range(values.shape[1]):
            panel.plot(t, values[:, i], lw=1, label=AXES[i])
        for mark in marks:
            if mark.curve is not None:
                panel.plot(t, mark.curve, color="k", lw=0.8, label=mark.label)
            for level in mark.levels:
                panel.axhline(level, color="k", ls="--", lw=0.8)
        panel.set_ylabel(name)
    panels[0].set_title("derivatives against their limits (dashed)")
    panels[0].legend(loc="upper right", fontsize=8, ncols=4)
    panels[-1].set_xlabel("t [s]")
    fig.suptitle(samples.title)
    save_png(fig, path, dpi=110)
