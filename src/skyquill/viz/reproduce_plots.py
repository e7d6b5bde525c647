"""Figures of the paper-003 reproductions (one function per figure).

Every function takes plain arrays and mappings (no study objects), writes one
PNG and closes its figure. World frame z-up, metres, seconds.

* :func:`plot_fig10` -- §5.4, Fig. 10: cost and computing time against the
  number of control points, decoupled against coupled limits.
* :func:`plot_corridor_top_view` -- §5.4, Fig. 9: the boxes of the safe
  corridor seen from above with the trajectories of one ``M``.
* :func:`plot_fig7` -- §5.2, Fig. 7: top and side views of the three ways of
  flying a line-segment plan.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Polygon

from skyquill.validation import FloatArray

_STYLES = ("-", "--", "-.", ":")


def _color(i: int) -> str:
    return f"C{i % 10}"


def plot_fig10(
    n_ctrl: Sequence[int],
    cost: Mapping[str, Sequence[float | None]],
    time_s: Mapping[str, Sequence[float | None]],
    path: str | Path,
    title: str = "",
    *,
    reference: Sequence[float | None] | None = None,
) -> None:
    """Cost (a) and computing time (b) against the number of control points.

    Parameters
    ----------
    n_ctrl
        Numbers of control points ``M``, length K.
    cost
        Per variant (e.g. ``"decoupled"``, ``"coupled-6"``), K total costs
        (smoothness + deviation, paper 003 eq. 7); ``None`` where the problem
        was infeasible. Drawn on a log axis.
    time_s
        Per variant, K solve times in seconds (``None`` where infeasible).
    path
        PNG file to write.
    title
        Figure title.
    reference
        K costs of the same problems without derivative limits (a lower bound
        of every variant), drawn thin and grey in panel (a); ``None`` entries
        are skipped.

    Notes
    -----
    An infeasible ``M`` is marked with an ``x`` on a strip below each panel,
    one row per variant, so that feasibility with fewer control points can
    be read off directly.
    """
    m = np.asarray(n_ctrl, dtype=float)
    variants = list(cost)
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8), layout="constrained")
    panels = (
        (axes[0], cost, "total cost (smoothness + deviation)", "(a) cost"),
        (axes[1], time_s, "solve time [ms] (median)", "(b) computing time"),
    )
    for ax, data, ylabel, name in panels:
        scale = 1e3 if data is time_s else 1.0
        finite = [v * scale for seq in data.values() for v in seq if v is not None]
        lo = min(finite) if finite else 1.0
        hi = max(finite) if finite else 10.0
        if data is cost:
            ax.set_yscale("log")
            strip = [lo / 1.6 ** (i + 1) for i in range(len(variants))]
            ax.set_ylim(lo / 1.6 ** (len(variants) + 1), hi * 1.6)
        else:
            pad = (hi - lo) * 0.12 + 1e-3
            strip = [lo - pad * (i + 1) for i in range(len(variants))]
            ax.set_ylim(lo - pad * (len(variants) + 1), hi + pad)
        for i, name_v in enumerate(variants):
            values = data[name_v]
            y = np.array([np.nan if v is None else v * scale for v in values])
            ax.plot(
                m,
                y,
                _STYLES[i % len(_STYLES)],
                marker="o",
                ms=4,
                color=_color(i),
                label=f"{name_v} (feasible {int(np.sum(np.isfinite(y)))}/{y.size})",
            )
            bad = ~np.isfinite(y)
            if np.any(bad):
                ax.plot(
                    m[bad],
                    np.full(int(bad.sum()), strip[i]),
                    "x",
                    ms=7,
                    mew=1.6,
                    color=_color(i),
                    linestyle="none",
                )
        if data is cost and reference is not None:
            ref = np.array([np.nan if v is None else v for v in reference])
            ax.plot(
                m,
                ref,
                ":",
                color="0.5",
                lw=1.2,
                marker=".",
                label="no derivative limits (lower bound)",
            )
        ax.set(xlabel="number of control points M", ylabel=ylabel, title=name)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(loc="upper right", fontsize=8, title="x below: infeasible", title_fontsize=8)
    if title:
        fig.suptitle(title)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_corridor_top_view(
    footprints: Sequence[FloatArray],
    waypoints: FloatArray,
    trajectories: Mapping[str, FloatArray | None],
    path: str | Path,
    title: str = "",
    *,
    speeds: Mapping[str, tuple[FloatArray, FloatArray]] | None = None,
    speed_limits: Mapping[str, float] | None = None,
) -> None:
    """Top view of a box corridor and the trajectories flown through it.

    Parameters
    ----------
    footprints
        One (4, 2) array per box: the corners of its footprint in x, y, m,
        in order around the rectangle.
    waypoints
        Nominal path, shape (W, 3) or (W, 2), m.
    trajectories
        Per variant, positions sampled densely, shape (N, >= 2), m; ``None``
        for a variant that is infeasible (listed in the legend as such).
    path
        PNG file to write.
    title
        Figure title.
    speeds
        Optional panel below the map: per curve ``(t, speed)``, shapes (N,)
        and (N,), s and m/s (e.g. each variant's horizontal speed and the
        nominal plan's). A name without a trajectory is drawn in black.
    speed_limits
        Horizontal lines in the speed panel, ``{label: m/s}``.
    """
    fig = plt.figure(figsize=(8.5, 11.5 if speeds else 8.5), layout="constrained")
    grid = fig.add_gridspec(2 if speeds else 1, 1, height_ratios=[3, 1] if speeds else [1])
    ax = fig.add_subplot(grid[0, 0])
    for i, corners in enumerate(footprints):
        ax.add_patch(
            Polygon(
                corners,
                closed=True,
                facecolor="0.85",
                edgecolor="0.45",
                alpha=0.55,
                lw=1.0,
                label="corridor boxes" if i == 0 else None,
            )
        )
        centre = np.asarray(corners).mean(axis=0)
        ax.annotate(f"box {i}", centre, color="0.35", fontsize=8, ha="center", va="center")
    wp = np.asarray(waypoints)
    ax.plot(wp[:, 0], wp[:, 1], "k--", lw=0.9, marker="s", ms=4, label="nominal waypoints")
    for i, (name, p) in enumerate(trajectories.items()):
        if p is None:
            ax.plot([], [], _STYLES[i % len(_STYLES)], color=_color(i), label=f"{name}: infeasible")
            continue
        ax.plot(p[:, 0], p[:, 1], _STYLES[i % len(_STYLES)], color=_color(i), lw=1.4, label=name)
    ax.set(xlabel="x [m]", ylabel="y [m]", aspect="equal", title=title or "safe corridor")
    ax.autoscale_view()
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower left", fontsize=8)
    if speeds:
        sp = fig.add_subplot(grid[1, 0])
        names = list(trajectories)
        for name, (t, v) in speeds.items():
            i = names.index(name) if name in names else -1
            style = _STYLES[i % len(_STYLES)] if i >= 0 else "-"
            sp.plot(
                t,
                v,
                style,
                color=_color(i) if i >= 0 else "0.2",
                lw=1.2 if i >= 0 else 0.8,
                label=name,
            )
        for k, (label, value) in enumerate((speed_limits or {}).items()):
            sp.axhline(value, color="0.4", ls=(":", "--", "-.")[k % 3], lw=0.9, label=label)
        top = max(
            [float(np.max(v)) for _, v in speeds.values()] + list((speed_limits or {}).values())
        )
        sp.set_ylim(0.0, 1.45 * top)  # room for the legend above the curves
        sp.set(xlabel="t [s]", ylabel="horizontal speed [m/s]", title="horizontal speed")
        sp.grid(True, alpha=0.3)
        sp.legend(loc="upper left", fontsize=7, ncol=2)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_fig7(
    polyline: FloatArray,
    extra_points: FloatArray,
    trajectories: Mapping[str, FloatArray],
    path: str | Path,
    title: str = "",
    *,
    times: FloatArray | None = None,
    deviations: Mapping[str, FloatArray] | None = None,
    snap_norms: Mapping[str, FloatArray] | None = None,
) -> None:
    """Top view (x-y) and side view (x-z) of line-segment fits (paper 003 Fig. 7).

    Parameters
    ----------
    polyline
        Waypoints of the line-segment plan, shape (W, d), d = 2 or 3, m.
    extra_points
        The intermediate points ``S_i^+``, ``S_{i+1}^-`` (§3.5), shape (P, d), m.
    trajectories
        Per method, dense samples of the position, shape (N, d), m.
    path
        PNG file to write.
    title
        Figure title.
    times
        Sample times, shape (N,), s; needed for the two optional panels.
    deviations
        Per method, distance to the polyline at ``times``, shape (N,), m:
        drawn against time on a log axis.
    snap_norms
        Per method, ``||d^4 p / dt^4||`` at ``times``, shape (N,), m/s^4.
    """
    wp = np.asarray(polyline)
    views = ((0, 1, "top view", "y [m]"), (0, 2, "side view", "z [m]"))
    n_views = 2 if wp.shape[1] >= 3 else 1
    extra_row = times is not None and (deviations is not None or snap_norms is not None)
    fig = plt.figure(
        figsize=(12, 4.0 * n_views + (3.6 if extra_row else 0.0)), layout="constrained"
    )
    grid = fig.add_gridspec(n_views + int(extra_row), 2)
    for row in range(n_views):
        ax = fig.add_subplot(grid[row, :])
        i, j, name, ylabel = views[row]
        ax.plot(wp[:, i], wp[:, j], "k-", lw=2.4, alpha=0.25, label="line segments")
        ax.plot(wp[:, i], wp[:, j], "ks", ms=5, label="waypoints")
        if extra_points.size:
            ax.plot(
                extra_points[:, i],
                extra_points[:, j],
                "o",
                ms=4,
                mfc="none",
                color="0.3",
                label="intermediate points (Method 2)",
            )
        for k, (label, p) in enumerate(trajectories.items()):
            ax.plot(
                p[:, i], p[:, j], _STYLES[k % len(_STYLES)], color=_color(k), lw=1.3, label=label
            )
        ax.set(xlabel="x [m]", ylabel=ylabel, title=name)
        if row == 0:
            ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize=8)
    if extra_row and times is not None:
        panels = (
            (deviations, "distance to the polyline [m]", "deviation", True),
            (snap_norms, "|snap| [m/s⁴]", "snap", False),
        )
        for col, (data, ylabel, name, log) in enumerate(panels):
            if data is None:
                continue
            ax = fig.add_subplot(grid[n_views, col])
            for k, (label, y) in enumerate(data.items()):
                ax.plot(
                    times,
                    np.maximum(y, 1e-6) if log else y,
                    _STYLES[k % len(_STYLES)],
                    color=_color(k),
                    lw=1.0,
                    label=label.split(":")[0],
                )
            if log:
                ax.set_yscale("log")
                ax.set_ylim(1e-5, None)
            ax.set(xlabel="t [s]", ylabel=ylabel, title=name)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(loc="best", fontsize=8)
    if title:
        fig.suptitle(title)
    fig.savefig(path, dpi=120)
    plt.close(fig)
