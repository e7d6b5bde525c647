"""Colours per drone or per stroke from a palette."""

from __future__ import annotations

import pytest

from skyquill.errors import InputError
from skyquill.show.lights import window_palette

RED, GREEN, BLUE = (255, 0, 0), (0, 255, 0), (0, 0, 255)


def test_per_drone_each_drone_takes_the_next_colour() -> None:
    assert window_palette([2, 1, 3], [RED, GREEN]) == [(RED, RED), (GREEN,), (RED, RED, RED)]


def test_per_stroke_the_strokes_are_counted_across_the_drones() -> None:
    colors = window_palette([2, 1, 3], [RED, GREEN, BLUE], by="stroke")
    assert colors == [(RED, GREEN), (BLUE,), (RED, GREEN, BLUE)]


@pytest.mark.parametrize(
    ("palette", "by", "message"),
    [
        ([], "drone", "palette: got no colour"),
        ([(1, 2, 300)], "drone", r"palette\[0\]: got \(1, 2, 300\)"),
        ([RED], "word", "color_by: got 'word', expected one of drone, stroke"),
    ],
)
def test_bad_palettes_are_named(palette: list[tuple[int, int, int]], by: str, message: str) -> None:
    with pytest.raises(InputError, match=message):
        window_palette([1], palette, by)
