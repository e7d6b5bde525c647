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
"""

from __future__ import annotations

from contextlib import AbstractContextManager
from pathlib import Path
from typing import Any

import matplotlib
from matplotlib.figure import Figure
from matplotlib.ticker import AutoLocator, MaxNLocator

#: Most intervals between major ticks on an axis (matplotlib's default allows nine).
MAX_TICKS = 5
#: Steps of matplotlib's default locator (:class:`~matplotlib.ticker.AutoLocator`).
NICE_STEPS = (1.0, 2.0, 2.5, 5.0, 10.0)
#: zlib level of the PNGs written (Pillow's default is 6).
PNG_COMPRESSION = 1


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
