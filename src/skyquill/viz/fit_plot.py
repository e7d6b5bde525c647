"""The figure of a point fit: path over input, and each derivative against its limit."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes

from skyquill.limits import BoxLimit, DerivativeLimit, NormLimit
from skyquill.optimize.fit import PointFit

AXES = "xyz"


def plot_fit(fit: PointFit, path: str | Path, title: str = "") -> None:
    """Save a 2x2 figure: top view, speed, acceleration and jerk with limits.

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
    fig, ax = plt.subplots(2, 2, figsize=(11, 8))
    fig.subplots_adjust(left=0.07, right=0.98, bottom=0.07, top=0.92, hspace=0.28, wspace=0.22)
    p = traj.evaluate(t)
    ax[0, 0].plot(fit.points[:, 0], fit.points[:, 1], ".", ms=2, color="0.6", label="input")
    ax[0, 0].plot(p[:, 0], p[:, 1], "-", lw=1.2, color="C0", label="trajectory")
    ax[0, 0].set(xlabel="x [m]", ylabel="y [m]", aspect="equal", title="path (top view)")
    ax[0, 0].legend(loc="upper right", fontsize=8)  # "best" tests every point of the path
    for panel, order, unit in ((ax[0, 1], 1, "m/s"), (ax[1, 0], 2, "m/s²"), (ax[1, 1], 3, "m/s³")):
        values = traj.evaluate(t, order)
        for i in range(values.shape[1]):
            panel.plot(t, values[:, i], lw=1, label=AXES[i])
        for lim in fit.limits:
            if lim.order == order:
                _draw_limit(panel, t, values, lim)
        name = {1: "velocity", 2: "acceleration", 3: "jerk"}[order]
        panel.set(xlabel="t [s]", ylabel=f"{name} [{unit}]", title=name)
        panel.legend(loc="upper right", fontsize=8)
    check = fit.verification
    fig.suptitle(
        f"{title}  duration {traj.duration:.2f} s, max excess {check.max_excess:.1e}, "
        f"rms deviation {1e3 * fit.rms_deviation_m:.1f} mm"
    )
    fig.savefig(path, dpi=110)
    plt.close(fig)


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
