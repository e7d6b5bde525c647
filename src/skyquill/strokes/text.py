"""Typed text to strokes: Latin through Hershey fonts, Chinese through hanzi medians."""

from __future__ import annotations

import itertools
import unicodedata
from pathlib import Path

import numpy as np

from skyquill.errors import InputError
from skyquill.strokes.hanzi import hanzi_text
from skyquill.strokes.hershey import text_strokes
from skyquill.strokes.model import Strokes


def is_cjk(text: str) -> bool:
    """Whether ``text`` holds CJK ideographs (written from hanzi medians, not Hershey)."""
    return any(unicodedata.name(c, "").startswith("CJK UNIFIED IDEOGRAPH") for c in text)


def split_text(text: str, parts: int) -> list[str]:
    """``text`` in ``parts`` consecutive chunks: characters for hanzi, words otherwise."""
    units = [c for c in text if not c.isspace()] if is_cjk(text) else text.split()
    if len(units) < parts:
        raise InputError(
            f"drones: got {parts} drones for {len(units)} character(s)/word(s) in "
            f"{text!r}, expected at most one drone per character or word"
        )
    joiner = "" if is_cjk(text) else " "
    bounds = np.linspace(0, len(units), parts + 1).round().astype(int)
    return [joiner.join(units[a:b]) for a, b in itertools.pairwise(bounds)]


def typed_strokes(text: str, font: str = "futural", hanzi: Path | None = None) -> Strokes:
    """``text`` as strokes: hanzi medians when it holds CJK ideographs, else a Hershey font.

    Parameters
    ----------
    text
        What to write.
    font
        Hershey font for Latin text.
    hanzi
        hanzi-writer-data JSON file or directory for characters not bundled.
    """
    return hanzi_text(text, source=hanzi) if is_cjk(text) else text_strokes(text, font)
