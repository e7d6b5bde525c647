"""Typed text to strokes: Latin through Hershey fonts, Chinese through hanzi medians."""

from __future__ import annotations

import itertools
import unicodedata
from pathlib import Path

import numpy as np

from skyquill.errors import InputError
from skyquill.strokes.hanzi import EM, EM_BOTTOM, EM_TOP, hanzi_text
from skyquill.strokes.hershey import line_extent, text_strokes
from skyquill.strokes.model import FloatArray, Strokes

#: Unicode name prefixes of what is written from hanzi medians: the ideographs, and
#: the radical forms (U+2E80 block) that hanzi-writer-data also ships (⺀, ⺈, ...).
CJK_NAMES = ("CJK UNIFIED IDEOGRAPH", "CJK COMPATIBILITY IDEOGRAPH", "CJK RADICAL")


def is_cjk(text: str) -> bool:
    """Whether ``text`` holds CJK ideographs or radicals (hanzi medians, not Hershey)."""
    return any(unicodedata.name(c, "").startswith(CJK_NAMES) for c in text)


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


def typed_parts(
    text: str, parts: int, font: str = "futural", hanzi: Path | None = None
) -> list[Strokes]:
    """``text`` shared out in ``parts`` consecutive chunks, all laid out with one scale.

    Each chunk (:func:`split_text`) is written by :func:`typed_strokes` and
    given a layout box (:attr:`Strokes.box`): its character cells (hanzi: one
    em box per character; Latin: from the left of the first glyph to the end of
    the ink, descender line to cap line), grown to the widest and tallest
    chunk's. Every part then has the same extent, so scaling each to the same
    size scales all alike: 一 on its own is as wide as it is beside 永, not
    stretched to the whole board, and a narrow word stays narrow.

    Parameters
    ----------
    text
        What to write.
    parts
        Number of chunks (drones), at least 1. A single part is returned as
        :func:`typed_strokes` gives it (fitted to its ink).
    font, hanzi
        As for :func:`typed_strokes`.

    Returns
    -------
    list of Strokes
        One per chunk, in order, in font or em-box units, y up.

    Raises
    ------
    InputError
        If ``parts`` is not an integer >= 1, there are fewer characters
        (hanzi) or words (Latin) than parts, or a chunk cannot be written (as
        :func:`typed_strokes`).
    """
    if isinstance(parts, bool) or not isinstance(parts, int) or parts < 1:
        raise InputError(f"parts: got {parts!r}, expected an integer >= 1")
    if parts == 1:
        return [typed_strokes(text, font, hanzi)]
    chunks = split_text(text, parts)
    written = [typed_strokes(chunk, font, hanzi) for chunk in chunks]
    extents = [
        Strokes(paths=s.paths, box=_cells(chunk, s, font)).bounds()
        for chunk, s in zip(chunks, written, strict=True)
    ]
    size = np.max([hi - lo for lo, hi in extents], axis=0)
    return [
        Strokes(paths=s.paths, times=s.times, source=s.source, box=np.stack([lo, lo + size]))
        for s, (lo, _) in zip(written, extents, strict=True)
    ]


def _cells(chunk: str, strokes: Strokes, font: str) -> FloatArray:
    """The layout box of one chunk as written by :func:`typed_strokes`, its units."""
    if is_cjk(chunk):
        # hanzi_text puts character i's em box at x = i * EM, spaces included.
        return np.array([[0.0, EM_BOTTOM], [len(chunk) * EM, EM_TOP]])
    bottom, top = line_extent(font)
    right = max(float(p[:, 0].max()) for p in strokes.paths)
    return np.array([[0.0, bottom], [right, top]])
