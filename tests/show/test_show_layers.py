"""Depth layers: as loose as asked, only along the plane's normal, never towards the ground."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.show.formation import grid_formation, home_grid
from skyquill.show.layers import layer_depths, plane_normal, spacing, step_out

SPREAD = math.sqrt(2.0) * 3.0


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 10**6),
    count=st.integers(2, 60),
    columns=st.integers(1, 12),
    gap=st.floats(3.0, 4.2),
    yaw=st.floats(-math.pi, math.pi),
)
def test_a_tight_vertical_formation_steps_out_along_its_normal_only(
    seed: int, count: int, columns: int, gap: float, yaw: float
) -> None:
    rng = np.random.default_rng(seed)
    grid = grid_formation(
        count, origin=rng.uniform(-50, 50, 3), columns=columns, spacing_m=gap, safety_m=3.0
    ).points
    turn = np.array(
        [[math.cos(yaw), -math.sin(yaw), 0], [math.sin(yaw), math.cos(yaw), 0], [0, 0, 1]]
    )
    points = grid @ turn.T
    layers = step_out(points, SPREAD)
    assert layers is not None
    assert spacing(layers.points) >= SPREAD
    moved = layers.points - points
    normal = plane_normal(points)
    assert normal is not None
    np.testing.assert_allclose(moved - np.outer(moved @ normal, normal), 0.0, atol=1e-9)
    np.testing.assert_allclose(moved @ normal, layers.depth * layers.step_m, atol=1e-9)
    assert np.abs(layers.depth).max() <= 1.5  # a grid needs two or three layers, centred


def test_loose_points_stay() -> None:
    points = grid_formation(20, origin=np.zeros(3), columns=5, spacing_m=4.5, safety_m=3.0).points
    layers = step_out(points, SPREAD)
    assert layers is not None and not layers.moved
    np.testing.assert_array_equal(layers.points, points)


def test_an_air_grid_steps_up_only() -> None:
    air = home_grid(25, origin=np.zeros(2), spacing_m=3.0, safety_m=3.0) + np.array([0.0, 0.0, 4.0])
    layers = step_out(air, SPREAD)
    assert layers is not None and layers.moved
    assert layers.normal.tolist() == [0.0, 0.0, 1.0]
    assert (layers.points[:, 2] >= 4.0).all()
    assert spacing(layers.points) >= SPREAD


def test_tight_points_off_any_plane_cannot_step_out() -> None:
    points = np.array([[0.0, 0, 0], [3.0, 0, 0], [0.0, 3, 0], [0.0, 0, 3]])
    assert step_out(points, SPREAD) is None


@pytest.mark.parametrize(
    ("count", "upward", "expected"),
    [(1, False, [0.0]), (2, False, [-0.5, 0.5]), (3, False, [0, -1, 1]), (3, True, [0, 1, 2])],
)
def test_layers_are_centred_on_a_vertical_plane(
    count: int, upward: bool, expected: list[float]
) -> None:
    assert layer_depths(count, upward=upward).tolist() == expected
