"""Strokes from a JSON file (a tablet's or the studio's recording)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from skyquill.errors import InputError
from skyquill.strokes.model import Strokes

_KEYS = ("strokes", "t")


def read_json(path: str | Path, what: str) -> Any:
    """Parse a JSON file, turning every failure into an :class:`InputError`.

    Parameters
    ----------
    path
        The file.
    what
        What the file should hold, for the message (e.g. ``"a stroke JSON file"``).
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError(f"{p}: no such file, expected {what}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{p}: cannot be read ({exc}), expected {what}") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(
            f"{p}: malformed JSON at line {exc.lineno}, column {exc.colno} ({exc.msg}); "
            f"expected {what}"
        ) from None
    except RecursionError:
        raise InputError(f"{p}: JSON nested too deeply, expected {what}") from None


def load_stroke_json(path: str | Path) -> Strokes:
    """Load strokes recorded as JSON.

    The file holds an object ``{"strokes": [[[x, y], ...], ...], "t": [[t, ...],
    ...]}``: one list of ``[x, y]`` points per stroke, in drawing order, y up,
    in any length unit; ``"t"`` is optional (or ``null``) and gives one
    timestamp per point, strictly increasing within and across strokes. No
    other key is accepted, so that a misspelt ``"t"`` is not silently dropped.

    Parameters
    ----------
    path
        The JSON file.

    Returns
    -------
    Strokes
        ``source`` is the file's name.

    Raises
    ------
    InputError
        If the file is missing, unreadable or malformed JSON, or its content
        breaks any rule above or of :class:`Strokes`; the message names the
        file and the offending field.
    """
    p = Path(path)
    what = 'an object {"strokes": [[[x, y], ...], ...], "t": [[t, ...], ...] (optional)}'
    data = read_json(p, what)
    if not isinstance(data, dict):
        raise InputError(f"{p}: got a JSON {type(data).__name__} at top level, expected {what}")
    unknown = sorted(set(data) - set(_KEYS))
    if unknown:
        raise InputError(f"{p}: got unknown key(s) {unknown}, expected only {list(_KEYS)}")
    if "strokes" not in data:
        raise InputError(f'{p}: no "strokes" key, expected {what}')
    strokes = data["strokes"]
    if not isinstance(strokes, list):
        raise InputError(
            f'{p}: "strokes" is a JSON {type(strokes).__name__}, expected a list of strokes'
        )
    times = data.get("t")
    if times is not None and not isinstance(times, list):
        raise InputError(
            f'{p}: "t" is a JSON {type(times).__name__}, expected a list of per-stroke time lists'
        )
    return Strokes(
        paths=tuple(strokes),
        times=None if times is None else tuple(times),
        source=p.name,
    )
