"""turning_points: split-and-merge of paper 000, section 4."""

from __future__ import annotations

import itertools
import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from skyquill.errors import InputError
from skyquill.strokes import Strokes, hanzi_strokes, text_strokes, turning_points

_CORNERS = np.array([(0, 0), (4, 0), (4, 3), (1, 5), (5, 9), (8, 1), (10, 4)], dtype=float)


def _noisy_polyline(
    rng: np.random.Generator, step: float, noise: float
) -> tuple[np.ndarray, np.ndarray]:
    """Points every ``step`` along the corner polyline, plus uniform noise; corner indices."""
    parts = [_CORNERS[:1]]
    index = [0]
    for a, b in itertools.pairwise(_CORNERS):
        n = int(np.ceil(np.linalg.norm(b - a) / step))
        t = np.linspace(0.0, 1.0, n + 1)[1:, None]
        parts.append(a + t * (b - a))
        index.append(index[-1] + n)
    pts = np.concatenate(parts)
    return pts + rng.uniform(-noise, noise, pts.shape), np.asarray(index)


def _max_excess(stroke: np.ndarray, idx: np.ndarray) -> float:
    """Largest distance of any point to its own kept segment.

    Scalar Python, one point at a time, independent of the vectorised code under
    test: the foot of the perpendicular clamped to the segment.
    """
    worst = 0.0
    for a, b in itertools.pairwise(idx):
        p0, p1 = stroke[a], stroke[b]
        for q in stroke[a : b + 1]:
            v = p1 - p0
            L2 = float(v @ v)
            t = 0.0 if L2 == 0.0 else min(1.0, max(0.0, float((q - p0) @ v) / L2))
            foot = p0 + t * v
            worst = max(worst, float(np.hypot(*(q - foot))))
    return worst


@pytest.mark.parametrize("seed", range(10))
def test_known_corners_are_recovered_exactly_under_noise(seed: int) -> None:
    rng = np.random.default_rng(seed)
    pts, corners = _noisy_polyline(rng, step=0.05, noise=0.003)
    np.testing.assert_array_equal(turning_points(pts, 0.1), corners)


def test_straight_stroke_keeps_only_its_ends() -> None:
    pts = np.column_stack([np.linspace(0, 1, 50), np.zeros(50)])
    np.testing.assert_array_equal(turning_points(pts, 1e-6), [0, 49])
    np.testing.assert_array_equal(turning_points(pts[:2], 1.0), [0, 1])


def test_doubling_back_is_caught_by_segment_distance() -> None:
    # out along the x axis and back: every point is on the line through the ends,
    # so only a distance to the *segment* sees the turn at x = 1
    x = np.concatenate([np.linspace(0, 1, 11), np.linspace(0.9, 0.2, 8)])
    pts = np.column_stack([x, np.zeros_like(x)])
    np.testing.assert_array_equal(turning_points(pts, 0.05), [0, 10, 18])


def test_closed_stroke() -> None:
    t = np.linspace(0, 2 * np.pi, 101)
    pts = np.column_stack([np.cos(t), np.sin(t)])  # starts and ends at (1, 0)
    idx = turning_points(pts, 0.01)
    assert idx[0] == 0 and idx[-1] == 100 and idx.size > 8
    assert _max_excess(pts, idx) <= 0.01


def test_merge_drops_a_split_point() -> None:
    pts = np.array([[3.0, 0.0], [0.0, 4.0], [1.0, 9.0], [3.0, 7.0]])
    # split: chord 0-3 leaves (0, 4) at 3 > 2.5, then chord 1-3 leaves (1, 9) at 2.83;
    # merge: (0, 4) is within 2.5 of the chord from (3, 0) to (1, 9), so it goes
    np.testing.assert_array_equal(turning_points(pts, 2.5), [0, 2, 3])


def test_on_real_strokes() -> None:
    for strokes in (text_strokes("Hi").scaled(1.0), hanzi_strokes("永").scaled(1.0)):
        for path in strokes.paths:
            idx = turning_points(path, 0.01)
            assert _max_excess(path, idx) <= 0.01


_polyline = st.integers(2, 40).flatmap(
    lambda k: arrays(
        np.float64,
        (k, 2),
        elements=st.floats(-100, 100, allow_nan=False, allow_infinity=False, width=32),
    )
)


@settings(max_examples=400, deadline=None)
@given(stroke=_polyline, threshold=st.floats(1e-3, 200.0))
def test_every_point_within_threshold_of_its_kept_segment(
    stroke: np.ndarray, threshold: float
) -> None:
    idx = turning_points(stroke, threshold)
    k = stroke.shape[0]
    assert idx.dtype.kind == "i"
    assert idx[0] == 0 and idx[-1] == k - 1
    assert np.all(np.diff(idx) > 0)
    assert _max_excess(stroke, idx) <= threshold * (1 + 1e-9) + 1e-12


def test_million_points_in_bounded_time() -> None:
    rng = np.random.default_rng(0)
    t = np.linspace(0.0, 20.0 * np.pi, 1_000_000)
    pts = np.column_stack([t * np.cos(t), t * np.sin(t)]) + rng.normal(0.0, 0.01, (t.size, 2))
    start = time.perf_counter()
    idx = turning_points(pts, 0.5)
    elapsed = time.perf_counter() - start
    # Not a benchmark (bench/ measures speed): a guard against a quadratic blow-up, which
    # would take minutes here; ~2 s on an idle machine, 5-6 s when the 2 cores are shared.
    assert elapsed < 30.0
    assert idx[0] == 0 and idx[-1] == t.size - 1 and 50 < idx.size < 2000
    # spot-check the guarantee on a few segments
    for j in rng.integers(0, idx.size - 1, 20):
        a, b = idx[j], idx[j + 1]
        assert _max_excess(pts[a : b + 1], np.array([0, b - a])) <= 0.5


@pytest.mark.timeout(60)  # a hang guard, not a speed claim: ~0.5 s on a quiet machine
def test_long_random_walk_with_many_corners() -> None:
    rng = np.random.default_rng(1)
    pts = np.cumsum(rng.normal(0.0, 1.0, (300_000, 2)), axis=0)
    idx = turning_points(pts, 0.5)  # most points are corners at this threshold
    assert idx.size > 100_000


def test_bad_threshold() -> None:
    pts = np.array([[0.0, 0.0], [1.0, 1.0]])
    with pytest.raises(InputError, match=r"threshold: got 0, expected a number > 0"):
        turning_points(pts, 0.0)
    with pytest.raises(InputError, match=r"threshold: got -1, expected a number > 0"):
        turning_points(pts, -1.0)
    with pytest.raises(InputError, match="threshold: got nan, expected a finite number"):
        turning_points(pts, float("nan"))


def test_bad_stroke() -> None:
    with pytest.raises(InputError, match=r"stroke: got 1 point\(s\), expected at least 2"):
        turning_points(np.array([[0.0, 0.0]]), 1.0)
    with pytest.raises(InputError, match=r"stroke: got 1 NaN or infinite value"):
        turning_points(np.array([[0.0, 0.0], [np.nan, 1.0]]), 1.0)
    with pytest.raises(InputError, match=r"stroke: got an array of shape \(3,\)"):
        turning_points(np.zeros(3), 1.0)


def test_works_on_scaled_strokes_in_metres() -> None:
    s = Strokes(paths=(np.array([[0.0, 0.0], [50.0, 1.0], [100.0, 0.0], [100.0, 80.0]]),))
    path = s.scaled(2.0).paths[0]  # 100 units -> 2 m, the bump is 2 cm
    np.testing.assert_array_equal(turning_points(path, 0.05), [0, 2, 3])
    np.testing.assert_array_equal(turning_points(path, 0.01), [0, 1, 2, 3])


@settings(max_examples=200, deadline=None)
@given(
    stroke=arrays(
        np.float64,
        st.tuples(st.integers(2, 64), st.just(2)),
        elements=st.floats(-10.0, 10.0, allow_nan=False, allow_infinity=False),
    ),
    threshold=st.floats(1e-3, 5.0),
)
def test_short_strokes_in_python_match_the_vectorised_sweep(
    stroke: np.ndarray, threshold: float
) -> None:
    """Strokes of at most 64 points are simplified point by point in Python: the same
    turning points as the vectorised split and merge every longer stroke goes through."""
    from skyquill.strokes.turning import _merge, _split

    vectorised = _merge(stroke, _split(stroke, threshold), threshold)
    np.testing.assert_array_equal(turning_points(stroke, threshold), vectorised)
