"""The simulated ink beside the input: ``ink.png`` (:mod:`skyquill.calligraphy.ink` measures it)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import shapely
from shapely.geometry.base import BaseGeometry

from skyquill.calligraphy.ink import InkFidelity


def render_ink(fidelity: InkFidelity, path: str | Path, title: str = "") -> None:
    """Save the input, the simulated ink and the two overlaid, side by side, as a PNG.

    Parameters
    ----------
    fidelity
        The measure whose shapes are drawn (:func:`measure_ink`), (u, v) in m.
    path
        PNG file to write (the caller makes it atomic).
    title
        Put before the numbers in the figure's title.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(
        1, 3, figsize=(13, 4.8), sharex=True, sharey=True, layout="constrained"
    )
    grey, black = "0.7", "0.05"
    _fill(axes[0], fidelity.input_shape, grey, 1.0)
    _fill(axes[1], fidelity.ink_shape, black, 1.0)
    # Overlaid: grey alone is input the ink missed, red is ink off the input.
    _fill(axes[2], fidelity.input_shape, grey, 1.0)
    _fill(axes[2], fidelity.ink_shape, black, 0.6)
    _fill(axes[2], shapely.difference(fidelity.ink_shape, fidelity.input_shape), "C3", 1.0)
    names = (
        f"input at the planned width ({1e3 * fidelity.width_m:.1f} mm)",
        "simulated ink (width from the pressing depth)",
        "overlay (red: ink off the input)",
    )
    for ax, name in zip(axes, names, strict=True):
        ax.set(aspect="equal", title=name, xlabel="u (m)")
    axes[0].set_ylabel("v (m)")
    _frame(axes[0], fidelity)
    deviation = fidelity.max_deviation_m
    fig.suptitle(
        f"{title}  max deviation "
        + (f"{1e3 * deviation:.2f} mm" if math.isfinite(deviation) else "- (no ink)")
        + f", ink strokes {fidelity.ink_strokes} / {fidelity.input_strokes}, "
        f"IoU {fidelity.iou:.3f}"
    )
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _fill(ax: Any, shape: BaseGeometry, color: str, alpha: float) -> None:
    """Fill the polygons of ``shape`` (holes left open) on ``ax``."""
    from shapely.plotting import plot_polygon

    for polygon in shapely.get_parts(shape):
        if isinstance(polygon, shapely.Polygon) and not polygon.is_empty:
            plot_polygon(
                polygon, ax=ax, add_points=False, facecolor=color, edgecolor="none",
                linewidth=0.0, alpha=alpha,
            )  # fmt: skip


def _frame(ax: Any, fidelity: InkFidelity) -> None:
    """Limits that hold both shapes with a margin (shared by the three panels)."""
    both = shapely.union(fidelity.ink_shape, fidelity.input_shape)
    if both.is_empty:
        return
    u0, v0, u1, v1 = both.bounds
    margin = 0.05 * max(u1 - u0, v1 - v0, 1e-3)
    ax.set_xlim(u0 - margin, u1 + margin)
    ax.set_ylim(v0 - margin, v1 + margin)
