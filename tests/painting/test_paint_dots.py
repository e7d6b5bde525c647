"""Dots: CSV reading and its errors, stippling, the paper's drawing."""

from __future__ import annotations

import struct
import tempfile
import zlib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image

from skyquill.errors import InputError
from skyquill.painting.dots import (
    MAX_IMAGE_PIXELS,
    STIPPLE_MAX_SIDE,
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


def _png_header(width: int, height: int) -> bytes:
    """A PNG signature and IHDR claiming ``width`` x ``height`` 8-bit grey, then a bogus IDAT."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (
            struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
        )

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(b"\0" * 64))


def test_a_decompression_bomb_is_refused_from_its_header(tmp_path: Path) -> None:
    bomb = tmp_path / "bomb.png"
    bomb.write_bytes(_png_header(20_000, 20_000))  # 400 Mpx claimed by a 100-byte file
    with pytest.raises(
        InputError,
        match=rf"--image: got 'bomb.png' of more than [0-9,]+ px, expected a picture of 1 "
        rf"to {MAX_IMAGE_PIXELS:,} pixels",
    ):
        load_darkness(bomb)
    bomb.write_bytes(_png_header(10_000, 5_000))  # below Pillow's own limit, above ours
    with pytest.raises(
        InputError,
        match=rf"--image: got 'bomb.png' of 10000 x 5000 px, expected a picture of 1 to "
        rf"{MAX_IMAGE_PIXELS:,} pixels",
    ):
        load_darkness(bomb)


def test_a_truncated_image_is_named(tmp_path: Path) -> None:
    whole = _picture(tmp_path / "whole.png").read_bytes()
    cut = tmp_path / "cut.png"
    cut.write_bytes(whole[: len(whole) // 2])
    with pytest.raises(InputError, match=r"--image: got 'cut.png' that Pillow cannot read"):
        load_darkness(cut)
    small = tmp_path / "small.png"
    small.write_bytes(_png_header(8, 8))  # the header is fine, the pixel data is not
    with pytest.raises(InputError, match=r"--image: got 'small.png' that Pillow cannot read"):
        load_darkness(small)


def test_other_formats_are_refused(tmp_path: Path) -> None:
    gif = tmp_path / "x.gif"
    Image.new("L", (8, 8), 0).save(gif)
    with pytest.raises(InputError, match=r"got 'x.gif' that Pillow cannot read.*expected a PNG"):
        load_darkness(gif)


def test_sixteen_bit_grey_keeps_its_range(tmp_path: Path) -> None:
    path = tmp_path / "deep.png"
    Image.fromarray(np.array([[0, 32768, 65535]], dtype=np.uint16)).save(path)
    assert Image.open(path).mode.startswith("I;16")
    np.testing.assert_allclose(load_darkness(path), [[1.0, 1 - 32768 / 65535, 0.0]], atol=1e-6)


def test_transparent_pixels_are_paper(tmp_path: Path) -> None:
    path = tmp_path / "alpha.png"
    Image.new("RGBA", (4, 4), (0, 0, 0, 0)).save(path)  # black, but fully transparent
    np.testing.assert_allclose(load_darkness(path), 0.0)


_modes = st.sampled_from(["1", "L", "LA", "P", "RGB", "RGBA", "I;16"])


@settings(max_examples=60, deadline=None)
@given(
    mode=_modes,
    width=st.integers(1, 300),
    height=st.integers(1, 30),
    fmt=st.sampled_from(["PNG", "JPEG"]),
    cut=st.one_of(st.none(), st.integers(0, 400)),
)
def test_random_small_images_give_darkness_or_an_input_error(
    mode: str, width: int, height: int, fmt: str, cut: int | None
) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "r.img"
        rng = np.random.default_rng(width * height)
        img = Image.new(mode, (width, height))
        img.putdata(rng.integers(0, 255, width * height).tolist())
        try:
            img.save(path, fmt)
        except OSError:  # JPEG cannot hold every mode; nothing to read then
            return
        if cut is not None:
            path.write_bytes(path.read_bytes()[:cut])
        try:
            darkness = load_darkness(path)
        except InputError as exc:
            assert "r.img" in str(exc)
            return
    assert darkness.ndim == 2 and max(darkness.shape) <= STIPPLE_MAX_SIDE
    assert np.all((darkness >= 0.0) & (darkness <= 1.0))


@settings(max_examples=100, deadline=None)
@given(raw=st.binary(max_size=80), prefix=st.sampled_from([b"", b"\x89PNG\r\n\x1a\n", b"\xff\xd8"]))
def test_random_bytes_give_an_input_error(raw: bytes, prefix: bytes) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "raw.png"
        path.write_bytes(prefix + raw)
        with pytest.raises(InputError, match=r"--image: got 'raw.png'"):
            load_darkness(path)


def test_stipple_refuses_a_picture_over_the_pixel_budget() -> None:
    message = (
        r"^darkness: got a 1001 x 1000 picture, expected at most 1,000,000 pixels "
        r"\(downscale it, as load_darkness does to 200 px\)$"
    )
    with pytest.raises(InputError, match=message):
        stipple(np.ones((1001, 1000)), 3, rng=np.random.default_rng(0))
