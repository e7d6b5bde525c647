"""Strokes: validation, bounds, scaling."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.strokes import Strokes


def _two() -> tuple[np.ndarray, np.ndarray]:
    return np.array([[0.0, 0.0], [2.0, 1.0]]), np.array([[1.0, 3.0], [1.0, -1.0], [0.5, 0.0]])


def test_bounds_and_n_points() -> None:
    s = Strokes(paths=_two())
    lo, hi = s.bounds()
    np.testing.assert_array_equal(lo, [0.0, -1.0])
    np.testing.assert_array_equal(hi, [2.0, 3.0])
    assert s.n_points == 5
    assert s.n_strokes == 2


def test_accepts_lists_and_stores_readonly_float_arrays() -> None:
    s = Strokes(paths=([[0, 0], [1, 1]],))  # type: ignore[arg-type]
    assert s.paths[0].dtype == np.float64
    with pytest.raises(ValueError, match="read-only"):
        s.paths[0][0, 0] = 5.0


def test_scaled_puts_larger_side_at_size_and_corner_at_origin() -> None:
    s = Strokes(paths=_two(), times=(np.array([0.0, 0.1]), np.array([0.2, 0.3, 0.4])))
    out = s.scaled(0.8)
    lo, hi = out.bounds()
    np.testing.assert_allclose(lo, [0.0, 0.0], atol=1e-15)
    # extent was (2, 4): the larger side (y) becomes 0.8, x keeps the aspect ratio
    np.testing.assert_allclose(hi, [0.4, 0.8], rtol=1e-12)
    assert out.times is not None and s.times is not None
    np.testing.assert_array_equal(out.times[1], s.times[1])
    # the shape is only scaled: every pairwise distance scales by 0.2
    np.testing.assert_allclose(np.diff(out.paths[1], axis=0), 0.2 * np.diff(s.paths[1], axis=0))


@pytest.mark.parametrize("size", [0.0, -1.0, float("nan"), float("inf"), "1"])
def test_scaled_rejects_bad_size(size: object) -> None:
    with pytest.raises(InputError, match="size"):
        Strokes(paths=_two()).scaled(size)  # type: ignore[arg-type]


def test_scaled_refuses_overflowing_factor() -> None:
    s = Strokes(paths=(np.array([[0.0, 0.0], [1e-320, 0.0]]),))
    with pytest.raises(InputError, match="overflows"):
        s.scaled(1.0)


def test_empty_stroke_list() -> None:
    with pytest.raises(InputError, match="empty list of strokes, expected at least one"):
        Strokes(paths=())


def test_one_point_stroke() -> None:
    with pytest.raises(InputError, match=r"stroke 1: got 1 point\(s\), expected at least 2"):
        Strokes(paths=(np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([[3.0, 4.0]])))


def test_repeated_points_name_the_stroke() -> None:
    with pytest.raises(InputError, match=r"stroke 2: got 3 points all equal to \(1, 2\)"):
        Strokes(paths=(*_two(), np.array([[1.0, 2.0]] * 3)))


def test_nan_is_refused() -> None:
    bad = np.array([[0.0, 0.0], [np.nan, 1.0]])
    with pytest.raises(InputError, match=r"stroke 0: got 1 NaN or infinite"):
        Strokes(paths=(bad,))


def test_wrong_shape_is_refused() -> None:
    with pytest.raises(InputError, match=r"stroke 0: got an array of shape \(2, 3\)"):
        Strokes(paths=(np.zeros((2, 3)),))


def test_huge_coordinates_are_refused() -> None:
    with pytest.raises(InputError, match="magnitude"):
        Strokes(paths=(np.array([[0.0, 0.0], [1e300, 0.0]]),))


def test_source_appears_in_messages() -> None:
    with pytest.raises(InputError, match=r"strokes from pad\.json: stroke 0"):
        Strokes(paths=(np.array([[0.0, 0.0]]),), source="pad.json")


def test_times_must_match_lengths() -> None:
    with pytest.raises(InputError, match=r"times of stroke 1: got an array of shape \(2,\)"):
        Strokes(paths=_two(), times=(np.array([0.0, 1.0]), np.array([2.0, 3.0])))


def test_times_count_must_match_strokes() -> None:
    with pytest.raises(InputError, match=r"got 1 time list\(s\), expected one per stroke \(2\)"):
        Strokes(paths=_two(), times=(np.array([0.0, 1.0]),))


def test_times_not_increasing_within_a_stroke() -> None:
    with pytest.raises(InputError, match=r"stroke 1: got t\[1\] = 3 followed by t\[2\] = 3"):
        Strokes(paths=_two(), times=(np.array([0.0, 1.0]), np.array([2.0, 3.0, 3.0])))


def test_times_not_increasing_across_strokes() -> None:
    with pytest.raises(InputError, match=r"stroke 1: starts at 0.5, not after the end of stroke 0"):
        Strokes(paths=_two(), times=(np.array([0.0, 1.0]), np.array([0.5, 3.0, 4.0])))


_scalars = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(10**30), max_value=10**30),
    st.booleans(),
    st.none(),
    st.text(max_size=3),
)
_jsonish = st.recursive(
    _scalars,
    lambda inner: st.one_of(
        st.lists(inner, max_size=5), st.dictionaries(st.text(max_size=3), inner, max_size=3)
    ),
    max_leaves=30,
)
_pointish = st.lists(
    st.one_of(
        st.tuples(st.floats(-1e3, 1e3), st.floats(-1e3, 1e3)).map(list),
        _jsonish,
    ),
    max_size=6,
)


@settings(max_examples=300, deadline=None)
@given(
    paths=st.one_of(_jsonish, st.lists(_pointish, max_size=4)),
    times=st.one_of(st.none(), _jsonish, st.lists(st.lists(st.floats(), max_size=6), max_size=4)),
)
def test_random_data_gives_strokes_or_input_error(paths: object, times: object) -> None:
    try:
        s = Strokes(paths=paths, times=times)  # type: ignore[arg-type]
    except InputError:
        return
    assert s.n_strokes >= 1
    for p in s.paths:
        assert p.ndim == 2 and p.shape[1] == 2 and p.shape[0] >= 2
        assert np.all(np.isfinite(p))
    try:
        out = s.scaled(1.0)
    except InputError:
        return
    assert np.max(out.bounds()[1]) == pytest.approx(1.0)
