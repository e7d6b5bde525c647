"""Where commands put their files: staged, checked, then moved in; nobody else's file replaced.

A command writes into a staging folder inside its output folder
(:func:`staged_output`); when it has finished, every file is checked and then
moved into place by an atomic rename, ``summary.json`` last:

* a file already there is replaced only if the same command wrote it in an
  earlier run (the folder's :data:`MANIFEST` says who wrote what), or with
  ``force``; otherwise nothing is replaced and the message says which file and
  how to proceed;
* a file that is one of the command's own inputs is never written over;
* files the same command wrote earlier and does not write now (a plan for two
  drones replaced by one for one drone) are removed, so the folder holds one
  result.

An interrupted run leaves the previous files or the new ones, each whole; a
refused or failed run leaves the folder as it was.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path

from skyquill.errors import InputError
from skyquill.io.atomic import write_json

#: Who wrote which file in a folder: ``{"files": {name: command}}``.
MANIFEST = ".skyquill-files.json"
#: Moved in last: it names the others, so a reader never sees it ahead of them.
LAST = "summary.json"


@contextlib.contextmanager
def staged_output(
    out: Path, command: str, *, force: bool = False, inputs: Sequence[Path] = ()
) -> Iterator[Path]:
    """A fresh staging folder to write into; its files replace ``out``'s at the end.

    Parameters
    ----------
    out
        The output folder (created if missing; an existing file is refused).
    command
        Who writes (``"fit"``, ``"fly"``, ``"export"``, ...), recorded per file.
    force
        Replace files that another command or another program wrote.
    inputs
        The command's input files, never written over.

    Raises
    ------
    InputError
        ``out`` is a file, or a file would replace one that is not the
        command's own (or an input). Nothing is moved then.
    """
    check_folder(out)
    out.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=".staging-", dir=out))
    try:
        yield staging
        _commit(staging, out, command, force, inputs)
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def check_folder(out: Path, name: str = "out") -> None:
    """Refuse ``out`` (the argument ``name``) if it is a file or lies inside one."""
    if out.exists() and not out.is_dir():
        raise InputError(f"{name}: got {str(out)!r}, an existing file; expected a folder")
    for parent in out.parents:
        if parent.exists():
            if not parent.is_dir():
                raise InputError(
                    f"{name}: got {str(out)!r}, inside {str(parent)!r} which is a file; "
                    "expected a folder"
                )
            return


def _commit(staging: Path, out: Path, command: str, force: bool, inputs: Sequence[Path]) -> None:
    names = sorted((p.name for p in staging.iterdir() if p.is_file()), key=lambda n: n == LAST)
    owners = _owners(out)
    protected = {p.resolve() for p in inputs}
    for name in names:
        target = out / name
        if target.resolve() in protected:
            raise InputError(
                f"out: {str(target)!r} is one of this command's inputs; expected another "
                "file or folder to write to"
            )
        owner = owners.get(name)
        if target.exists() and owner != command and not force:
            who = f"skyquill {owner}" if owner else "another program"
            raise InputError(
                f"out: {str(target)!r} exists and was written by {who}; expected a folder "
                f"without it (choose another --out, or --force to replace it)"
            )
    stale = [n for n, who in owners.items() if who == command and n not in names]
    for name in names:
        os.replace(staging / name, out / name)
        owners[name] = command
    for name in stale:
        (out / name).unlink(missing_ok=True)
        owners.pop(name)
    write_json(out / MANIFEST, {"files": owners})


def _owners(out: Path) -> dict[str, str]:
    """``{file: command}`` of the folder's manifest (empty when there is none or it is damaged)."""
    try:
        data = json.loads((out / MANIFEST).read_text(encoding="utf-8"))
        files = data["files"]
    except (OSError, ValueError, KeyError, TypeError, RecursionError):
        return {}
    if not isinstance(files, dict):
        return {}
    return {str(k): str(v) for k, v in files.items() if isinstance(k, str) and isinstance(v, str)}
