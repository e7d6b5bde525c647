"""polyline_distance(s): exact (against the table of every point and segment), in linear memory."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from skyquill.errors import InputError
from skyquill.geometry import polyline_distance, polyline_distances


def _table(p: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Every point against every segment: the reference (quadratic memory)."""
    a, ab = v[:-1], v[1:] - v[:-1]
    length2 = (ab * ab).sum(1)
    q = p[:, None, :] - a[None]
    s = np.clip((q * ab[None]).sum(2) / np.where(length2 > 0, length2, 1.0), 0.0, 1.0)
    gap = q - s[:, :, None] * ab[None]
    return np.sqrt((gap * gap).sum(2).min(1))


coords = st.floats(-100.0, 100.0, allow_nan=False, allow_infinity=False)


@settings(max_examples=150, deadline=None)
@given(
    v=arrays(np.float64, st.tuples(st.integers(2, 30), st.just(2)), elements=coords),
    p=arrays(np.float64, st.tuples(st.integers(1, 40), st.just(2)), elements=coords),
)
def test_the_distance_is_the_nearest_segments(v: np.ndarray, p: np.ndarray) -> None:
    np.testing.assert_allclose(polyline_distance(p, v), _table(p, v), rtol=1e-9, atol=1e-9)


@settings(max_examples=40, deadline=None)
@given(
    sizes=st.lists(st.tuples(st.integers(0, 40), st.integers(2, 30)), min_size=0, max_size=8),
    seed=st.integers(0, 2**16),
    dim=st.sampled_from([2, 3]),
)
def test_many_pairs_at_once_are_each_pairs_distance_bit_for_bit(
    sizes: list[tuple[int, int]], seed: int, dim: int
) -> None:
    rng = np.random.default_rng(seed)
    pairs = [(rng.normal(size=(n, dim)), rng.normal(size=(v, dim))) for n, v in sizes]
    # A repeated vertex (a zero-length segment) and one pair above the table's size.
    if pairs:
        pairs[0][1][1] = pairs[0][1][0]
    pairs.append((rng.normal(size=(300, dim)), rng.normal(size=(120, dim))))
    joint = polyline_distances(pairs)
    assert len(joint) == len(pairs)
    for (p, v), d in zip(pairs, joint, strict=True):
        assert np.array_equal(d, polyline_distance(p, v))


def test_three_dimensions_repeated_vertices_and_a_long_segment() -> None:
    rng = np.random.default_rng(3)
    v = np.cumsum(rng.normal(size=(50, 3)), axis=0)
    v[10:13] = v[10]
    v[30] = v[29] + 500.0  # one segment far longer than the others
    p = rng.normal(size=(500, 3)) * 50.0
    np.testing.assert_allclose(polyline_distance(p, v), _table(p, v), rtol=1e-9, atol=1e-9)


def test_memory_grows_with_the_points_and_segments_not_their_product() -> None:
    """Issue 25: the write of one SVG path spent 6.7 GB in this table."""
    t = np.linspace(0.0, 60.0, 60_000)
    v = np.column_stack([np.cos(t), np.sin(t)])
    tracemalloc.start()
    try:
        polyline_distance(v[::2] + 1e-3, v)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 100 * 2**20  # the table would take 30,000 x 60,000 x 16 B = 29 GB


def test_the_k_d_tree_and_the_table_agree_above_and_below_the_switch() -> None:
    """Many pairs go through the k-d tree, few through the table: the same distances."""
    rng = np.random.default_rng(5)
    v = np.cumsum(rng.normal(size=(120, 2)), axis=0)
    p = v[rng.integers(0, 120, 1_000)] + rng.normal(size=(1_000, 2))  # 119,000 pairs
    many = polyline_distance(p, v)
    few = np.concatenate([polyline_distance(p[i : i + 50], v) for i in range(0, 1_000, 50)])
    np.testing.assert_allclose(many, _table(p, v), rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(few, _table(p, v), rtol=1e-9, atol=1e-9)


def test_many_pairs_refuse_what_one_pair_refuses() -> None:
    good = (np.zeros((3, 2)), np.array([[0.0, 0.0], [1.0, 0.0]]))
    with pytest.raises(InputError, match="points: got 1 NaN"):
        polyline_distances([good, (np.array([[np.nan, 0.0]]), good[1])])
    with pytest.raises(InputError, match="vertices: got an array of shape"):
        polyline_distances([good, (good[0], np.zeros((2, 3)))])
    with pytest.raises(InputError, match="vertices: got 1 vertex"):
        polyline_distances([(good[0], np.zeros((1, 2)))])
    with pytest.raises(InputError, match="pairs: got points of"):
        polyline_distances([good, (np.zeros((2, 3)), np.zeros((2, 3)))])
