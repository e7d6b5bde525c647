"""Formations: spacing kept, counts refused with both numbers, on the vertical plane."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.distance import pdist

from skyquill.errors import InputError
from skyquill.show.formation import (
    circle_capacity,
    circle_formation,
    grid_formation,
    home_grid,
    shape_formation,
)
from skyquill.strokes import typed_strokes

ORIGIN = np.array([-5.0, 2.0, 10.0])


def test_text_formation_spreads_drones_on_the_plane_at_least_the_spacing_apart() -> None:
    f = shape_formation(typed_strokes("SQ"), 12, origin=ORIGIN, size_m=12.0, spacing_m=1.5)
    assert f.points.shape == (12, 3)
    assert pdist(f.points).min() >= 1.5
    assert f.spacing_m == pytest.approx(pdist(f.points).min())
    np.testing.assert_allclose(f.points[:, 1], 2.0)  # on the plane y = origin y
    assert f.points[:, 0].min() >= -5.0 - 1e-9 and f.points[:, 0].max() <= 7.0 + 1e-9
    # spread: the points cover most of the drawing's width, not one corner
    assert np.ptp(f.points[:, 0]) > 8.0


def test_more_drones_than_the_shape_holds_names_both_counts() -> None:
    with pytest.raises(InputError, match=r"drones: got 50, expected at most \d+ "):
        shape_formation(typed_strokes("I"), 50, origin=ORIGIN, size_m=5.0, spacing_m=1.5)


def test_chinese_character_formation() -> None:
    f = shape_formation(typed_strokes("永"), 10, origin=ORIGIN, size_m=10.0, spacing_m=1.0)
    assert pdist(f.points).min() >= 1.0


def test_circle_capacity_and_refusal() -> None:
    n = circle_capacity(4.0, 1.5)
    f = circle_formation(n, center=ORIGIN, radius_m=4.0, spacing_m=1.5)
    assert pdist(f.points).min() >= 1.5
    with pytest.raises(InputError, match=rf"drones: got {n + 1}, expected at most {n} "):
        circle_formation(n + 1, center=ORIGIN, radius_m=4.0, spacing_m=1.5)


def test_grid_and_pads_refuse_a_spacing_below_the_safety_distance() -> None:
    with pytest.raises(InputError, match="spacing: got 1 m, expected at least"):
        grid_formation(4, origin=ORIGIN, columns=2, spacing_m=1.0, safety_m=1.5)
    with pytest.raises(InputError, match="home_spacing: got 1 m, expected at least"):
        home_grid(4, origin=np.zeros(2), spacing_m=1.0, safety_m=1.5)
    pads = home_grid(10, origin=np.zeros(2), spacing_m=2.0, safety_m=2.0)
    assert pads.shape == (10, 3) and np.all(pads[:, 2] == 0.0)
    assert pdist(pads).min() >= 2.0
