"""Time allocation (paper 003 §3.5) against closed forms and dense simulation."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.optimize import LineDeviation, PointDeviation
from skyquill.optimize.timing import (
    allocate_path_times,
    allocate_segment_times,
    rest_to_rest_distance,
    rest_to_rest_time,
    segment_chain_terms,
)


def test_rest_to_rest_trapezoid_and_triangle() -> None:
    # Trapezoid: 10 m at 2 m/s, 1 m/s^2: 2 s up, 3 s cruise, 2 s down.
    assert rest_to_rest_time(10.0, 2.0, 1.0) == pytest.approx(7.0)
    # Triangle: 1 m never reaches 2 m/s: t = 2 sqrt(d / a).
    assert rest_to_rest_time(1.0, 2.0, 1.0) == pytest.approx(2.0)
    assert rest_to_rest_time(0.0, 2.0, 1.0) == 0.0


@settings(max_examples=50, deadline=None)
@given(st.floats(0.01, 50.0), st.floats(0.1, 5.0), st.floats(0.1, 5.0))
def test_profile_respects_limits_and_arrives(distance: float, vmax: float, amax: float) -> None:
    total = rest_to_rest_time(distance, vmax, amax)
    t = np.linspace(0.0, total, 4001)
    s = rest_to_rest_distance(t, distance, vmax, amax)
    assert s[0] == 0.0
    assert s[-1] == pytest.approx(distance, rel=1e-9, abs=1e-12)
    v = np.diff(s) / np.diff(t)
    assert v.max() <= vmax * (1 + 1e-9)
    assert np.all(np.diff(s) >= -1e-12)
    # Minimal: with any less time the distance is out of reach at these limits.
    assert rest_to_rest_distance(np.array([0.99 * total]), distance, vmax, amax)[0] < distance


def test_segment_times_are_cumulative_rest_to_rest() -> None:
    wp = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 1.0]])
    assert allocate_segment_times(wp, 2.0, 1.0) == pytest.approx([0.0, 7.0, 9.0])


def test_path_allocation_reduces_to_rest_to_rest_on_a_line() -> None:
    line = np.column_stack([np.linspace(0.0, 10.0, 201), np.zeros(201)])
    t = allocate_path_times(line, 2.0, 1.0)
    assert t[-1] == pytest.approx(7.0, rel=1e-9)
    assert np.all(np.diff(t) > 0)


def test_path_allocation_slows_in_tight_turns() -> None:
    theta = np.linspace(0.0, 2 * np.pi, 400)
    small = 0.1 * np.column_stack([np.cos(theta), np.sin(theta)])
    big = 10.0 * small
    # Same speed limit: the small circle is limited by v^2 / r <= a.
    t_small = allocate_path_times(small, 2.0, 1.0)[-1]
    perimeter = 2 * np.pi * 0.1
    assert t_small >= perimeter / np.sqrt(1.0 * 0.1) * 0.98
    assert allocate_path_times(big, 2.0, 1.0)[-1] > t_small


def test_segment_chain_terms_structure() -> None:
    wp = np.array([[0.0, 0.0, 1.0], [3.0, 0.0, 1.0], [3.0, 2.0, 1.5]])
    times = allocate_segment_times(wp, 2.0, 1.0)
    terms = segment_chain_terms(wp, times, 2.0, 1.0, kappa=0.25)
    points, *lines = terms
    assert isinstance(points, PointDeviation)
    assert points.points.shape == (1 + 3 * 2, 3)
    assert all(isinstance(line, LineDeviation) for line in lines)
    assert len(lines) == 2
    # Intermediate points lie on their segment, in order.
    seg = wp[1] - wp[0]
    for p in points.points[1:3]:
        along = (p - wp[0]) @ seg / (seg @ seg)
        assert 0.0 < along < 1.0
        assert np.linalg.norm(p - wp[0] - along * seg) < 1e-12
    assert lines[0].t_start == pytest.approx(0.25 * times[1])


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: rest_to_rest_time(-1.0, 1.0, 1.0), "distance: got -1, expected a number >= 0"),
        (lambda: rest_to_rest_time(1.0, 0.0, 1.0), "vmax: got 0, expected a number > 0"),
        (lambda: allocate_segment_times(np.zeros((1, 2)), 1.0, 1.0), "at least 2"),
        (lambda: allocate_segment_times(np.zeros((2, 2)), 1.0, 1.0), "equal"),
        (lambda: allocate_path_times(np.zeros((3, 2)), 1.0, 1.0), "all points equal"),
        (lambda: allocate_path_times(np.array([[0.0, np.nan], [1, 1]]), 1, 1), "NaN"),
        (
            lambda: segment_chain_terms(np.eye(2), np.array([0.0, 1.0]), 1.0, 1.0, kappa=0.7),
            r"kappa: got 0.7, expected a fraction in \(0, 0.5\)",
        ),
    ],
)
def test_bad_input_is_named(call: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        call()  # type: ignore[operator]
