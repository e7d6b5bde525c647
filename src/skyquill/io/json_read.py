"""Parse untrusted JSON: one set of refusals for every JSON file skyquill reads.

The file is opened and decoded by :mod:`skyquill.io.source` (a regular file, its
size checked before reading; UTF-8 with or without a byte-order mark). Everything
else is an :class:`~skyquill.errors.InputError` whose message names the file, what
came and what was expected: malformed JSON; what RFC 8259 does not allow but
Python's parser takes -- ``NaN``, ``Infinity``, a number beyond the float range
(``1e400``, which Python reads as infinity) and a key repeated in one object
(Python keeps the last one silently); an integer literal too long for Python to
convert; or nesting deeper than :data:`MAX_DEPTH` (checked without recursion, so
that the readers' own messages, which ``repr`` the values, and numpy's array
conversion never meet a structure deep enough to overflow the stack).
"""

from __future__ import annotations

import gc
import json
import math
import re
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from skyquill.errors import InputError
from skyquill.io.source import decode_text, read_bytes

#: Deepest nesting of arrays and objects accepted. skyquill's own files nest at
#: most 6 deep; 64 leaves room for any honest producer and stays far below the
#: interpreter's recursion limit (and numpy's 32 array dimensions are checked
#: by the readers on conversion).
MAX_DEPTH = 64
#: Largest JSON file read by default, bytes (64 MiB); a reader may pass its own.
MAX_BYTES = 64 * 2**20


class _RefusedError(Exception):
    """Raised inside the parser's hooks: what came, and the rule it broke."""

    def __init__(self, got: str, rule: str) -> None:
        super().__init__(got)
        self.got = got
        self.rule = rule


def read_json_file(path: str | Path, what: str, *, max_bytes: int = MAX_BYTES) -> Any:
    """Read and parse the JSON file ``path``.

    Parameters
    ----------
    path
        The file.
    what
        What the file should hold, for messages (e.g. ``"a stroke JSON file"``).
    max_bytes
        Largest size accepted, bytes; a larger file is refused before it is read.

    Returns
    -------
    Any
        The parsed document (``dict``, ``list``, ``str``, number, ``bool`` or ``None``).

    Raises
    ------
    InputError
        See the module docstring; the message starts with the file's path.
    """
    file = Path(path)
    raw = read_bytes(file, what, max_bytes=max_bytes)
    return parse_json(raw, str(file), what)


def parse_json(raw: bytes, name: str, what: str) -> Any:
    """Parse the JSON bytes ``raw``; ``name`` (a file's name) starts every message.

    Raises
    ------
    InputError
        See the module docstring.
    """
    text = decode_text(raw, name, what)
    try:
        with collector_paused():
            data = json.loads(text, object_pairs_hook=_unique_keys, parse_constant=_no_constant)
    except _RefusedError as exc:
        raise InputError(f"{name}: got {exc.got}, expected {what} ({exc.rule})") from None
    except json.JSONDecodeError as exc:
        raise InputError(
            f"{name}: got malformed JSON at line {exc.lineno}, column {exc.colno} ({exc.msg}), "
            f"expected {what}"
        ) from None
    except RecursionError:
        raise InputError(
            f"{name}: got JSON nested too deeply, expected {what} nested at most {MAX_DEPTH} deep"
        ) from None
    except ValueError as exc:  # an integer literal beyond Python's digit limit
        raise InputError(f"{name}: got an unreadable number ({exc}), expected {what}") from None
    if _may_refuse(raw):
        check_depth(data, name, what)
    return data


@contextmanager
def collector_paused() -> Iterator[None]:
    """Python's cyclic garbage collector paused (and resumed if it ran), for building or
    parsing a large JSON document.

    Such a document allocates a list or dict per array or object and none of them can
    form a cycle, but each allocation counts towards a collection that walks every object
    alive: a 40 MB ``show.json`` (1,000 drones' keyframes) parsed in 1.5 s instead of 5.6 s.
    """
    running = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if running:
            gc.enable()


#: A string of the JSON text, escapes included (UTF-8 bytes: no byte of a multi-byte
#: character is a quote or a backslash).
_STRING = re.compile(rb'"[^"\\]*(?:\\.[^"\\]*)*"')
#: An exponent of 100 or more.
_LARGE_EXPONENT = re.compile(rb"[eE]\+?0*[1-9]\d\d")
#: Digits to ``0``, every other byte to a space: a run of digits is a run of ``0``.
_DIGITS = bytes(ord("0") if ord("0") <= c <= ord("9") else ord(" ") for c in range(256))
#: Every byte but a bracket (deleted before counting them).
_NOT_BRACKETS = bytes(c for c in range(256) if chr(c) not in "[]{}")


def _may_refuse(raw: bytes) -> bool:
    """Whether :func:`check_depth` could refuse the document parsed from ``raw``.

    Read off the text by C-speed scans (0.6 s on a 40 MB ``show.json``) instead of
    walking every value (3 s): outside its strings, a document nested no deeper than
    :data:`MAX_DEPTH` brackets, without a run of 100 digits or an exponent of 100 or
    more, holds no number beyond 1e200 and nothing else the walk refuses. Otherwise the
    walk runs and refuses as it always has.
    """
    bare = _STRING.sub(b"", raw)
    if _LARGE_EXPONENT.search(bare) or bare.translate(_DIGITS).find(b"0" * 100) >= 0:
        return True
    brackets = np.frombuffer(bare.translate(None, _NOT_BRACKETS), dtype=np.uint8)
    if not brackets.size:
        return False
    step = np.where((brackets == ord("[")) | (brackets == ord("{")), 1, -1)
    return int(np.cumsum(step).max()) > MAX_DEPTH


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """An object's pairs as a dict; a repeated key is refused, not overwritten."""
    data = dict(pairs)
    if len(data) < len(pairs):
        seen: set[str] = set()
        for key, _ in pairs:
            if key in seen:
                raise _RefusedError(f"the key {_short(key)!r} twice in one object", "each key once")
            seen.add(key)
    return data


def _no_constant(word: str) -> Any:
    """``NaN``, ``Infinity`` and ``-Infinity``: not JSON (RFC 8259), refused."""
    raise _RefusedError(word, "finite JSON numbers: NaN and Infinity are not JSON")


def _short(text: str) -> str:
    return text if len(text) <= 40 else text[:37] + "..."


def check_depth(data: Any, name: str, what: str) -> None:
    """Refuse ``data`` nested deeper than :data:`MAX_DEPTH` (an explicit stack, no recursion)."""
    stack: list[tuple[Any, int]] = [(data, 0)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict):
            children: Any = item.values()
        elif isinstance(item, list):
            children = item
        else:
            if isinstance(item, float) and not math.isfinite(item):
                # Python reads 1e400 as infinity (NaN and Infinity are refused while parsing).
                raise InputError(
                    f"{name}: got a number beyond the float range (about 1.8e308), expected {what}"
                )
            continue
        if depth >= MAX_DEPTH:
            raise InputError(f"{name}: got JSON nested more than {MAX_DEPTH} deep, expected {what}")
        stack.extend((child, depth + 1) for child in children)
