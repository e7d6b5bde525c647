"""The figure of a point fit: path over input, and each derivative against its limit."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.axes import Axes

from skyquill.limits import BoxLimit, DerivativeLimit, NormLimit
from skyquill.optimize.fit import PointFit
from skyquill.viz.figures import figure_style, new_figure, save_png, stack_time_panels

AXES = "xyz"


def plot_fit(fit: PointFit, path: str | Path, title: str = "") -> None:
    """Save the top view beside velocity, acceleration and jerk against time with limits.

    The three derivative panels are stacked on one shared time axis (one set of time
    tick labels, one legend): most of a panel's drawing time is its ticks and text.

    Parameters
    ----------
    fit
        The fit to show.
    path
        PNG file to write.
    title
        Figure title.
    """
    traj = fit.trajectory
    t = np.linspace(0.0, traj.duration, 2000)
    # A fixed layout: constrained layout draws the figure twice to measure it (half the time).
    fig = new_figure((11, 8))
    with figure_style():
        top = fig.add_axes((0.07, 0.07, 0.4, 0.83))
        panels = stack_time_panels(fig, (0.56, 0.07, 0.42, 0.83), 3)
    p = traj.evaluate(t)
    top.plot(fit.points[:, 0], fit.points[:, 1], ".", ms=2, color="0.6", label="input")
    top.plot(p[:, 0], p[:, 1], "-", lw=1.2, color="C0", label="trajectory")
    top.set(xlabel="x [m]", ylabel="y [m]", aspect="equal", title="path (top view)")
    top.legend(loc="upper right", fontsize=8)  # "best" tests every point of the path
    for panel, order, unit in zip(panels, (1, 2, 3), ("m/s", "m/s²", "m/s³"), strict=True):
        values = traj.evaluate(t, order)
        for i in range(values.shape[1]):
            panel.plot(t, values[:, i], lw=1, label=AXES[i])
        for lim in fit.limits:
            if lim.order == order:
                _draw_limit(panel, t, values, lim)
        name = {1: "velocity", 2: "acceleration", 3: "jerk"}[order]
        panel.set_ylabel(f"{name} [{unit}]")
    panels[0].set_title("derivatives against their limits (dashed)")
    panels[0].legend(loc="upper right", fontsize=8, ncols=4)
    panels[-1].set_xlabel("t [s]")
    check = fit.verification
    fig.suptitle(
        f"{title}  duration {traj.duration:.2f} s, max excess {check.max_excess:.1e}, "
        f"rms deviation {1e3 * fit.rms_deviation_m:.1f} mm"
    )
    save_png(fig, path, dpi=110)


def _draw_limit(panel: Axes, t: np.ndarray, values: np.ndarray, lim: DerivativeLimit) -> None:
    if isinstance(lim, BoxLimit):
        for bound in (lim.upper.max(), lim.lower.min()):
            panel.axhline(bound, color="k", ls="--", lw=0.8)
    elif isinstance(lim, NormLimit):
        panel.plot(t, np.linalg.norm(values, axis=1), color="k", lw=0.8, label="norm")
        panel.axhline(lim.radius, color="k", ls="--", lw=0.8)
    else:
        panel.plot(t, np.hypot(values[:, 0], values[:, 1]), color="k", lw=0.8, label="|xy|")
        panel.axhline(lim.radius, color="k", ls="--", lw=0.8)
