"""Typed text: which script, how it is shared out between drones, its strokes."""

from __future__ import annotations

import pytest

from skyquill.errors import InputError
from skyquill.strokes import bundled_hanzi, hanzi_strokes, is_cjk, split_text, typed_strokes


def test_split_text() -> None:
    assert split_text("一马当先", 4) == ["一", "马", "当", "先"]
    assert split_text("one two three", 2) == ["one two", "three"]
    with pytest.raises(InputError, match="drones: got 3 drones for 2"):
        split_text("one two", 3)


def test_typed_strokes_picks_the_script() -> None:
    assert is_cjk("永") and not is_cjk("yong")
    assert typed_strokes("永").n_strokes == 5
    assert typed_strokes("hi").n_strokes >= 3


def test_every_bundled_character_is_written_from_its_medians() -> None:
    # hanzi-writer-data also ships radical forms (U+2E80 block), not "CJK UNIFIED
    # IDEOGRAPH"s: they were sent to the Hershey font, which has no glyph for them.
    assert [c for c in bundled_hanzi() if not is_cjk(c)] == []
    radical = typed_strokes("⺀")
    assert radical.source == "hanzi ⺀"
    assert radical.n_strokes == hanzi_strokes("⺀").n_strokes
    assert not is_cjk("。,")  # punctuation is not written from medians
