"""Typed text: which script, how it is shared out between drones, its strokes."""

from __future__ import annotations

import pytest

from skyquill.errors import InputError
from skyquill.strokes import is_cjk, split_text, typed_strokes


def test_split_text() -> None:
    assert split_text("一马当先", 4) == ["一", "马", "当", "先"]
    assert split_text("one two three", 2) == ["one two", "three"]
    with pytest.raises(InputError, match="drones: got 3 drones for 2"):
        split_text("one two", 3)


def test_typed_strokes_picks_the_script() -> None:
    assert is_cjk("永") and not is_cjk("yong")
    assert typed_strokes("永").n_strokes == 5
    assert typed_strokes("hi").n_strokes >= 3
