"""The long exposure and the preview, read back from the files written."""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image, ImageSequence

from skyquill.errors import InputError
from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.trajectory import PiecewisePolynomial
from skyquill.viz import light_painting
from skyquill.viz.camera import Camera
from skyquill.viz.light_painting import (
    DARK,
    STAMP,
    View,
    _palette_colors,
    animate_show,
    long_exposure,
    write_pictures,
)

RED, BLUE = (255, 0, 0), (0, 0, 255)


def _line(start: list[float], end: list[float], duration: float = 4.0) -> PiecewisePolynomial:
    coeffs = np.zeros((1, 2, 3))
    coeffs[0, 0], coeffs[0, 1] = start, (np.array(end) - np.array(start)) / duration
    return PiecewisePolynomial(np.array([0.0, duration]), coeffs)


def _drones() -> list[PlannedTrajectory]:
    """A red horizontal bar lit from 1 s to 3 s, and a blue vertical one lit all along."""
    bar = PlannedTrajectory(_line([-2.0, 0.0, 2.0], [2.0, 0.0, 2.0]), ((1.0, 3.0),), (), (RED,))
    post = PlannedTrajectory(_line([3.0, 0.0, 1.0], [3.0, 0.0, 3.0]), ((0.0, 4.0),), (), (BLUE,))
    return [bar, post]


CAMERA = Camera(np.array([0.5, -12.0, 2.0]), np.array([0.5, 0.0, 2.0]), width_px=640, height_px=360)


def _pixel(point: list[float]) -> tuple[int, int]:
    uv = CAMERA.project(np.array([point]))[0][0]
    return int(np.rint(uv[0])), int(np.rint(uv[1]))


def test_the_photograph_is_lit_only_along_the_lit_path(tmp_path: Path) -> None:
    drones = _drones()
    exposure = long_exposure(drones, CAMERA, tmp_path / "photo.png")
    assert exposure.lit_windows == 2 and exposure.lit_length_m == pytest.approx(2.0 + 2.0)
    image = np.asarray(Image.open(exposure.path).convert("RGB")).astype(int)
    assert image.shape == (360, 640, 3)
    # every bright pixel is within the glow of a projected lit sample
    lit_points = np.concatenate(
        [drones[0].trajectory.evaluate(np.linspace(1.0, 3.0, 400)),
         drones[1].trajectory.evaluate(np.linspace(0.0, 4.0, 400))]
    )  # fmt: skip
    uv, _ = CAMERA.project(lit_points)
    rows, cols = np.nonzero(image.max(axis=2) > 40)
    assert rows.size > 100
    gaps = np.min(np.hypot(cols[:, None] - uv[None, :, 0], rows[:, None] - uv[None, :, 1]), axis=1)
    assert gaps.max() <= 6.0
    # the bar is red, the post blue; the bar's unlit ends stay dark
    u, v = _pixel([0.0, 0.0, 2.0])
    assert image[v, u, 0] > 150 and image[v, u, 2] < image[v, u, 0]
    u, v = _pixel([3.0, 0.0, 2.0])
    assert image[v, u, 2] > 150 and image[v, u, 0] < image[v, u, 2]
    u, v = _pixel([-1.8, 0.0, 2.0])
    assert image[v - 2 : v + 3, u - 2 : u + 3].max() < 40


def test_the_preview_plays_the_show_and_builds_up_the_light(tmp_path: Path) -> None:
    frames = animate_show(_drones(), CAMERA, tmp_path / "p.gif", trail_s=math.inf, max_frames=30)
    gif = Image.open(tmp_path / "p.gif")
    assert frames == gif.n_frames == 30 and gif.size == (640, 360)
    gif.seek(29)
    last = np.asarray(gif.convert("RGB")).astype(int)
    u, v = _pixel([0.0, 0.0, 2.0])
    assert last[v - 1 : v + 2, u - 1 : u + 2, 0].max() > 150  # the whole bar is on screen


def test_write_pictures_frames_the_light_and_the_flight(tmp_path: Path) -> None:
    entry = write_pictures(_drones(), tmp_path, View(azimuth_deg=-60.0))
    assert (tmp_path / "long_exposure.png").is_file() and (tmp_path / "preview.gif").is_file()
    assert entry["lit_windows"] == 2 and entry["view"] == {
        "azimuth_deg": -60.0, "elevation_deg": 10.0, "fov_deg": 50.0,
    }  # fmt: skip


def test_no_drone_and_a_negative_trail_are_refused(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="drones: got none"):
        long_exposure([], CAMERA, tmp_path / "x.png")
    with pytest.raises(InputError, match="trail_s"):
        animate_show(_drones(), CAMERA, tmp_path / "x.gif", trail_s=-1.0)


def test_a_light_held_still_is_a_dot(tmp_path: Path) -> None:
    """A drone lit while it holds a formation place leaves a dot, not nothing."""
    still = PlannedTrajectory(_line([0.5, 0.0, 2.0], [0.5, 0.0, 2.0]), ((0.0, 4.0),), (), (RED,))
    long_exposure([still], CAMERA, tmp_path / "dot.png")
    image = np.asarray(Image.open(tmp_path / "dot.png").convert("RGB")).astype(int)
    u, v = _pixel([0.5, 0.0, 2.0])
    assert image[v - 1 : v + 2, u - 1 : u + 2, 0].max() > 150


@settings(max_examples=25, deadline=None)
@given(
    azimuth=st.floats(allow_nan=True, allow_infinity=True),
    elevation=st.floats(-200, 200) | st.just(math.nan),
    fov=st.floats(-10, 400) | st.just(math.nan),
)
def test_any_view_gives_a_picture_or_an_input_error(
    azimuth: float, elevation: float, fov: float
) -> None:
    """Hostile views: a photograph with every lit point in front of the camera, or InputError."""
    drones = _drones()
    points = np.concatenate([d.trajectory.evaluate(np.linspace(0, 4, 50)) for d in drones])
    try:
        camera = Camera.framing(points, azimuth, elevation, fov_deg=fov, width_px=160, height_px=90)
    except InputError:
        return
    with tempfile.TemporaryDirectory() as tmp:
        exposure = long_exposure(drones, camera, Path(tmp) / "p.png")
        assert Image.open(exposure.path).size == (160, 90)
    assert camera.project(points)[1].all()


@settings(max_examples=40, deadline=None)
@given(
    drones=st.integers(1, 6),
    samples=st.integers(1, 40),
    seed=st.integers(0, 2**32 - 1),
)
def test_palette_has_the_colours_of_every_sample(drones: int, samples: int, seed: int) -> None:
    # Rounding only the samples where the colour changes keeps every colour: the palette
    # is the one of rounding every sample.
    rng = np.random.default_rng(seed)
    choices = rng.integers(0, 256, (4, 3)) / 255.0
    choices[0] = 0.0
    colors = choices[rng.integers(0, 4, (drones, samples))] + rng.choice(
        [0.0, 1e-4], (drones, samples, 1)
    )
    rgb = np.clip(np.round(255 * colors.reshape(-1, 3)), 0, 255).astype(np.int64)
    lights = np.unique(rgb, axis=0).astype(float)
    fixed = np.array([(0, 0, 0), [round(255 * c) for c in DARK], STAMP], dtype=float)
    every = np.unique(np.concatenate([fixed, lights]), axis=0).astype(np.uint8)
    np.testing.assert_array_equal(_palette_colors(colors), every)


@pytest.mark.parametrize("trail_s", [1.0, math.inf])
def test_frames_drawn_as_palette_indices_equal_rgb_frames_quantized(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, trail_s: float
) -> None:
    # The preview's frames are drawn as palette indices; drawn in RGB and quantized to the
    # same palette (as with more colours than a GIF holds), every frame decodes the same.
    indexed = tmp_path / "indexed.gif"
    animate_show(_drones(), CAMERA, indexed, trail_s=trail_s, max_frames=20)
    monkeypatch.setattr(light_painting, "_indexer", lambda palette: None)
    quantized = tmp_path / "quantized.gif"
    animate_show(_drones(), CAMERA, quantized, trail_s=trail_s, max_frames=20)

    def frames(path: Path) -> list[np.ndarray]:
        return [np.asarray(f.convert("RGB")) for f in ImageSequence.Iterator(Image.open(path))]

    a, b = frames(indexed), frames(quantized)
    assert len(a) == len(b) == 20
    assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
    assert any(x.any() for x in a)  # something is lit
