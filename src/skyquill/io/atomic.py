"""Files written whole or not at all: a temporary file in the same folder, then a rename.

An interrupted run leaves the previous file or the new one, never half of one
(docs/architecture.md "Outputs and errors"); the rename is atomic on POSIX within one file
system, which a temporary file in the same folder guarantees. The file gets the mode any
new file of the user's gets (``0666`` less the umask), not the ``0600`` of a temporary file.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any


def _umask() -> int:
    """The process's umask (read by setting it and putting it back: there is no getter)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


#: Read once at import, while the program is single-threaded.
_UMASK = _umask()


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path to write to; renamed to ``path`` when the block ends without error.

    The temporary name keeps ``path``'s suffix, so writers that choose the
    format by suffix (matplotlib, numpy) behave as for ``path`` itself.
    """
    target = Path(path)
    handle, name = tempfile.mkstemp(
        prefix=f".{target.stem}.", suffix=f"{target.suffix}.part{target.suffix}", dir=target.parent
    )
    os.close(handle)
    temporary = Path(name)
    try:
        yield temporary
        os.chmod(temporary, 0o666 & ~_UMASK)
        os.replace(temporary, target)
    finally:
        temporary.unlink(missing_ok=True)


def write_text(path: str | Path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def write_json(path: str | Path, data: Any, *, indent: int | None = 2) -> None:
    """Write ``data`` as JSON atomically (NaN is refused: it is not JSON)."""
    write_text(path, json.dumps(data, indent=indent, allow_nan=False) + "\n")
