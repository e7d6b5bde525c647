"""ink.png: the input, the simulated ink and the two overlaid, side by side."""

from __future__ import annotations

from pathlib import Path

import matplotlib.image
import numpy as np
import pytest

from skyquill.calligraphy.ink import ink_fidelity
from skyquill.viz.ink_plot import render_ink

L, W = 0.2, 0.01  # stroke length and width, m


@pytest.mark.parametrize("offset", [0.004, None])
def test_render_ink_writes_a_png(tmp_path: Path, offset: float | None) -> None:
    stroke = [np.array([[0.0, 0.0], [L, 0.0]])]
    if offset is None:  # no ink at all: the input alone, and no deviation in the title
        fidelity = ink_fidelity([], [], stroke, W)
    else:
        ink = np.column_stack([np.linspace(0.0, L, 50), np.full(50, offset)])
        fidelity = ink_fidelity([ink], [np.full(50, W)], stroke, W)
    render_ink(fidelity, tmp_path / "ink.png", "test")
    image = matplotlib.image.imread(tmp_path / "ink.png")
    assert image.ndim == 3 and image.shape[1] > 2 * image.shape[0]  # three panels side by side
    assert image[..., :3].min() < 0.3  # something dark was drawn
