"""Hypothesis strategies for random regions, shared by the coverage tests."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st


@st.composite
def star_shaped(
    draw: st.DrawFn,
    *,
    vertices: tuple[int, int],
    size_m: tuple[float, float],
    radius: tuple[float, float],
) -> np.ndarray:
    """Vertex lists ``(K, 2)`` at sorted random angles and random radii (mostly concave).

    ``vertices``, ``size_m`` (across) and ``radius`` (fraction of half the
    size) are ``(low, high)`` ranges.
    """
    count = draw(st.integers(*vertices))
    size = draw(st.floats(*size_m))
    angles = np.sort(draw(st.lists(st.floats(0.0, 2 * np.pi), min_size=count, max_size=count)))
    radii = draw(st.lists(st.floats(*radius), min_size=count, max_size=count))
    return np.c_[np.cos(angles), np.sin(angles)] * (0.5 * size * np.asarray(radii))[:, None]
