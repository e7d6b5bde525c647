"""The figure of a coverage plan: region, path and covered area; speed, acceleration, jerk."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import numpy as np
import shapely
from matplotlib.axes import Axes
from shapely.geometry import MultiPolygon, Polygon

from skyquill.coverage.plan import CoveragePlan
from skyquill.coverage.regions import swept as swept_area
from skyquill.viz.figures import figure_style, new_figure, save_png, stack_time_panels

#: Most setpoints drawn as dots (a 10 ha field has 370k; the figure cannot show more).
MAX_DOTS = 40_000


def _fill(ax: Axes, shape: Polygon | MultiPolygon, **style: object) -> None:
    for part in getattr(shape, "geoms", [shape]):
        if isinstance(part, Polygon) and not part.is_empty:
            ax.fill(*part.exterior.xy, **style)  # type: ignore[arg-type]
            for hole in part.interiors:
                ax.fill(*hole.xy, color="white")


def plot_coverage(plan: CoveragePlan, path: str | Path) -> None:
    """Save a PNG of ``plan``.

    Left: the region (grey outline), the covered area (light blue), what is
    left uncovered (red), the waypoints (dots) and the flown path coloured by
    speed. Right: speed, per-axis |acceleration| and |jerk| against time with
    their limits dashed.

    Parameters
    ----------
    plan
        A :func:`~skyquill.coverage.plan.plan_coverage` result.
    path
        PNG file to write.
    """
    opts = plan.options
    sp = plan.samples()
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
    sprayed = None if plan.mission is None else plan.mission.swept  # spray off on transits
    # The planner's own simplified sweep: the raw buffer of a 20 km path's 1 M
    # points took a minute.
    swept = swept_area(plan.path, opts.width) if sprayed is None else sprayed
    _fill(top, plan.region.intersection(swept), color="#cfe3f7")
    _fill(top, plan.region.difference(swept), color="#e4572e", alpha=0.8)
    for ring in shapely.get_parts(plan.region.boundary):  # shells and holes of every field
        top.plot(*ring.xy, color="0.3", lw=1.2)
    speed = np.linalg.norm(sp.v, axis=1)
    every = max(1, speed.size // MAX_DOTS)
    dots = top.scatter(
        sp.p[::every, 0], sp.p[::every, 1], c=speed[::every], s=2, cmap="viridis", vmin=0.0
    )
    top.plot(plan.waypoints[:, 0], plan.waypoints[:, 1], ".", ms=3, color="0.5")
    fig.colorbar(dots, ax=top, label="speed (m/s)", shrink=0.7)
    top.set_aspect("equal")
    top.set_xlabel("x (m)")
    top.set_ylabel("y (m)")
    missed = "" if plan.missed is None else f", {plan.missed.area_m2:.3g} m²"
    # Two lines: on one, a long flight's numbers ran past the map's left edge.
    top.set_title(
        f"{opts.pattern}: {plan.duration:.1f} s, {plan.path_length:.1f} m\n"
        f"coverage {100 * plan.coverage:.1f} % (red: missed{missed})"
    )
    rows = (
        ("speed (m/s)", speed[:, None], opts.vmax),
        ("|acc| (m/s²)", np.abs(sp.a[:, :2]), opts.amax),
        ("|jerk| (m/s³)", np.abs(sp.j[:, :2]), opts.jmax),
    )
    for k, (label, values, limit) in enumerate(rows):
        ax = panels[k]
        for i in range(values.shape[1]):
            name = "" if values.shape[1] == 1 else "xyz"[i]
            ax.plot(sp.t, values[:, i], lw=0.9, label=name or None)
        ax.axhline(limit, ls="--", color="k", lw=0.8)
        ax.set_ylabel(label)
        if values.shape[1] > 1:
            ax.legend(loc="upper right", fontsize=8)
    ax.set_xlabel("t (s)")
    save_png(fig, path, dpi=100)  # (110 before: 0.145 s for the L-shaped field, now 0.13 s)
