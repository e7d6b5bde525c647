"""Transitions: optimal assignment, limits, proven separation, delays, refusals."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.distance import pdist

from skyquill.errors import InfeasibleError
from skyquill.optimize.legs import LegLimits
from skyquill.show import ShowDrone, ShowLimits, check_show
from skyquill.show.transition import assign, plan_transition
from skyquill.trajectory import dense_times

LIMITS = LegLimits(3.0, 2.0, 10.0)


def _cost(a: np.ndarray, b: np.ndarray, perm: np.ndarray) -> float:
    return float(((a - b[perm]) ** 2).sum())


@pytest.mark.parametrize("seed", range(5))
def test_assignment_is_optimal_against_brute_force(seed: int) -> None:
    rng = np.random.default_rng(seed)
    a, b = rng.uniform(-5, 5, (6, 3)), rng.uniform(-5, 5, (6, 3))
    best = min(_cost(a, b, np.array(p)) for p in itertools.permutations(range(6)))
    assert _cost(a, b, assign(a, b)) == pytest.approx(best)


def test_assignment_picks_the_nearest_subset_of_more_goals() -> None:
    a = np.array([[0.0, 0, 0], [10.0, 0, 0]])
    b = np.array([[50.0, 0, 0], [9.0, 0, 0], [1.0, 0, 0]])
    np.testing.assert_array_equal(assign(a, b), [2, 1])


def _verify(starts: np.ndarray, goals: np.ndarray, safety: float) -> None:
    """Independent of the planner: skyquill check, and dense sampled distances."""
    moves = plan_transition(starts, goals, LIMITS, safety)
    flights = [moves.trajectory(i) for i in range(len(starts))]
    report = check_show(
        [ShowDrone(f, f"d{i}") for i, f in enumerate(flights)],
        safety,
        ShowLimits(3.0 + 1e-6, 3.0 + 1e-6, 3.0 + 1e-6, 2.0 + 1e-6, None, None),
    )
    assert report.passed, report.violations[:2]
    t = dense_times(np.array([0.0, moves.duration]))
    p = np.stack([f.evaluate(t) for f in flights], axis=1)  # (T, N, 3)
    closest = min(pdist(row).min() for row in p[:: max(1, len(t) // 4000)])
    assert closest >= safety
    for i, f in enumerate(flights):
        np.testing.assert_allclose(f.evaluate(np.array([f.duration]))[0], goals[i], atol=1e-9)


def test_grid_to_circle_is_proven_apart() -> None:
    k = np.arange(16)
    grid = np.column_stack([3.0 * (k % 4), np.zeros(16), 5.0 + 3.0 * (k // 4)])
    angle = 2 * np.pi * k / 16
    circle = np.column_stack([4.5 + 8 * np.sin(angle), np.zeros(16), 9.5 + 8 * np.cos(angle)])
    _verify(grid, circle[assign(grid, circle)], 2.0)


def test_a_crossing_is_resolved_by_the_faster_of_delays_and_layers() -> None:
    # Straight synchronised paths cross in the middle.
    starts = np.array([[0.0, 0, 5], [0.0, 0, 15]])
    goals = np.array([[10.0, 0, 15], [10.0, 0, 5]])
    moves = plan_transition(starts, goals, LIMITS, 2.0)
    assert moves.closest_m >= 2.0
    waves = moves.legs[0].waves
    assert len(moves.legs) == 3 or sorted(waves.tolist()) == [0, 1]
    _verify(starts, goals, 2.0)


def test_a_crossing_where_layers_are_blocked_is_resolved_by_a_delay() -> None:
    # Drones that stay on both sides of the plane leave no room to step out: one waits.
    still = np.array([[0.0, -2.5, 5], [0.0, -2.5, 15], [0.0, 2.5, 5], [0.0, 2.5, 15]])
    starts = np.vstack([[[0.0, 0, 5], [0.0, 0, 15]], still])
    goals = np.vstack([[[10.0, 0, 15], [10.0, 0, 5]], still])
    moves = plan_transition(starts, goals, LIMITS, 2.0)
    assert len(moves.legs) == 1
    assert moves.waves.tolist() == [0, 1, -1, -1, -1, -1]
    _verify(starts, goals, 2.0)


def test_a_swap_on_one_line_is_resolved_by_a_depth_layer() -> None:
    # No delay helps (each waits where the other passes): one drone steps out of the plane.
    starts = np.array([[0.0, 0, 5], [10.0, 0, 5]])
    moves = plan_transition(starts, starts[::-1].copy(), LIMITS, 2.0)
    assert len(moves.legs) == 3
    assert sorted(np.abs(moves.layers).tolist()) == [0, 1]
    _verify(starts, starts[::-1].copy(), 2.0)


def test_an_impossible_swap_names_the_pair_and_the_time() -> None:
    # Swapping along the layers' own axis: stepping out runs into the other drone.
    starts = np.array([[0.0, 0, 5], [0.0, 2.5, 5]])
    with pytest.raises(InfeasibleError, match=r"drone 0 and drone 1 come within 0\.000 m at t = "):
        plan_transition(starts, starts[::-1].copy(), LIMITS, 2.0)


def test_a_path_through_a_drone_that_stays_steps_around_it() -> None:
    starts = np.array([[0.0, 0, 5], [5.0, 0, 5]])
    goals = np.array([[10.0, 0, 5], [5.0, 0, 5]])
    moves = plan_transition(starts, goals, LIMITS, 2.0)
    assert len(moves.legs) == 3
    _verify(starts, goals, 2.0)


def test_a_drone_that_stays_in_the_way_of_a_layer_is_refused() -> None:
    # 0 crosses the point where 1 stays; stepping out along y runs into 2, which stays too.
    starts = np.array([[0.0, 0, 5], [5.0, 0, 5], [5.0, -2.5, 5], [5.0, 2.5, 5]])
    goals = np.array([[10.0, 0, 5], [5.0, 0, 5], [5.0, -2.5, 5], [5.0, 2.5, 5]])
    with pytest.raises(InfeasibleError, match=r"drone 0 and drone 1 come within 0\.000 m at t = "):
        plan_transition(starts, goals, LIMITS, 2.0)


def _spread(points: np.ndarray, spacing: float) -> np.ndarray:
    """Points of a random cloud at least ``spacing`` apart (greedy)."""
    kept: list[np.ndarray] = []
    for p in points:
        if all(np.linalg.norm(p - q) >= spacing for q in kept):
            kept.append(p)
    return np.array(kept)


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**31), n=st.integers(2, 12), shuffle=st.booleans())
def test_random_planar_formations_always_transition_safely(
    seed: int, n: int, shuffle: bool
) -> None:
    # Formations on the plane y = 0 (as the shows' are): delays or layers always work,
    # even for a deliberately bad (random) assignment.
    rng = np.random.default_rng(seed)
    a = _spread(rng.uniform(0, 10, (80, 3)) * [1, 0, 1], 2.0)[:n]
    b = _spread(rng.uniform(0, 10, (80, 3)) * [1, 0, 1] + [4, 0, 2], 2.0)[: len(a)]
    a = a[: len(b)]
    goals = b[rng.permutation(len(b))] if shuffle else b[assign(a, b)]
    _verify(a, goals, 2.0)


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**31), n=st.integers(2, 12))
def test_random_formations_transition_safely_or_are_refused(seed: int, n: int) -> None:
    rng = np.random.default_rng(seed)
    a = _spread(rng.uniform(0, 12, (60, 3)), 2.0)[:n]
    b = _spread(rng.uniform(0, 12, (60, 3)) + np.array([6.0, 0.0, 0.0]), 2.0)[: len(a)]
    a = a[: len(b)]
    goals = b[assign(a, b)]
    try:
        _verify(a, goals, 2.0)
    except InfeasibleError as exc:  # refused, never unsafe: the message names the pair
        assert "come within" in str(exc) and "at t = " in str(exc)
