"""Dots: CSV reading and its errors, stippling, the paper's drawing."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from skyquill.errors import InputError
from skyquill.painting.dots import (
    load_darkness,
    paper_drawing,
    read_dots_csv,
    stipple,
    write_dots_csv,
)


def test_csv_round_trip(tmp_path: Path) -> None:
    dots = np.array([[0.1, 1.0], [-0.5, 2.25]])
    write_dots_csv(tmp_path / "d.csv", dots)
    assert np.allclose(read_dots_csv(tmp_path / "d.csv"), dots)


def test_csv_extra_columns_and_order(tmp_path: Path) -> None:
    (tmp_path / "d.csv").write_text("id,z,x\n1,1.5,0.2\n2,1.0,-0.2\n")
    assert np.allclose(read_dots_csv(tmp_path / "d.csv"), [[0.2, 1.5], [-0.2, 1.0]])


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("x,z\n", r"d.csv: got 0 dots, expected 1 to 10000"),
        ("x,y\n0,1\n", r"d.csv: got columns \['x', 'y'\], expected columns x,z .* missing z"),
        ("x,z\n0,nan\n", r"d.csv line 2, column z: got 'nan', expected a finite number"),
        ("x,z\n0,1\nq,1\n", r"d.csv line 3, column x: got 'q', expected a number"),
        ("x,z\n0\n", r"d.csv line 2: got 1 columns, expected 2"),
    ],
)
def test_csv_errors(tmp_path: Path, text: str, match: str) -> None:
    (tmp_path / "d.csv").write_text(text)
    with pytest.raises(InputError, match=match):
        read_dots_csv(tmp_path / "d.csv")


def test_missing_csv(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"dots file: got .*nope.csv', expected an existing"):
        read_dots_csv(tmp_path / "nope.csv")


def _picture(path: Path) -> Path:
    """Left half black, right half white, 80 x 40 px."""
    img = Image.new("L", (80, 40), 255)
    img.paste(0, (0, 0, 40, 40))
    img.save(path)
    return path


def test_stipple_puts_dots_on_the_dark_half(tmp_path: Path) -> None:
    darkness = load_darkness(_picture(tmp_path / "half.png"))
    assert darkness.shape == (40, 80)
    calls: list[int] = []
    dots = stipple(
        darkness,
        60,
        width_m=2.0,
        rng=np.random.default_rng(0),
        progress=lambda done, total: calls.append(done),
    )
    assert dots.shape == (60, 2) and calls
    assert np.all(dots[:, 0] < 0.0)  # the black half is x < 0 (centred drawing)
    assert dots[:, 0].min() >= -1.0 and dots[:, 1].min() >= 0.5 and dots[:, 1].max() <= 1.5
    # Lloyd relaxation spreads them: no two dots closer than a quarter of the mean spacing
    d = np.linalg.norm(dots[:, None] - dots[None], axis=-1) + np.eye(60)
    assert d.min() > 0.25 * np.sqrt(1.0 / 60)


def test_unreadable_and_blank_images(tmp_path: Path) -> None:
    bad = tmp_path / "bad.png"
    bad.write_bytes(b"not a png")
    with pytest.raises(InputError, match=r"--image: got 'bad.png' that Pillow cannot read"):
        load_darkness(bad)
    with pytest.raises(InputError, match=r"--image: got .*none.png', expected an existing"):
        load_darkness(tmp_path / "none.png")
    with pytest.raises(InputError, match=r"--image: got an all-white picture"):
        stipple(np.zeros((5, 5)), 3, rng=np.random.default_rng(0))
    with pytest.raises(InputError, match=r"--dots: got 0, expected an integer from 1"):
        stipple(np.ones((5, 5)), 0, rng=np.random.default_rng(0))


def test_paper_drawing_is_140_dots_35_by_21() -> None:
    dots = paper_drawing()
    assert dots.shape == (140, 2)
    assert np.ptp(dots[:, 0]) == pytest.approx(3.5, abs=1e-3)
    assert np.ptp(dots[:, 1]) == pytest.approx(2.1, abs=0.01)
    assert len(np.unique(np.round(dots, 6), axis=0)) == 140


def test_example_csv_is_the_paper_drawing() -> None:
    example = Path(__file__).parents[2] / "examples" / "painting" / "paper_140.csv"
    dots = read_dots_csv(example)
    assert dots.shape == (140, 2)
    assert np.allclose(np.sort(dots, axis=0), np.sort(paper_drawing(), axis=0), atol=1e-4)


def test_a_decompression_bomb_is_a_named_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Pillow refuses pictures over 2 x MAX_IMAGE_PIXELS; lowered here so no test allocates.
    Image.new("L", (20, 20)).save(tmp_path / "bomb.png")
    monkeypatch.setattr(Image, "MAX_IMAGE_PIXELS", 10)
    with pytest.raises(InputError, match=r"--image: got 'bomb.png' that Pillow cannot read"):
        load_darkness(tmp_path / "bomb.png")


def test_stipple_refuses_a_picture_over_the_pixel_budget() -> None:
    message = (
        r"^darkness: got a 1001 x 1000 picture, expected at most 1,000,000 pixels "
        r"\(downscale it, as load_darkness does to 200 px\)$"
    )
    with pytest.raises(InputError, match=message):
        stipple(np.ones((1001, 1000)), 3, rng=np.random.default_rng(0))
