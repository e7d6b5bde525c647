"""Strokes of typed Latin text, drawn with the Hershey vector fonts."""

from __future__ import annotations

from typing import Any

import numpy as np
from HersheyFonts import HersheyFonts
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.strokes.model import Strokes

FloatArray = NDArray[np.float64]

#: Distance between baselines of successive lines, in units of the font's
#: cap-to-baseline height (21 font units for the standard Hershey fonts).
LINE_SPACING = 1.6


def hershey_fonts() -> list[str]:
    """Names of the Hershey fonts ``text_strokes`` can use (e.g. ``"futural"``)."""
    return list(HersheyFonts().default_font_names)


def _load(font: str) -> HersheyFonts:
    if not isinstance(font, str):
        raise InputError(f"font: got {type(font).__name__}, expected a font name (str)")
    hf = HersheyFonts()
    names = list(hf.default_font_names)
    if font not in names:
        raise InputError(f"font: got {font!r}, expected one of {', '.join(names)}")
    hf.load_default_font(font)
    return hf


def missing_glyphs(text: str, font: str = "futural") -> str:
    """The characters of ``text`` (line breaks aside) that ``font`` has no glyph for.

    Each once, sorted by code point; ``""`` when :func:`text_strokes` can write all of it.
    """
    if not isinstance(text, str):
        raise InputError(f"text: got {type(text).__name__}, expected a str")
    return "".join(_missing(text, _load(font)))


def _missing(text: str, hf: HersheyFonts) -> list[str]:
    glyphs = hf.all_glyphs
    return sorted({c for c in text if c != "\n" and c not in glyphs})


def line_extent(font: str = "futural") -> tuple[float, float]:
    """The bottom and top of a line of text, font units, y up from the baseline.

    Parameters
    ----------
    font
        A name from :func:`hershey_fonts`.

    Returns
    -------
    bottom, top
        The descender line (negative) and the cap line, in the units and frame
        of :func:`text_strokes` (``-7`` and ``21`` for the standard fonts).

    Raises
    ------
    InputError
        If ``font`` is unknown.
    """
    opts = _load(font).render_options
    base = float(opts["base_line"])
    return base - float(opts["bottom_line"]), base - float(opts["cap_line"])


def _polylines(segments: list[tuple[tuple[float, float], tuple[float, float]]]) -> list[list[Any]]:
    """Join consecutive segments sharing an endpoint into polylines."""
    lines: list[list[Any]] = []
    for a, b in segments:
        if lines and lines[-1][-1] == a:
            lines[-1].append(b)
        else:
            lines.append([a, b])
    return lines


def text_strokes(text: str, font: str = "futural") -> Strokes:
    """Strokes that write ``text`` in a Hershey font, left to right.

    Each glyph's line segments (``_HersheyGlyph.lines`` of the ``Hershey-Fonts``
    package) are joined into polylines wherever one segment starts where the
    previous one ended, so a stroke is one pen-down movement; glyphs follow each
    other at their advance widths, and ``"\\n"`` starts a new line below.

    Parameters
    ----------
    text
        The text; every character must be in the font (the standard fonts cover
        printable ASCII). Spaces advance without drawing.
    font
        A name from :func:`hershey_fonts`; ``"futural"`` (Futura light, single
        stroke) writes the cleanest lines.

    Returns
    -------
    Strokes
        Points in font units, y up, the first line's baseline at ``y = 0`` and
        the first glyph's left side at ``x = 0``; capitals are 21 units tall.
        ``source`` reads ``"text 'Hi' (futural)"``.

    Raises
    ------
    InputError
        If ``font`` is unknown (the message lists the available fonts), ``text``
        is empty or only white space, or some characters are not in the font
        (the message names them).
    """
    if not isinstance(text, str):
        raise InputError(f"text: got {type(text).__name__}, expected a str")
    if not text.strip():
        raise InputError(f"text: got {text!r}, expected at least one visible character")
    hf = _load(font)
    glyphs = hf.all_glyphs
    missing = _missing(text, hf)
    if missing:
        codes = ", ".join(f"U+{ord(c):04X}" for c in missing)
        raise InputError(
            f"text: characters {''.join(missing)!r} ({codes}) are not in Hershey font "
            f"{font!r}, expected printable ASCII"
        )
    opts = hf.render_options
    base = float(opts["base_line"])
    line_height = LINE_SPACING * (base - float(opts["cap_line"]))

    paths: list[FloatArray] = []
    x0 = 0.0
    y0 = 0.0
    for ch in text:
        if ch == "\n":
            x0 = 0.0
            y0 -= line_height
            continue
        glyph = glyphs[ch]
        left = float(glyph.left_offset)
        for line in _polylines(list(glyph.lines)):
            pts = np.asarray(line, dtype=np.float64)
            # Hershey y points down from the glyph's centre; put the baseline at y0, y up.
            paths.append(np.column_stack([x0 + pts[:, 0] - left, y0 + base - pts[:, 1]]))
        x0 += float(glyph.char_width)
    if not paths:
        raise InputError(f"text: got {text!r}, which draws nothing in font {font!r}")
    return Strokes(paths=tuple(paths), source=f"text {text!r} ({font})")
