"""text_strokes: Latin text through the Hershey fonts."""

from __future__ import annotations

import numpy as np
import pytest

from skyquill.errors import InputError
from skyquill.strokes import hershey_fonts, text_strokes


def test_hi_has_five_strokes() -> None:
    # H: two stems and the bar; i: the dot (a closed loop) and the stem
    s = text_strokes("Hi")
    assert s.n_strokes == 5
    assert s.source == "text 'Hi' (futural)"
    # the H stems are vertical, 21 units tall, standing on the baseline y = 0
    np.testing.assert_allclose(s.paths[0], [[4, 21], [4, 0]])
    lo, hi = s.bounds()
    assert lo[1] == 0.0  # baseline, nothing in "Hi" descends
    assert hi[1] == 22.0  # the dot of the i sits above the cap height
    # the i's dot is a closed loop: starts and ends at the same point
    np.testing.assert_array_equal(s.paths[3][0], s.paths[3][-1])


def test_hi_scales_to_size() -> None:
    s = text_strokes("Hi").scaled(0.5)
    lo, hi = s.bounds()
    np.testing.assert_allclose(lo, [0.0, 0.0], atol=1e-15)
    extent = hi - lo
    assert extent.max() == pytest.approx(0.5)
    assert extent[0] == pytest.approx(0.5)  # "Hi" is wider (23) than tall (22)
    assert extent[1] == pytest.approx(0.5 * 22 / 23)


def test_glyphs_advance_and_spaces_draw_nothing() -> None:
    a = text_strokes("H")
    b = text_strokes("H H")
    assert b.n_strokes == 2 * a.n_strokes
    shift = b.paths[3][0, 0] - a.paths[0][0, 0]
    assert shift == pytest.approx(22 + 16)  # H advance + space advance in futural


def test_newline_moves_down() -> None:
    s = text_strokes("H\nH")
    assert s.n_strokes == 6
    assert s.paths[3][0, 0] == s.paths[0][0, 0]
    # the second baseline sits 1.6 cap heights (21 units) below the first
    np.testing.assert_allclose(s.paths[3][:, 1], s.paths[0][:, 1] - 1.6 * 21)
    # and the second line's capitals clear the first line's descenders (7 units)
    assert s.paths[3][:, 1].max() < -7


def test_font_selectable() -> None:
    assert "futural" in hershey_fonts() and "scripts" in hershey_fonts()
    a = text_strokes("a", font="timesr")
    b = text_strokes("a", font="futural")
    assert a.source.endswith("(timesr)")
    assert a.n_points != b.n_points


def test_unknown_font_lists_available() -> None:
    with pytest.raises(InputError, match=r"font: got 'comic', expected one of futural, .*timesr"):
        text_strokes("Hi", font="comic")


@pytest.mark.parametrize("text", ["", "   ", "\n"])
def test_empty_text(text: str) -> None:
    with pytest.raises(InputError, match="expected at least one visible character"):
        text_strokes(text)


def test_missing_characters_are_named() -> None:
    with pytest.raises(InputError, match=r"characters 'éø' \(U\+00E9, U\+00F8\) are not in"):
        text_strokes("Héllø")


def test_missing_glyphs_names_what_the_font_cannot_write() -> None:
    from skyquill.strokes.hershey import missing_glyphs

    assert missing_glyphs("Hello, world!\n42") == ""
    assert missing_glyphs("é😀aé") == "é😀"
