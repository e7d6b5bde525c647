"""Piecewise-linear cuts: the DP against brute force, the criterion, the one-sided screen."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from skyquill.errors import InputError
from skyquill.painting.segmentation import Splits, corner_or_step, fit_pieces, screen
from skyquill.painting.wall import Wall


def _line_rss(x: np.ndarray, y: np.ndarray) -> float:
    coef = np.polyfit(x, y, 1)
    return float(np.sum((np.polyval(coef, x) - y) ** 2))


def _brute(x: np.ndarray, y: np.ndarray, k: int, min_points: int, min_width: float) -> float:
    """Smallest RSS over every cut of the sorted points into k runs (the DP's definition)."""
    order = np.argsort(x)
    xs, ys = x[order], y[order]
    n = xs.size
    best = np.inf
    for cuts in itertools.combinations(range(1, n), k - 1):
        edges = [0, *cuts, n]
        runs = list(itertools.pairwise(edges))
        if any(b - a < min_points or xs[b - 1] - xs[a] < min_width for a, b in runs):
            continue
        best = min(best, sum(_line_rss(xs[a:b], ys[a:b]) for a, b in runs))
    return best


@pytest.mark.parametrize("seed", range(4))
def test_dp_finds_the_brute_force_optimum(seed: int) -> None:
    rng = np.random.default_rng(seed)
    x = rng.uniform(-1.5, 1.5, 13)
    wall = Wall.segmented([-15, 0, 12], (-1.5, 1.5))
    y = wall.depth(x) + rng.normal(0, 0.01, x.size)
    splits = Splits(x, y, max_pieces=3)
    for k in (2, 3):
        assert splits.pieces(k).rss == pytest.approx(_brute(x, y, k, 3, 0.1), rel=1e-9, abs=1e-12)


def test_the_criterion_picks_the_number_of_pieces() -> None:
    rng = np.random.default_rng(5)
    x = rng.uniform(-1.75, 1.75, 80)
    flat = fit_pieces(x, rng.normal(0, 0.0005, x.size))
    assert flat.n_pieces == 1
    wall = Wall.segmented([-10, 0, 10], (-1.75, 1.75))
    three = fit_pieces(x, wall.depth(x) + rng.normal(0, 0.0005, x.size))
    assert three.n_pieces == 3
    assert three.breaks == pytest.approx(wall.breaks_m, abs=0.02)
    assert np.degrees(np.arctan(three.slopes)) == pytest.approx([-10, 0, 10], abs=0.1)


def test_noise_below_the_floor_never_buys_pieces() -> None:
    """A flat wall touched with 1 cm noise (onboard) stays one piece at a 1 cm floor."""
    rng = np.random.default_rng(6)
    x = rng.uniform(-1.75, 1.75, 150)
    assert fit_pieces(x, rng.normal(0, 0.01, x.size), noise_floor_m=0.01).n_pieces == 1


def test_a_step_and_a_corner_meet_where_they_should() -> None:
    left, right = np.array([0.0, 0.0]), np.array([0.2, -0.1])  # cross at x = 0.5
    assert corner_or_step(0.4, 0.6, left, right) == pytest.approx(0.5)
    assert corner_or_step(0.1, 0.3, left, right) == pytest.approx(0.2)  # a step: half-way
    assert corner_or_step(0.1, 0.3, left, left) == pytest.approx(0.2)  # parallel


def test_screen_drops_contacts_short_of_the_wall_only() -> None:
    rng = np.random.default_rng(7)
    x = np.sort(rng.uniform(-1.75, 1.75, 60))
    wall = Wall.segmented([-10, 0, 10], (-1.75, 1.75))
    y = wall.depth(x)
    short = [5, 21, 22, 40]  # two false contacts side by side among them
    y[short] -= [0.3, 0.1, 0.45, 0.07]
    y[30] += 0.2  # beyond the wall: says the wall is farther, never dropped
    keep = screen(x, y)
    assert np.flatnonzero(~keep).tolist() == short


def test_screen_keeps_a_piece_of_three_contacts() -> None:
    x = np.array([-1.6, -1.2, -0.8, -0.4, 0.0, 0.4, 0.8, 1.2, 1.6])
    wall = Wall.segmented([10, 0, 10], (-0.6, 0.6))  # the middle three on their own piece
    assert screen(x, wall.depth(x)).all()


def test_too_few_points_are_refused() -> None:
    with pytest.raises(InputError, match=r"x, y: got 1 point\(s\), expected at least 2"):
        fit_pieces(np.zeros(1), np.zeros(1))
    with pytest.raises(InputError, match=r"expected at least 2 at distinct x"):
        fit_pieces(np.ones(4), np.arange(4.0))


@settings(max_examples=40, deadline=None)
@given(
    xy=hnp.arrays(np.float64, st.tuples(st.integers(2, 60), st.just(2)), elements=st.floats(-3, 3)),
    max_pieces=st.integers(1, 6),
)
def test_any_points_give_contiguous_pieces(xy: np.ndarray, max_pieces: int) -> None:
    x, y = xy[:, 0], xy[:, 1]
    if np.ptp(x) <= 1e-3:
        x = x + np.arange(x.size) * 1e-3
    pieces = fit_pieces(x, y, max_pieces=max_pieces)
    assert 1 <= pieces.n_pieces <= max_pieces
    assert np.all(np.diff(pieces.breaks) >= 0)
    assert np.all(np.isfinite(pieces.slopes)) and np.all(np.isfinite(pieces.intercepts))
    order = np.argsort(x, kind="stable")
    assert np.all(np.diff(pieces.labels[order]) >= 0)  # runs along x
    assert screen(x, y).shape == x.shape
