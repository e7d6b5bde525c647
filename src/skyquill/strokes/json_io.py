"""Strokes from a JSON file (a tablet's or the studio's recording)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from skyquill.errors import InputError
from skyquill.io.json_read import read_json_file
from skyquill.strokes.model import MAX_POINTS, MAX_STROKES, Strokes

_KEYS = ("strokes", "t")
#: Largest stroke JSON file read, bytes: :data:`MAX_POINTS` points take ~5 MB of text.
MAX_BYTES = 32 * 2**20


def read_json(path: str | Path, what: str) -> Any:
    """Parse a JSON file, turning every failure into an :class:`InputError`.

    Parameters
    ----------
    path
        The file.
    what
        What the file should hold, for the message (e.g. ``"a stroke JSON file"``).

    Raises
    ------
    InputError
        Missing, larger than :data:`MAX_BYTES`, not UTF-8 (a byte-order mark is
        accepted), malformed or too deeply nested JSON
        (:mod:`skyquill.io.json_read`).
    """
    return read_json_file(path, what, max_bytes=MAX_BYTES)


def load_stroke_json(path: str | Path) -> Strokes:
    """Load strokes recorded as JSON.

    The file holds an object ``{"strokes": [[[x, y], ...], ...], "t": [[t, ...],
    ...]}``: one list of ``[x, y]`` points per stroke, in drawing order, y up,
    in any length unit; ``"t"`` is optional (or ``null``) and gives one
    timestamp per point, strictly increasing within and across strokes. No
    other key is accepted, so that a misspelt ``"t"`` is not silently dropped.
    Coordinates and times are JSON numbers: a string such as ``"1"`` is
    refused, not converted. At most :data:`~skyquill.strokes.model.MAX_STROKES`
    strokes and :data:`~skyquill.strokes.model.MAX_POINTS` points in all.

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
        If the file is missing, unreadable, not UTF-8 or malformed JSON, or its
        content breaks any rule above or of :class:`Strokes`; the message names
        the file and the offending field.
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
    _check_strokes(p, strokes)
    times = data.get("t")
    if times is not None:
        _check_times(p, times)
    return Strokes(
        paths=tuple(strokes),
        times=None if times is None else tuple(times),
        source=p.name,
    )


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _check_strokes(p: Path, strokes: list[Any]) -> None:
    """Refuse all but lists of ``[x, y]`` numbers within the ceilings, before numpy sees them."""
    if len(strokes) > MAX_STROKES:
        raise InputError(
            f'{p}: "strokes": got {len(strokes):,} strokes, expected at most {MAX_STROKES:,}'
        )
    total = 0
    for i, stroke in enumerate(strokes):
        if not isinstance(stroke, list):
            raise InputError(
                f'{p}: "strokes"[{i}]: got a JSON {type(stroke).__name__}, '
                "expected a list of [x, y] points"
            )
        total += len(stroke)
        if total > MAX_POINTS:
            raise InputError(
                f'{p}: "strokes": got more than {MAX_POINTS:,} points by stroke {i}, '
                f"expected at most {MAX_POINTS:,} in all"
            )
        for k, point in enumerate(stroke):
            if not (isinstance(point, list) and len(point) == 2 and all(map(_is_number, point))):
                raise InputError(
                    f'{p}: "strokes"[{i}][{k}]: got {_short(point)}, '
                    "expected [x, y] of two JSON numbers"
                )


def _check_times(p: Path, times: Any) -> None:
    if not isinstance(times, list):
        raise InputError(
            f'{p}: "t" is a JSON {type(times).__name__}, expected a list of per-stroke time lists'
        )
    for i, stroke in enumerate(times[: MAX_STROKES + 1]):
        if not isinstance(stroke, list) or not all(map(_is_number, stroke)):
            raise InputError(
                f'{p}: "t"[{i}]: got {_short(stroke)}, expected a list of JSON numbers (s)'
            )


def _short(value: Any) -> str:
    """A value for a message, at most 40 characters (the value is at most 64 deep)."""
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."
