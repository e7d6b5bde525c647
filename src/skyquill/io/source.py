"""Where every input file is opened: one regular-file check, one size check, one BOM rule.

Every reader (CSV, JSON strokes, SVG, GeoJSON/WKT, TOML show scripts, ``.skyc``,
hanzi files, dot CSVs, pictures, plan files) gets its bytes or its text stream here:

* **A regular file, or nothing.** The file is opened without blocking
  (``O_NONBLOCK``) and checked on the open descriptor (``fstat``): a named pipe, a
  device (``/dev/zero``, a terminal), a socket or a folder is refused at once --
  reading one would block forever or never end. A symbolic link to a regular file
  is read (that is what the user named).
* **A size known before reading.** A file above the reader's ceiling is refused
  before a byte is read, and never more than the ceiling is read (a file growing
  while it is read is refused too).
* **One byte-order-mark rule.** Text is UTF-8, with or without the byte-order mark
  Windows editors and spreadsheets write; UTF-16 (named by its mark), a NUL byte
  (binary data) or bytes that are not UTF-8 are refused, naming the offset.

Messages start with the file's name and say what came and what was expected.
"""

from __future__ import annotations

import codecs
import contextlib
import io
import os
import stat
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO, TextIO

from skyquill.errors import InputError

_UTF16_BOMS = (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)
#: How text is decoded everywhere: UTF-8, a leading byte-order mark dropped.
ENCODING = "utf-8-sig"

_KINDS = (
    (stat.S_ISDIR, "a folder"),
    (stat.S_ISFIFO, "a named pipe"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def read_bytes(path: str | Path, what: str, *, max_bytes: int, name: str | None = None) -> bytes:
    """The bytes of the regular file ``path``, at most ``max_bytes`` of them.

    Parameters
    ----------
    path
        The file.
    what
        What it should hold, for messages (``"a stroke JSON file"``).
    max_bytes
        Largest size accepted, bytes.
    name
        How messages name the file (default: ``path`` as given).

    Raises
    ------
    InputError
        Missing, unreadable, not a regular file, or larger than ``max_bytes``.
    """
    shown = str(path) if name is None else name
    with _opened(Path(path), what, shown, max_bytes) as fd:
        chunks: list[bytes] = []
        left = max_bytes + 1
        while left > 0:
            chunk = _read(fd, min(left, 2**20), shown, what)
            if not chunk:
                break
            chunks.append(chunk)
            left -= len(chunk)
    raw = b"".join(chunks)
    if len(raw) > max_bytes:
        raise InputError(f"{shown}: got a file that grew past {max_bytes:,} bytes, expected {what}")
    return raw


@contextlib.contextmanager
def open_text(
    path: str | Path, what: str, *, max_bytes: int, name: str | None = None
) -> Iterator[TextIO]:
    """A text stream of the regular file ``path`` (UTF-8, an optional byte-order mark).

    For readers that stream a large file line by line (the CSV reader); decoding
    errors surface as :class:`UnicodeDecodeError` while reading, for the reader to
    name. ``newline=""``, as the ``csv`` module wants.

    Raises
    ------
    InputError
        As :func:`read_bytes`, before anything is read.
    """
    shown = str(path) if name is None else name
    with _opened(Path(path), what, shown, max_bytes) as fd:
        raw = io.FileIO(os.dup(fd), "r")
        with io.TextIOWrapper(io.BufferedReader(raw), encoding=ENCODING, newline="") as text:
            yield text


@contextlib.contextmanager
def open_binary(
    path: str | Path, what: str, *, max_bytes: int, name: str | None = None
) -> Iterator[BinaryIO]:
    """A binary stream of the regular file ``path`` (for ZIP archives and pictures).

    Raises
    ------
    InputError
        As :func:`read_bytes`, before anything is read.
    """
    shown = str(path) if name is None else name
    with (
        _opened(Path(path), what, shown, max_bytes) as fd,
        io.BufferedReader(io.FileIO(os.dup(fd), "r")) as stream,
    ):
        yield stream


def decode_text(raw: bytes, name: str, what: str) -> str:
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
        return raw.decode(ENCODING)
    except UnicodeDecodeError as exc:
        raise InputError(
            f"{name}: got bytes that are not UTF-8 (at offset {exc.start}), "
            f"expected {what} in UTF-8"
        ) from None


def read_text(path: str | Path, what: str, *, max_bytes: int, name: str | None = None) -> str:
    """:func:`read_bytes` then :func:`decode_text`."""
    shown = str(path) if name is None else name
    return decode_text(read_bytes(path, what, max_bytes=max_bytes, name=shown), shown, what)


def special_kind(path: str | Path) -> str | None:
    """What ``path`` is when it exists but is neither a regular file nor a folder
    (``"a named pipe"``, ``"a character device"``, ...); None otherwise."""
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return None
    if stat.S_ISREG(mode) or stat.S_ISDIR(mode):
        return None
    return next((kind for test, kind in _KINDS if test(mode)), "a special file")


def is_regular_file(path: str | Path) -> bool:
    """Whether ``path`` names a regular file (following links), without opening it."""
    try:
        return stat.S_ISREG(os.stat(path).st_mode)
    except (OSError, ValueError):
        return False


@contextlib.contextmanager
def _opened(path: Path, what: str, shown: str, max_bytes: int) -> Iterator[int]:
    """A descriptor of ``path`` once it is known to be a regular file of at most ``max_bytes``."""
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0)
    try:
        fd = os.open(path, flags | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise InputError(f"{shown}: no such file, expected {what}") from None
    except (OSError, ValueError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise InputError(
            f"{shown}: got a file that cannot be opened ({reason}), expected {what}"
        ) from None
    try:
        mode = os.fstat(fd).st_mode
        for test, kind in _KINDS:
            if test(mode):
                raise InputError(f"{shown}: got {kind}, expected {what} (a regular file)")
        size = os.fstat(fd).st_size
        if size > max_bytes:
            raise InputError(
                f"{shown}: got {size:,} bytes, expected {what} of at most {max_bytes:,}"
            )
        os.set_blocking(fd, True)
        yield fd
    finally:
        os.close(fd)


def _read(fd: int, n: int, shown: str, what: str) -> bytes:
    try:
        return os.read(fd, n)
    except OSError as exc:
        raise InputError(
            f"{shown}: got a file that cannot be read ({exc.strerror}), expected {what}"
        ) from None
