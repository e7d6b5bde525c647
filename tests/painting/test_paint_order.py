"""Painting orders: permutations, the paper's rows, nearest neighbour + 2-opt."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from skyquill.errors import InputError
from skyquill.painting.dots import paper_drawing
from skyquill.painting.order import nearest_neighbour, order_dots, path_length, two_opt


def test_paper_order_on_a_grid_is_rows_right_to_left_top_to_bottom() -> None:
    xs, zs = np.meshgrid([0.0, 0.5, 1.0], [2.0, 1.5])
    dots = np.column_stack([xs.ravel(), zs.ravel()])
    route = order_dots(dots, "paper")
    assert dots[route].tolist() == [
        [1.0, 2.0], [0.5, 2.0], [0.0, 2.0], [1.0, 1.5], [0.5, 1.5], [0.0, 1.5]
    ]  # fmt: skip


def test_shortest_beats_paper_order_on_the_paper_drawing() -> None:
    dots = paper_drawing()
    paper = path_length(dots, order_dots(dots, "paper"))
    nn = nearest_neighbour(dots, 0)
    shortest = path_length(dots, order_dots(dots, "shortest"))
    assert shortest < 0.3 * paper
    assert path_length(dots, two_opt(dots, nn)) <= path_length(dots, nn) + 1e-12


@settings(max_examples=40, deadline=None)
@given(hnp.arrays(np.float64, st.tuples(st.integers(1, 40), st.just(2)), elements=st.floats(-3, 3)))
def test_orders_are_permutations_and_two_opt_never_lengthens(dots: np.ndarray) -> None:
    for method in ("given", "paper", "shortest"):
        route = order_dots(dots, method)
        assert sorted(route.tolist()) == list(range(len(dots)))
    nn = nearest_neighbour(dots, 0)
    better = two_opt(dots, nn)
    assert better[0] == nn[0]
    assert path_length(dots, better) <= path_length(dots, nn) + 1e-9


def test_unknown_order() -> None:
    with pytest.raises(InputError, match=r"--order: got 'zigzag', expected one of given"):
        order_dots(np.zeros((2, 2)), "zigzag")


def test_spread_starts_with_dots_across_the_width() -> None:
    dots = paper_drawing()
    route = order_dots(dots, "spread", start_xz=np.array([0.0, 1.5]), spacing_m=0.5)
    assert sorted(route.tolist()) == list(range(len(dots)))
    first = dots[route[:8], 0]
    assert np.all(np.diff(first) > 0.3)  # one sweep, left to right (the start is nearer left?)
    assert first.min() < -1.6 and first.max() > 1.6
    for method in ("spread",):
        assert sorted(order_dots(dots[:5], method).tolist()) == list(range(5))
