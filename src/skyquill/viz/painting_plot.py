"""The mission's figure, after paper 002's Figs. 5-11 and 16, in one PNG.

Panels: desired and obtained drawing (Figs. 5-7, 15); the estimates ``delta_hat`` and
``gamma_hat`` against truth over time (Figs. 8-9); the yaw reference (Fig. 10); the distance
error per dot over time (Fig. 11); the wall seen from above with the contacts and, for the
segment model, the fitted lines (Fig. 16).

matplotlib is imported inside :func:`plot_mission` (the Agg backend).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from skyquill.painting.mission import MissionResult


def plot_mission(result: MissionResult, path: str | Path, title: str = "") -> None:
    """Write the six-panel figure of ``result`` to ``path`` (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(16, 8.5))
    _drawing(axes[0, 0], result)
    _estimates(axes[0, 1], result)
    _gamma(axes[0, 2], result)
    _yaw(axes[1, 0], result)
    _errors(axes[1, 1], result)
    _wall(axes[1, 2], result)
    fig.suptitle(
        f"{title}  estimator={result.estimator}, localization={result.localization}: "
        f"RMSE {100 * result.rmse_m:.2f} cm, max {100 * result.max_error_m:.2f} cm, "
        f"{result.flight_time_s / 60:.1f} min, {result.landings} landing(s)"
    )
    # A fixed layout: tight_layout draws the figure once more to measure it.
    fig.subplots_adjust(left=0.05, right=0.98, bottom=0.07, top=0.92, hspace=0.3, wspace=0.25)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _landings(ax: Any, result: MissionResult) -> None:
    for t in result.history["t_s"][result.history["landing"].astype(bool)]:
        ax.axvline(t / 60, color="0.7", lw=0.8, ls=":")


def _drawing(ax: Any, result: MissionResult) -> None:
    target = result.target_w
    ax.plot(target[:, 0], target[:, 2], "o", mfc="none", color="0.4", label="desired")
    ok = result.painted
    ax.plot(result.painted_w[ok, 0], result.painted_w[ok, 2], ".", color="C3", label="painted")
    for a, b in zip(target[ok], result.painted_w[ok], strict=True):
        ax.plot([a[0], b[0]], [a[2], b[2]], color="C3", lw=0.4)
    ax.set(xlabel="x_w (m)", ylabel="z_w (m)", title="drawing (Figs. 5-7)", aspect="equal")
    ax.legend(loc="lower right", fontsize=8)


def _estimates(ax: Any, result: MissionResult) -> None:
    h = result.history
    t = h["t_s"] / 60
    delta = h["delta_hat_w"].reshape(-1, 3)
    for k, name in ((0, "x"), (1, "y")):
        ax.plot(t, delta[:, k], color=f"C{k}", label=f"delta_{name} estimate")
        ax.axhline(result.truth.delta_w[k], color=f"C{k}", ls="--", lw=0.8, label=f"delta_{name}")
    _landings(ax, result)
    ax.set(xlabel="time (min)", ylabel="m", title="delta estimate (Fig. 8)")
    ax.legend(fontsize=8)


def _gamma(ax: Any, result: MissionResult) -> None:
    h = result.history
    ax.plot(h["t_s"] / 60, np.degrees(h["gamma_hat_rad"]), label="gamma estimate")
    ax.axhline(result.truth.gamma_deg, color="k", ls="--", lw=0.8, label="gamma")
    _landings(ax, result)
    ax.set(xlabel="time (min)", ylabel="deg", title="gamma estimate (Fig. 9)")
    ax.legend(fontsize=8)


def _yaw(ax: Any, result: MissionResult) -> None:
    h = result.history
    ax.step(h["t_s"] / 60, np.degrees(h["yaw_rad"]), where="post", label="yaw reference")
    _landings(ax, result)
    ax.set(xlabel="time (min)", ylabel="deg", title="yaw reference in R_rho (Fig. 10)")
    ax.legend(fontsize=8)


def _errors(ax: Any, result: MissionResult) -> None:
    h = result.history
    ok = np.isfinite(h["error_m"])
    ax.plot(h["t_s"][ok] / 60, 100 * h["error_m"][ok], ".-", lw=0.6)
    _landings(ax, result)
    ax.set(xlabel="time (min)", ylabel="cm", title="distance error per dot (Fig. 11)")


def _wall(ax: Any, result: MissionResult) -> None:
    poly = result.wall.polyline()
    ax.plot(poly[:, 0], poly[:, 1], "k-", lw=2, label="wall")
    c = result.contacts_w
    ax.plot(c[:, 0], c[:, 1], ".", color="C2", ms=3, label="contacts")
    est = result.estimate
    for a, b, lo, hi in result.lines_rho:  # the lines live in R_rho; shown through the truth
        x = np.linspace(lo, hi, 20)
        pts = np.column_stack([x, a * x + b, np.zeros_like(x)])
        w = result.truth.to_w(pts)
        ax.plot(w[:, 0], w[:, 1], "C1-", lw=1)
    home = result.truth.to_w(np.zeros(3))
    ax.plot(home[0], home[1], "k^", label="take-off")
    lo, hi = result.reference[:, 0].min(), result.reference[:, 0].max()
    ax.set_xlim(min(lo, home[0]) - 0.5, max(hi, home[0]) + 0.5)
    ax.set(
        xlabel="x_w (m)",
        ylabel="y_w (m)",
        title=f"wall from above (Fig. 16); gamma_hat {math.degrees(est.gamma_rad):.2f} deg",
    )
    ax.legend(fontsize=8)
