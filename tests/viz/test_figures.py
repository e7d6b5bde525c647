"""Saving figures cheaply (viz.figures): fewer ticks only where matplotlib chose them."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import FixedLocator, LogLocator
from PIL import Image

from skyquill.viz.figures import (
    MAX_TICKS,
    figure_style,
    new_figure,
    save_png,
    stack_time_panels,
)


def _ticks_in_view(axis: matplotlib.axis.Axis) -> int:
    low, high = sorted(axis.get_view_interval())
    return int(
        np.count_nonzero((axis.get_majorticklocs() >= low) & (axis.get_majorticklocs() <= high))
    )


def test_default_ticks_are_thinned_custom_and_log_ones_kept(tmp_path: Path) -> None:
    with figure_style():
        fig, (wide, log, fixed) = plt.subplots(
            1, 3, figsize=(15, 4), gridspec_kw={"width_ratios": (4, 1, 1)}
        )
    for ax in (wide, log, fixed):
        ax.plot(np.linspace(0.0, 8.0, 50), np.linspace(1.0, 1e4, 50))
        ax.set_title("a title at a fixed height")
    log.set_yscale("log")
    fixed.xaxis.set_major_locator(FixedLocator(np.linspace(0.0, 8.0, 12)))
    fig.canvas.draw()  # what matplotlib would draw by default
    before = _ticks_in_view(wide.xaxis)
    save_png(fig, tmp_path / "f.png", dpi=50)
    assert before > MAX_TICKS + 1  # the default would have placed more
    assert _ticks_in_view(wide.xaxis) <= MAX_TICKS + 1
    assert isinstance(log.yaxis.get_major_locator(), LogLocator)
    assert _ticks_in_view(fixed.xaxis) == 12
    assert wide.title.get_position()[1] == 1.0
    plt.close(fig)
    with Image.open(tmp_path / "f.png") as image:
        assert image.format == "PNG" and image.size == (750, 200)


def test_stacked_panels_share_one_time_axis_labelled_once(tmp_path: Path) -> None:
    fig = new_figure((8, 6))
    panels = stack_time_panels(fig, (0.1, 0.1, 0.8, 0.8), 3)
    for k, panel in enumerate(panels):
        panel.plot(np.linspace(0.0, 10.0 * (k + 1), 20), np.arange(20.0))
    save_png(fig, tmp_path / "s.png", dpi=50)
    limits = {panel.get_xlim() for panel in panels}
    assert len(limits) == 1 and max(limits)[1] >= 30.0  # one axis, spanning every panel
    labelled = [any(t.get_visible() for t in p.get_xticklabels()) for p in panels]
    assert labelled == [False, False, True]
    with Image.open(tmp_path / "s.png") as image:
        assert image.size == (400, 300)


def test_the_short_commands_figures_draw_without_pyplot() -> None:
    # pyplot's import, figure manager and backend resolution are a tenth of a second of a
    # fresh `skyquill fit` / `fly` / `write`: their figures are made without it.
    code = (
        "import sys\n"
        "import skyquill.viz.fit_plot, skyquill.viz.flight_plot, skyquill.viz.writing_plot\n"
        "assert 'matplotlib.pyplot' not in sys.modules, 'pyplot imported'\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
