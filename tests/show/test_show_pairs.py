"""Sweep and prune: exactly the pairs of boxes within the gap, against every pair compared."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.show import pairs
from skyquill.show.pairs import close_boxes


def _brute(lo: np.ndarray, hi: np.ndarray, gap: float, groups: np.ndarray) -> set[tuple[int, int]]:
    out = set()
    for i in range(len(lo)):
        for j in range(i + 1, len(lo)):
            far = np.maximum(0.0, np.maximum(lo[i] - hi[j], lo[j] - hi[i]))
            if groups[i] == groups[j] and np.linalg.norm(far) <= gap:
                out.add((i, j))
    return out


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 10**6),
    count=st.integers(0, 40),
    gap=st.floats(0.0, 3.0),
    windows=st.integers(1, 4),
    spread=st.sampled_from([1.0, 10.0, 1e4]),
)
def test_the_pairs_are_those_every_pair_compared_finds(
    seed: int, count: int, gap: float, windows: int, spread: float
) -> None:
    rng = np.random.default_rng(seed)
    lo = rng.uniform(-spread, spread, (count, 3))
    hi = lo + rng.exponential(1.0, (count, 3)) * (rng.random((count, 1)) < 0.7)
    groups = rng.integers(0, windows, count)
    first, second = close_boxes(lo, hi, gap, groups)
    assert set(zip(first.tolist(), second.tolist(), strict=True)) == _brute(lo, hi, gap, groups)
    assert np.all(first < second)
    assert np.all(np.diff(first * (count + 1) + second) > 0)  # sorted, no repeats


def test_boxes_that_touch_are_paired_and_a_gap_beyond_is_not() -> None:
    points = np.array([[0.0, 0, 0], [3.0, 0, 0], [6.0 + 1e-6, 0, 0]])
    first, second = close_boxes(points, points, 3.0)
    assert (first.tolist(), second.tolist()) == ([0], [1])


def test_batches_give_the_same_pairs(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = np.random.default_rng(3)
    lo = rng.uniform(0, 5, (60, 3))
    whole = close_boxes(lo, lo + 1.0, 1.0)
    monkeypatch.setattr(pairs, "BATCH", 7)
    batched = close_boxes(lo, lo + 1.0, 1.0)
    np.testing.assert_array_equal(whole[0], batched[0])
    np.testing.assert_array_equal(whole[1], batched[1])


def test_a_grid_of_drones_pairs_only_neighbours() -> None:
    k = np.arange(10_000)
    centres = np.column_stack([4.0 * (k % 100), np.zeros(k.size), 4.0 * (k // 100)])
    first, _ = close_boxes(centres - 0.5, centres + 0.5, 3.0)
    assert first.size == 2 * 100 * 99  # the horizontal and vertical neighbours, 3 m apart
