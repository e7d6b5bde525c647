"""The pinhole camera: the target at the centre, right is right, up is up, framing fits."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.viz.camera import Camera

FRONT = Camera(np.array([0.0, -10.0, 2.0]), np.array([0.0, 0.0, 2.0]))


def test_the_target_is_the_centre_and_the_axes_point_the_right_way() -> None:
    points = np.array([[0.0, 0.0, 2.0], [1.0, 0.0, 2.0], [0.0, 0.0, 3.0], [0.0, -20.0, 2.0]])
    uv, front = FRONT.project(points)
    np.testing.assert_allclose(uv[0], [640.0, 360.0])
    assert uv[1, 0] > 640.0 and uv[1, 1] == pytest.approx(360.0)  # +x is to the right
    assert uv[2, 1] < 360.0 and uv[2, 0] == pytest.approx(640.0)  # +z is up
    assert front.tolist() == [True, True, True, False]  # behind the camera


def test_the_field_of_view_is_the_picture_width() -> None:
    """A point at half the field of view off the axis lands on the picture's edge."""
    camera = Camera(np.zeros(3), np.array([0.0, 1.0, 0.0]), fov_deg=90.0, width_px=200)
    uv, _ = camera.project(np.array([[1.0, 1.0, 0.0]]))  # 45 degrees to the right
    assert uv[0, 0] == pytest.approx(200.0)


@settings(max_examples=40, deadline=None)
@given(
    st.lists(st.tuples(*[st.floats(-50, 50, allow_nan=False)] * 3), min_size=1, max_size=30),
    st.floats(-180, 180),
    st.floats(-80, 80),
)
def test_framing_keeps_every_point_in_the_picture(
    points: list[tuple[float, float, float]], azimuth: float, elevation: float
) -> None:
    p = np.array(points)
    camera = Camera.framing(p, azimuth, elevation, width_px=640, height_px=360)
    uv, front = camera.project(p)
    assert front.all()
    assert np.all((uv >= -1e-6) & (uv <= np.array([640.0, 360.0]) + 1e-6))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"fov_deg": 180.0}, "fov_deg: got 180, expected 1 to 170 degrees"),
        ({"width_px": 5}, "width_px"),
        ({"target": np.array([0.0, -10.0, 2.0])}, "camera target: got the camera's own position"),
    ],
)
def test_bad_cameras_are_named(kwargs: dict[str, object], message: str) -> None:
    args: dict[str, object] = {"position": FRONT.position, "target": FRONT.target} | kwargs
    with pytest.raises(InputError, match=message):
        Camera(**args)  # type: ignore[arg-type]


def test_framing_refuses_no_points_and_a_vertical_view() -> None:
    with pytest.raises(InputError, match="points: got none"):
        Camera.framing(np.empty((0, 3)))
    with pytest.raises(InputError, match="elevation_deg: got 90, expected -89 to 89"):
        Camera.framing(np.zeros((1, 3)), elevation_deg=90.0)
