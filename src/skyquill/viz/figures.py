"""Writing a figure as a PNG cheaply: what the pictures of every command share.

Profiled on ``fit`` and ``fly`` (issue 27, part 5), matplotlib spends its time on the
pictures' ticks and text, not on their lines: every tick is five artists (two tick
marks, a grid line, two labels) built on the first draw, every label a font layout, and
an axes places its title only after measuring its tick labels. ``fit``'s 2 x 2 figure of
2,000 samples per line took 0.6 s of CPU: 0.07 s building the figure, about 0.07 s
encoding the PNG, the rest drawing. So:

* at most :data:`MAX_TICKS` + 1 major ticks per axis where matplotlib's default locator
  would place up to ten (the same "nice" steps, 1, 2, 2.5, 5, 10; fewer where the axis is
  short, as before): a fifth less time;
* :func:`figure_style`: the title at a fixed height above the axes (``axes.titley``),
  which skips measuring the tick labels (no panel here has labels above its axes);
* zlib level 1 instead of Pillow's 6 for the PNG: flat colours and lines compress almost
  as well (the files of ``fit``, ``fly`` and ``paint`` grew 2 %, 8 % and 0.3 %).

Together ``fit``'s and ``fly``'s pictures take about 0.43 s of CPU instead of 0.59 s.
Constrained or tight layouts and ``bbox_inches="tight"`` draw a figure twice; the
figures here use fixed layouts instead.

Issue 27, part 5, second pass (run as a user runs them, a fresh ``skyquill`` process pays
for matplotlib's import inside the pictures' time):

* :func:`new_figure`: a :class:`~matplotlib.figure.Figure` on an Agg canvas, without
  ``matplotlib.pyplot`` (its import, its figure manager and its backend resolution: about
  0.1 s of a fresh process);
* :func:`stack_time_panels`: panels against the same time axis stacked and sharing it,
  the tick labels and the axis label drawn once, on the bottom panel: every tick label
  is a text layout, so three panels' worth of them cost three times one.
"""

from __future__ import annotations

from contextlib import AbstractContextManager
from pathlib import Path
from typing import Any

import matplotlib
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import AutoLocator, MaxNLocator

#: Most intervals between major ticks on an axis (matplotlib's default allows nine).
MAX_TICKS = 5
#: Steps of matplotlib's default locator (:class:`~matplotlib.ticker.AutoLocator`).
NICE_STEPS = (1.0, 2.0, 2.5, 5.0, 10.0)
#: zlib level of the PNGs written (Pillow's default is 6).
PNG_COMPRESSION = 1


def new_figure(figsize: tuple[float, float], dpi: float = 100.0) -> Figure:
    """A figure of ``figsize`` inches drawn by Agg, made without :mod:`matplotlib.pyplot`.

    Nothing holds on to it (no pyplot figure manager): it is freed with its last
    reference, so there is no ``close`` to call.
    """
    fig = Figure(figsize=figsize, dpi=dpi)
    FigureCanvasAgg(fig)  # attaches itself as fig.canvas: savefig writes PNGs through it
    return fig


def stack_time_panels(
    fig: Figure, rect: tuple[float, float, float, float], n: int, hspace: float = 0.12
) -> list[Axes]:
    """``n`` panels stacked in ``rect`` (left, bottom, width, height; figure fraction),
    sharing one time axis whose tick labels only the bottom panel draws.

    ``hspace``: the gap between two panels, a fraction of a panel's height (room for a
    title above each panel needs about 0.4).
    """
    grid = fig.add_gridspec(
        n, 1, left=rect[0], bottom=rect[1], right=rect[0] + rect[2], top=rect[1] + rect[3],
        hspace=hspace,
    )  # fmt: skip
    panels: list[Axes] = []
    for k in range(n):
        panels.append(fig.add_subplot(grid[k, 0], sharex=panels[0] if panels else None))
    for panel in panels[:-1]:
        panel.tick_params(labelbottom=False)
    return panels


def figure_style() -> AbstractContextManager[None]:
    """Settings to create a figure's axes under: each title at a fixed height (``with``)."""
    return matplotlib.rc_context({"axes.titley": 1.0})


def save_png(fig: Figure, path: str | Path, dpi: float, **savefig: Any) -> None:
    """Write ``fig`` to the PNG ``path`` with fewer ticks and faster compression.

    Axes whose ticks were left to matplotlib's default locator get at most
    :data:`MAX_TICKS` intervals (no more than the default would have placed); log axes,
    colour bars with their own locators and axes without ticks are left alone.

    Parameters
    ----------
    fig
        The figure, drawn once here.
    path
        PNG file to write.
    dpi
        Resolution, dots per inch.
    **savefig
        Further :meth:`matplotlib.figure.Figure.savefig` arguments (``facecolor``).
    """
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            if type(axis.get_major_locator()) is AutoLocator:
                room = max(1, min(9, axis.get_tick_space()))
                locator = MaxNLocator(nbins=min(MAX_TICKS, room), steps=list(NICE_STEPS))
                axis.set_major_locator(locator)
    fig.savefig(path, dpi=dpi, pil_kwargs={"compress_level": PNG_COMPRESSION}, **savefig)
