"""Parse untrusted JSON: one set of refusals for every JSON file skyquill reads.

The text must be UTF-8 (a leading byte-order mark is accepted, as editors on
Windows write one). Everything else is an :class:`~skyquill.errors.InputError`
whose message names the file, what came and what was expected: a missing or
unreadable file, a file larger than the caller's ceiling (checked before it is
read), UTF-16 or binary bytes, malformed JSON, an integer literal too long for
Python to convert, or nesting deeper than :data:`MAX_DEPTH` (checked without
recursion, so that the readers' own messages, which ``repr`` the values, and
numpy's array conversion never meet a structure deep enough to overflow the
stack).
"""

from __future__ import annotations

import codecs
import json
from pathlib import Path
from typing import Any

from skyquill.errors import InputError

#: Deepest nesting of arrays and objects accepted. skyquill's own files nest at
#: most 6 deep; 64 leaves room for any honest producer and stays far below the
#: interpreter's recursion limit (and numpy's 32 array dimensions are checked
#: by the readers on conversion).
MAX_DEPTH = 64
#: Largest JSON file read by default, bytes (64 MiB); a reader may pass its own.
MAX_BYTES = 64 * 2**20

_UTF16_BOMS = (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)


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
    try:
        size = file.stat().st_size
    except FileNotFoundError:
        raise InputError(f"{file}: no such file, expected {what}") from None
    except OSError as exc:
        raise InputError(f"{file}: cannot be read ({exc}), expected {what}") from None
    if size > max_bytes:
        raise InputError(f"{file}: got {size:,} bytes, expected {what} of at most {max_bytes:,}")
    try:
        raw = file.read_bytes()
    except OSError as exc:
        raise InputError(f"{file}: cannot be read ({exc}), expected {what}") from None
    return parse_json(raw, str(file), what)


def parse_json(raw: bytes, name: str, what: str) -> Any:
    """Parse the JSON bytes ``raw``; ``name`` (a file's name) starts every message.

    Raises
    ------
    InputError
        See the module docstring.
    """
    text = decode_utf8(raw, name, what)
    try:
        data = json.loads(text)
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
    check_depth(data, name, what)
    return data


def decode_utf8(raw: bytes, name: str, what: str) -> str:
    """``raw`` as UTF-8 text, a leading byte-order mark dropped.

    Raises
    ------
    InputError
        Naming UTF-16 (by its byte-order mark), binary data (a NUL byte) or the
        first byte that is not UTF-8.
    """
    if raw.startswith(_UTF16_BOMS):
        raise InputError(f"{name}: got UTF-16 text, expected {what} in UTF-8")
    nul = raw.find(b"\x00")
    if nul >= 0:
        raise InputError(
            f"{name}: got binary data (a NUL byte at offset {nul}), expected {what} in UTF-8"
        )
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputError(
            f"{name}: got bytes that are not UTF-8 (at offset {exc.start}), "
            f"expected {what} in UTF-8"
        ) from None


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
            continue
        if depth >= MAX_DEPTH:
            raise InputError(f"{name}: got JSON nested more than {MAX_DEPTH} deep, expected {what}")
        stack.extend((child, depth + 1) for child in children)
