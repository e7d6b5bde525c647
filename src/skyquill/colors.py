"""Pen colours: the light a drone shows while its pen is down, as R, G, B in 0..255.

skyquill's own notion of colour, shared by the plan files, the show scripts, the pictures and
every exporter that carries lights (Skybrush's light programs are in
:mod:`skyquill.export.skybrush.lights`).
"""

from __future__ import annotations

import string
from collections.abc import Sequence
from typing import Any

import numpy as np

from skyquill.errors import InputError

RGB = tuple[int, int, int]


def hex_rgb(digits: str) -> RGB | None:
    """``"rrggbb"`` (six hexadecimal digits) as a colour; ``None`` when it is not that."""
    if len(digits) != 6 or any(c not in string.hexdigits for c in digits):
        return None
    return (int(digits[0:2], 16), int(digits[2:4], 16), int(digits[4:6], 16))


def check_rgb(name: str, rgb: Any) -> RGB:
    """``rgb`` as three integers in 0..255; :class:`InputError` naming ``name`` otherwise."""
    if not (is_rgb(rgb) and all(0 <= int(c) <= 255 for c in rgb)):
        raise InputError(f"{name}: got {rgb!r:.60}, expected three integers in 0..255 (R, G, B)")
    return (int(rgb[0]), int(rgb[1]), int(rgb[2]))


def window_colors(name: str, windows: Sequence[Any], colors: Any) -> tuple[RGB, ...]:
    """``colors`` checked to be one R, G, B triple per window.

    Raises
    ------
    InputError
        Naming ``name``: not a sequence of triples, a colour that is not three integers
        in 0..255, or a count that is not the number of windows.
    """
    if isinstance(colors, str | bytes) or not isinstance(colors, Sequence) or is_rgb(colors):
        raise InputError(f"{name}: got {colors!r:.60}, expected one R, G, B triple per pen window")
    if len(colors) != len(windows):
        raise InputError(
            f"{name}: got {len(colors)} colours, expected one per pen window ({len(windows)})"
        )
    return tuple(check_rgb(f"{name}[{i}]", c) for i, c in enumerate(colors))


def is_rgb(value: Any) -> bool:
    return (
        isinstance(value, Sequence)
        and not isinstance(value, str)
        and len(value) == 3
        and all(isinstance(c, int | np.integer) and not isinstance(c, bool) for c in value)
    )
