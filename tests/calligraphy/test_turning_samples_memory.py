"""Finding a stroke's turning points among its route samples: right, in linear memory."""

from __future__ import annotations

import itertools
import tracemalloc

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.route import _nearest_by_table, _turning_samples


def _zigzag(n: int) -> np.ndarray:
    """A stroke on the board (z = 1) whose every vertex is a corner."""
    k = np.arange(n)
    return np.column_stack([1e-3 * k, 2e-3 * (k % 2), np.ones(n)])


def test_each_corner_is_found_at_its_own_sample() -> None:
    stroke = _zigzag(41)
    # The route densifies the stroke: the vertices are among the samples, in order.
    pieces = [np.linspace(a, b, 5, endpoint=False) for a, b in itertools.pairwise(stroke)]
    dense = np.concatenate([*pieces, stroke[-1:]])
    points = np.concatenate([np.zeros((7, 3)), dense])  # a transit before the stroke
    roles = np.concatenate([np.full(7, -1.0), np.zeros(dense.shape[0])])
    picked = _turning_samples((stroke,), Board(), points, roles, 1e-4)
    np.testing.assert_array_equal(points[picked], stroke)  # every vertex turns here


def test_memory_is_linear_in_the_samples() -> None:
    """Issue 25: samples x corners x 3 floats took 8.16 GiB for one 19,000-point SVG path."""
    stroke = _zigzag(19_000)
    dense = np.repeat(stroke, 4, axis=0)  # 76,000 samples, each vertex four times
    roles = np.zeros(dense.shape[0])
    tracemalloc.start()
    try:
        picked = _turning_samples((stroke,), Board(), dense, roles, 1e-4)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 200 * 2**20  # the table: 76,000 x 19,000 x 3 x 8 B = 32 GiB
    np.testing.assert_array_equal(picked[:3], [0, 4, 8])  # the first of equal samples


@settings(max_examples=80, deadline=None)
@given(
    samples=st.integers(1, 60),
    corners=st.integers(1, 8),
    grid=st.sampled_from([0.0, 1e-3]),
    seed=st.integers(0, 2**16),
)
def test_the_table_finds_the_k_d_trees_sample(
    samples: int, corners: int, grid: float, seed: int
) -> None:
    """Small strokes' corners by the table of every pair: the sample the k-d tree gives,
    the first of equally near ones (points on a grid make ties)."""
    rng = np.random.default_rng(seed)
    points = rng.uniform(0.0, 0.01, size=(samples, 3))
    if grid:
        points = np.round(points / grid) * grid  # repeated and equidistant samples
    near = rng.normal(0.0, grid or 1e-3, (corners, 3))
    targets = points[rng.integers(0, samples, corners)] + near
    tree = cKDTree(points)
    distance, _ = tree.query(targets)
    ties = tree.query_ball_point(targets, distance * (1.0 + 1e-12) + 1e-300)
    np.testing.assert_array_equal(_nearest_by_table(points, targets), [min(t) for t in ties])
