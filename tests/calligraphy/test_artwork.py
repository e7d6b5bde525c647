"""Many drones on one artwork: the sky grid's layout, and one drawing split among drones."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from skyquill.calligraphy.artwork import (
    GRID_MARGIN_M,
    grid_shape,
    sky_grid,
    split_homes,
    split_strokes,
)
from skyquill.calligraphy.board import sky_board
from skyquill.calligraphy.mission import WritingOptions, plan_writing
from skyquill.calligraphy.show import (
    MAX_DRONES,
    MAX_SHOW_STROKES,
    check_show_size,
    layout,
    plan_show,
)
from skyquill.errors import InputError
from skyquill.strokes import Strokes, typed_parts, typed_strokes


@pytest.mark.parametrize(("n", "shape"), [(1, (1, 1)), (3, (2, 2)), (20, (4, 5)), (100, (10, 10))])
def test_grid_is_nearly_square(n: int, shape: tuple[int, int]) -> None:
    assert grid_shape(n) == shape


def test_grid_given_must_hold_every_drone() -> None:
    assert grid_shape(6, (2, 3)) == (2, 3)
    with pytest.raises(InputError, match="grid: got 2x2 = 4 cells for 5 drones"):
        grid_shape(5, (2, 2))


def test_sky_grid_boards_are_a_pitch_apart_on_one_plane_with_homes_in_front() -> None:
    size, separation = 0.5, 1.0
    places = sky_grid(7, size, separation, height_m=2.0, yaw_deg=25.0, tilt_deg=15.0)
    pitch = size + separation + GRID_MARGIN_M
    base = sky_board(np.array([0.0, 0.0, 2.0]), yaw_deg=25.0, tilt_deg=15.0)  # the grid's
    uvh = base.to_board(np.array([b.origin for b, _ in places]))
    np.testing.assert_allclose(uvh[:, 2], 0.0, atol=1e-12)  # all on one plane
    rows, columns = grid_shape(7)
    for i, (u, v, _) in enumerate(uvh):
        r, c = divmod(i, columns)  # row 0 on top: reading order
        assert (u, v) == pytest.approx((c * pitch, (rows - 1 - r) * pitch))
    assert min(b.origin[2] for b, _ in places) == pytest.approx(2.0)  # the bottom row's edge
    homes = np.array([h for _, h in places])
    assert np.all(homes[:, 2] == 0.0)
    gaps = [np.linalg.norm(a - b) for a, b in itertools.combinations(homes, 2)]
    assert min(gaps) >= separation
    facing = np.array([np.sin(np.radians(25.0)), -np.cos(np.radians(25.0)), 0.0])
    ahead = (homes - base.origin) @ facing  # in front of the bottom edge, the audience's side
    assert ahead.min() == pytest.approx(1.0) and ahead.max() == pytest.approx(1.0 + 2 * pitch)


def test_layout_of_sky_boards_is_the_grid_and_checks_its_ceilings() -> None:
    boards = layout(4, 0.5, 1.0, kind="sky", height_m=3.0, grid=(1, 4))
    assert [b.kind for b, _ in boards] == ["sky"] * 4 and boards[0][0].lift_m == 0.0
    np.testing.assert_allclose([b.origin[2] for b, _ in boards], 3.0)
    with pytest.raises(InputError, match="sky boards only"):
        layout(2, 0.5, 1.0, kind="wall", grid=(1, 2))
    with pytest.raises(InputError, match=f"expected at most {MAX_DRONES} drones"):
        check_show_size([typed_strokes("l", "futural")] * (MAX_DRONES + 1))
    line = typed_strokes("E" * 40, "futural")  # 4 strokes per E
    with pytest.raises(InputError, match=f"{MAX_SHOW_STROKES:,} strokes"):
        check_show_size([line] * 20)


def _drawing() -> Strokes:
    return typed_strokes("HELLO", "futural")  # 10 strokes


def test_split_balances_the_flights_and_keeps_the_drawing_in_place() -> None:
    options = WritingOptions(size_m=8.0)
    board = sky_board(np.array([0.0, 0.0, 2.0]))
    split = split_strokes(_drawing(), 3, board, options)
    assert sorted(i for s in split.strokes for i in s) == list(range(10))
    assert split.balance < 1.2  # estimated writing times within 20 %
    # Each part is laid out in the whole drawing's box: scaled, its strokes stay put.
    whole = _drawing().scaled(8.0).paths
    for part, members in zip(split.parts, split.strokes, strict=True):
        for path, i in zip(part.scaled(8.0).paths, members, strict=True):
            np.testing.assert_allclose(path, whole[i], atol=1e-12)
    # Bands follow each other along the drawing's longer side (x here).
    centres = [np.mean(np.concatenate(p.scaled(8.0).paths)[:, 0]) for p in split.parts]
    assert centres == sorted(centres)
    homes = split_homes(split, board, 8.0, 1.0)
    assert min(np.linalg.norm(a - b) for a, b in itertools.combinations(homes, 2)) >= 1.0
    # The flights, planned: about as long as each other (max / min measured 1.13).
    times = [
        plan_writing(p, board, options, h).trajectory.duration
        for p, h in zip(split.parts, homes, strict=True)
    ]
    assert max(times) / min(times) < 1.25


def test_split_refuses_more_drones_than_strokes() -> None:
    with pytest.raises(InputError, match="drones: got 11 drones for a drawing of 10 strokes"):
        split_strokes(_drawing(), 11, sky_board(np.zeros(3) + 1), WritingOptions())


def test_plan_show_writes_a_sky_grid() -> None:
    parts = typed_parts("L I T", 3, "futural")
    options = WritingOptions(size_m=0.4, resegment="off")
    show = plan_show(
        parts, options, 1.0, workers=1, board_kind="sky", board_height_m=2.0, board_yaw_deg=10.0
    )
    assert show.min_separation_m >= 1.0
    assert all(m.board.kind == "sky" and m.faithful for m in show.missions)
