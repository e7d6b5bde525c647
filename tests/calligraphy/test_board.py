"""Board geometry: the sky board's pose, axes and round trip; the old boards unchanged."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from skyquill.calligraphy.board import MAX_TILT_DEG, Board, sky_board
from skyquill.errors import InputError

finite = st.floats(-50.0, 50.0, allow_nan=False)


@settings(max_examples=200, deadline=None)
@given(
    yaw=st.floats(-180.0, 180.0),
    tilt=st.floats(-MAX_TILT_DEG, MAX_TILT_DEG),
    origin=arrays(np.float64, 3, elements=finite),
    uv=arrays(np.float64, (7, 2), elements=finite),
    h=arrays(np.float64, 7, elements=finite),
)
def test_sky_round_trip(
    yaw: float, tilt: float, origin: np.ndarray, uv: np.ndarray, h: np.ndarray
) -> None:
    board = sky_board(origin, yaw, tilt)
    axes = board.axes
    np.testing.assert_allclose(axes @ axes.T, np.eye(3), atol=1e-12)  # orthonormal
    np.testing.assert_allclose(np.cross(axes[0], axes[1]), axes[2], atol=1e-12)  # right-handed
    assert axes[0][2] == 0.0  # the writing's x stays horizontal
    back = board.to_board(board.to_world(uv))
    np.testing.assert_allclose(back[:, :2], uv, atol=1e-9)
    np.testing.assert_allclose(back[:, 2], 0.0, atol=1e-9)  # on the plane
    off = board.to_world(uv) + h[:, None] * board.normal
    np.testing.assert_allclose(board.to_board(off)[:, 2], h, atol=1e-9)


def test_sky_default_faces_the_audience_like_a_wall() -> None:
    sky, wall = sky_board(np.array([1.0, 2.0, 3.0])), Board("wall", np.array([1.0, 2.0, 3.0]))
    np.testing.assert_array_equal(sky.axes, wall.axes)
    np.testing.assert_array_equal(sky.normal, [0.0, -1.0, 0.0])
    assert sky.lift_m == 0.0 and not sky.has_contact and wall.has_contact


def test_yaw_and_tilt_turn_the_plane() -> None:
    turned = sky_board(np.zeros(3), yaw_deg=90.0)
    np.testing.assert_allclose(turned.axes[0], [0.0, 1.0, 0.0], atol=1e-15)  # x along +y
    np.testing.assert_allclose(turned.normal, [1.0, 0.0, 0.0], atol=1e-15)  # faces +x
    leaning = sky_board(np.zeros(3), tilt_deg=30.0)
    # Leaning back: "up" goes away from the audience (+y), the normal looks up a little.
    np.testing.assert_allclose(leaning.axes[1], [0.0, 0.5, np.sqrt(3) / 2], atol=1e-15)
    np.testing.assert_allclose(leaning.normal, [0.0, -np.sqrt(3) / 2, 0.5], atol=1e-15)


def test_horizontal_and_wall_map_as_before() -> None:
    uv = np.array([[0.1, 0.2]])
    np.testing.assert_array_equal(Board().to_world(uv), [[0.1, 0.2, 1.0]])
    wall = Board("wall", np.zeros(3))
    np.testing.assert_array_equal(wall.to_world(uv), [[0.1, 0.0, 0.2]])
    np.testing.assert_array_equal(wall.to_board(np.array([[0.1, -0.3, 0.2]])), [[0.1, 0.2, 0.3]])


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: Board("ceiling"), "board kind: got 'ceiling', expected 'horizontal', 'wall'"),
        (lambda: sky_board(np.zeros(3), tilt_deg=85.0), "tilt_deg: got 85, expected -80 to 80"),
        (lambda: sky_board(np.zeros(3), yaw_deg=200.0), "yaw_deg: got 200, expected -180 to 180"),
        (lambda: Board("wall", np.zeros(3), 0.05, 10.0), "only a sky board takes a pose"),
        (lambda: Board("wall", np.zeros(3), 0.0), "lift_m: got 0 m on a wall board"),
        (lambda: sky_board(np.zeros(3), lift_m=-0.1), "lift_m"),
    ],
)
def test_bad_boards(make: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        make()  # type: ignore[operator]
