"""Writing work is bounded before the route is built or the QP assembled."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.brush import Brush
from skyquill.calligraphy.mission import (
    MAX_STROKES,
    WritingOptions,
    check_reach,
    plan_writing,
    route_length,
)
from skyquill.calligraphy.route import route_points
from skyquill.calligraphy.show import layout
from skyquill.errors import InputError
from skyquill.strokes import Strokes, hanzi_strokes

H = Strokes(
    paths=(
        np.array([[0.0, 0.0], [0.0, 1.0]]),
        np.array([[0.6, 0.0], [0.6, 1.0]]),
        np.array([[0.0, 0.5], [0.6, 0.5]]),
    )
)
HOME = np.array([0.25, -1.0, 0.0])


@pytest.mark.parametrize("size", [1e6, 1e-6, 0.005, 25.0])
def test_size_out_of_range_is_refused(size: float) -> None:
    message = rf"^size_m: got {re.escape(f'{size:g}')} m, expected 0\.01 to 20 m \(a character"
    with pytest.raises(InputError, match=message):
        WritingOptions(size_m=size)


def test_brush_and_lift_are_bounded() -> None:
    with pytest.raises(InputError, match=r"^brush length_m: got 3 m, expected at most 2 m"):
        Brush(length_m=3.0)
    with pytest.raises(InputError, match=r"^brush press_depth_m: got 0.03 m, expected less "):
        Brush(press_depth_m=0.03)
    with pytest.raises(InputError, match=r"^brush: got float, expected Brush"):
        WritingOptions(brush=0.3)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"^follow: got 'ink', expected 'tip' or 'path'"):
        WritingOptions(follow="ink")  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"^lift_m: got 1000 m, expected at most 1 m"):
        Board(lift_m=1000.0)
    with pytest.raises(InputError, match=r"^lift_m: got 1000 m"):
        layout(2, 0.5, 1.0, lift_m=1000.0)


@pytest.mark.parametrize(
    ("board", "brush", "message"),
    [
        (Board(), Brush(length_m=0.01), r"^brush length_m: got 0.01 m, expected at least 0.05 m"),
        (Board(origin=np.array([0.0, 0.0, -0.5])), Brush(), r"^board: got the writing from -0.5 m"),
        (Board(origin=np.array([0.0, 0.0, 119.9])), Brush(), r"vehicle up to 120.25 m"),
        (Board("wall", np.array([0.0, 0.0, 0.0])), Brush(), r"above the ground \(z > 0\)"),
    ],
    ids=["brush-too-short", "board-underground", "board-too-high", "wall-on-the-ground"],
)
def test_a_brush_or_board_the_vehicle_cannot_write_with_is_refused(
    board: Board, brush: Brush, message: str
) -> None:
    with pytest.raises(InputError, match=message):
        plan_writing(hanzi_strokes("一"), board, WritingOptions(brush=brush))


def test_drones_are_bounded() -> None:
    with pytest.raises(InputError, match=r"^drones: got 1001, expected an integer from 1 to 1000"):
        layout(1001, 0.5, 1.0)


def test_a_far_home_is_refused_by_the_route_estimate() -> None:
    message = (
        r"^strokes: got a route of about 2e\+05 m \(2e\+07 samples, one every 1 cm\), expected "
        r"at most 400,000 samples, i\.e\. about 4 km \(a smaller size_m, lift_m, a home nearer "
        r"the board or fewer strokes\)$"
    )
    with pytest.raises(InputError, match=message):
        plan_writing(H, home=np.array([1e5, 0.0, 0.0]))


def test_many_long_strokes_are_refused_by_the_route_estimate() -> None:
    # 1500 strokes of 20 m and the transits back: ~60 km of route, 6e6 samples.
    rows = np.arange(1500.0)
    strokes = Strokes(paths=tuple(np.array([[0.0, y], [1500.0, y]]) for y in rows))
    with pytest.raises(InputError, match=r"^strokes: got a route of about 6\.013e\+04 m"):
        plan_writing(strokes, options=WritingOptions(size_m=20.0))


def test_too_many_strokes_are_refused() -> None:
    strokes = Strokes(paths=tuple(np.array([[0.0, y], [1.0, y]]) for y in range(MAX_STROKES + 1)))
    with pytest.raises(InputError, match=r"^strokes: got 2,001 strokes, expected at most 2,000"):
        plan_writing(strokes)


def test_too_many_knot_spans_are_refused_before_assembly() -> None:
    message = r"^knot_interval: got 0\.0001 s for a \d+(\.\d+)? s flight, i\.e\. [\d,]+ knot spans"
    with pytest.raises(InputError, match=message):
        plan_writing(H, options=WritingOptions(knot_interval=1e-4))


def test_the_route_estimate_bounds_the_route() -> None:
    board = Board()
    world = tuple(board.to_world(p) for p in H.scaled(0.5).paths)
    home = HOME - 0.3 * board.normal
    points, _ = route_points(world, board, home)
    built = float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())
    assert built <= route_length(world, board, home) + 1e-9
    assert built >= 0.7 * route_length(world, board, home)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"max_stretches": 10**6}, "max_stretches: got 1000000, expected an integer from 0 to 50"),
        ({"resegment_iterations": 10**9}, "resegment_iterations: got 1000000000, expected an"),
    ],
)
def test_solve_counts_are_bounded(kwargs: dict[str, int], message: str) -> None:
    with pytest.raises(InputError, match=f"^{message}"):
        WritingOptions(**kwargs)  # type: ignore[arg-type]


_any_float = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True), st.integers(-10, 10), st.just("0.3")
)


@settings(max_examples=200, deadline=None, derandomize=True)
@given(
    length=_any_float,
    travel=_any_float,
    press=_any_float,
    height=st.floats(-1e3, 1e3),
    kind=st.sampled_from(["horizontal", "wall"]),
)
def test_any_brush_and_board_is_taken_or_refused_by_name(
    length: object, travel: object, press: object, height: float, kind: str
) -> None:
    """Hostile brushes and board heights: a Brush, or an InputError naming the field;
    a reachable board, or the check's InputError -- never another exception."""
    try:
        brush = Brush(length_m=length, travel_m=travel, press_depth_m=press)  # type: ignore[arg-type]
    except InputError as exc:
        assert str(exc).startswith("brush ")
        return
    board = Board(kind, np.array([0.0, 0.0, height]))  # type: ignore[arg-type]
    try:
        check_reach(board, WritingOptions(brush=brush))
    except InputError as exc:
        assert str(exc).startswith(("brush length_m", "board: got"))
