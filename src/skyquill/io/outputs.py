"""Where commands put their files: staged, checked, then moved in; nobody else's file touched.

A command writes into a staging folder inside its output folder
(:func:`staged_output`); when it has finished, every file is checked and then
moved into place by an atomic rename, ``summary.json`` last:

* a file already there is replaced only if it is the command's own -- the same
  command wrote it in an earlier run and it is still exactly that file -- or with
  ``force``; otherwise nothing is replaced and the message says which file and
  how to proceed;
* a file that is one of the command's own inputs is never written over;
* files the same command wrote earlier and does not write now (a plan for two
  drones replaced by one for one drone) are removed, so the folder holds one
  result -- again only a file that is provably still the one skyquill wrote.

**The manifest is a record, never an authority.** The folder's :data:`MANIFEST`
says who wrote which file, with the file's SHA-256 and inode as written. A plan
folder can come from someone else, so nothing in it is trusted: a name is acted
on (replaced or removed) only if it is a plain file name inside ``out`` (no
folder part, no ``..``) naming a regular file (not a link, not a folder) whose
inode and content are still those recorded when skyquill moved it in. A crafted
manifest naming ``../../victim.txt``, or the user's own ``notes.txt``, or a link,
makes skyquill touch nothing; a folder copied from elsewhere (new inodes) is
treated as another program's. Nothing outside ``out`` is ever removed or
replaced: every rename and removal is of ``out / <plain name>`` itself, never
through a link.

An interrupted run leaves the previous files or the new ones, each whole; a
refused or failed run leaves the folder as it was. A run killed outright leaves
its staging folder behind: the next run into the same folder removes every
staging folder whose run has ended (each run holds a lock on its own while it
lives), and commits under a lock of the folder, so two runs into one folder end
one after the other, each whole.
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import logging
import os
import re
import shutil
import stat
import tempfile
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from skyquill.errors import InputError
from skyquill.io.atomic import write_json

logger = logging.getLogger(__name__)

#: Who wrote which file in a folder: ``{"files": {name: {"command", "sha256", "inode"}}}``.
MANIFEST = ".skyquill-files.json"
#: Moved in last: it names the others, so a reader never sees it ahead of them.
LAST = "summary.json"
#: Staging folders are named ``.staging-<random>`` inside the output folder.
STAGING_PREFIX = ".staging-"
#: The lock file a run holds in its staging folder while it lives.
_LOCK = ".lock"
#: Appended to a staging folder's name while it is removed (it still starts with the prefix:
#: a cleanup killed half way is finished by the next).
_REMOVED = ".removed"
#: A staging folder without a lock (made by an older skyquill) is removed once this old, s.
_ORPHAN_AGE_S = 3600.0
#: Largest manifest read, bytes; a larger one is ignored (the folder is then nobody's).
_MANIFEST_BYTES = 4 * 2**20
_STAGING_PART = re.compile(rf"{re.escape(STAGING_PREFIX)}[^/\\]*[/\\]")


@dataclass(frozen=True)
class _Record:
    """What the manifest says of one file: who wrote it, and the file as written."""

    command: str
    sha256: str
    inode: int

    def as_dict(self) -> dict[str, Any]:
        return {"command": self.command, "sha256": self.sha256, "inode": self.inode}


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
    _clear_leftovers(out)
    with _own_staging(out) as staging:
        try:
            yield staging
            with _folder_locked(out):
                _commit(staging, out, command, force, inputs)
        finally:
            shutil.rmtree(staging, ignore_errors=True)


@contextlib.contextmanager
def _own_staging(out: Path) -> Iterator[Path]:
    """A new staging folder in ``out``, its lock held until the run ends.

    Between creating its lock file and locking it, another run's cleanup can take the
    folder for a dead run's (it locks the file first) and move it aside
    (:func:`_claimed`): the folder is then gone once the lock is ours, and another is
    made. Two runs into one folder lost a file so (``trajectory.csv`` written into a
    staging folder being removed: a CI run of session 41).
    """
    while True:
        staging = Path(tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=out))
        with _held(staging / _LOCK, create=True):
            if (staging / _LOCK).exists():
                yield staging
                return


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


def shown_path(path: str | os.PathLike[str]) -> str:
    """``path`` as the user knows it: a file in a staging folder named as in ``--out``."""
    return _STAGING_PART.sub("", str(path))


def _commit(staging: Path, out: Path, command: str, force: bool, inputs: Sequence[Path]) -> None:
    names = sorted(
        (p.name for p in staging.iterdir() if p.is_file() and p.name != _LOCK),
        key=lambda n: n == LAST,
    )
    records = _records(out)
    protected = {p.resolve() for p in inputs}
    for name in names:
        target = out / name
        if target.resolve() in protected:
            raise InputError(
                f"out: {str(target)!r} is one of this command's inputs; expected another "
                "file or folder to write to"
            )
        _check_replaceable(out, name, records.get(name), command, force)
    stale = [
        name for name, record in records.items() if record.command == command and name not in names
    ]
    for name in names:
        os.replace(staging / name, out / name)
        records[name] = _record_of(out / name, command)
    for name in stale:
        if _is_as_recorded(out, name, records.pop(name)):
            (out / name).unlink()
    write_json(out / MANIFEST, {"files": {n: r.as_dict() for n, r in records.items()}})


def _check_replaceable(
    out: Path, name: str, record: _Record | None, command: str, force: bool
) -> None:
    """Refuse to replace ``out / name`` unless it is the command's own file (or ``force``)."""
    target = out / name
    try:
        mode = os.lstat(target).st_mode
    except FileNotFoundError:
        return
    if stat.S_ISDIR(mode):
        raise InputError(
            f"out: {str(target)!r} exists and is a folder; expected a folder without it "
            "(choose another --out)"
        )
    if force:
        return
    if record is not None and _is_as_recorded(out, name, record):
        if record.command == command:
            return
        who = f"was written by skyquill {record.command}"
    elif record is not None:
        who = f"was changed since skyquill {record.command} wrote it"
    else:
        who = "was written by another program"
    raise InputError(
        f"out: {str(target)!r} exists and {who}; expected a folder without it "
        "(choose another --out, or --force to replace it)"
    )


def _records(out: Path) -> dict[str, _Record]:
    """The manifest's well-formed records of plain file names (empty when damaged or absent)."""
    from skyquill.io.json_read import parse_json
    from skyquill.io.source import read_bytes

    try:
        raw = read_bytes(out / MANIFEST, "a manifest", max_bytes=_MANIFEST_BYTES)
        files = parse_json(raw, MANIFEST, "a manifest")["files"]
    except (InputError, KeyError, TypeError):
        return {}
    if not isinstance(files, dict):
        return {}
    records = {}
    for name, entry in files.items():
        record = _parsed(entry)
        if record is not None and _plain_name(name):
            records[name] = record
    return records


def _parsed(entry: Any) -> _Record | None:
    """A record from its JSON form; None for anything else (an old or crafted entry)."""
    if not isinstance(entry, dict):
        return None
    command, digest, inode = entry.get("command"), entry.get("sha256"), entry.get("inode")
    if not (isinstance(command, str) and isinstance(digest, str) and isinstance(inode, int)):
        return None
    return _Record(command, digest, inode)


def _plain_name(name: str) -> bool:
    """A file name with no folder part that can only mean a file directly inside the folder."""
    return (
        bool(name)
        and name not in (".", "..", MANIFEST)
        and "/" not in name
        and "\\" not in name
        and "\x00" not in name
        and not name.startswith(STAGING_PREFIX)
        and Path(name).name == name
    )


def _is_as_recorded(out: Path, name: str, record: _Record) -> bool:
    """Whether ``out / name`` is a regular file, not a link, with the recorded inode and hash."""
    if not _plain_name(name):
        return False
    try:
        info = os.lstat(out / name)
        if not stat.S_ISREG(info.st_mode) or info.st_ino != record.inode:
            return False
        return _sha256(out / name) == record.sha256
    except OSError:
        return False


def _record_of(path: Path, command: str) -> _Record:
    return _Record(command, _sha256(path), os.lstat(path).st_ino)


def _sha256(path: Path) -> str:
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0))
    with open(fd, "rb") as handle:
        return hashlib.file_digest(handle, "sha256").hexdigest()


def _clear_leftovers(out: Path) -> None:
    """Remove the staging folders of runs into ``out`` that have ended (killed, not cleaned)."""
    try:
        entries = list(os.scandir(out))
    except OSError:
        return
    for entry in entries:
        if not entry.name.startswith(STAGING_PREFIX) or not entry.is_dir(follow_symlinks=False):
            continue
        folder = Path(entry.path)
        if (aside := _claimed(folder)) is not None:
            shutil.rmtree(aside, ignore_errors=True)
            logger.info("removed %s, left by an interrupted run", folder)


def _claimed(folder: Path) -> Path | None:
    """``folder`` moved aside to be removed, if no live run holds its lock (one without a
    lock: when it is old); None if a run holds it, or another cleanup took it first.

    Moved while its lock is held here, so that a run which had created the lock but not
    yet locked it finds its folder gone and makes another (:func:`_own_staging`).
    """
    aside = folder.with_name(folder.name + _REMOVED)
    try:
        with _held(folder / _LOCK, create=False, wait=False):
            folder.rename(aside)
            return aside
    except FileNotFoundError:
        try:
            if time.time() - folder.stat().st_mtime > _ORPHAN_AGE_S:
                folder.rename(aside)
                return aside
        except OSError:
            pass
        return None
    except OSError:  # held by a live run
        return None


@contextlib.contextmanager
def _held(lock: Path, *, create: bool, wait: bool = True) -> Iterator[None]:
    """Hold an exclusive lock on the file ``lock`` (released when the process ends, too)."""
    flags = os.O_RDWR | (os.O_CREAT if create else 0) | getattr(os, "O_NOFOLLOW", 0)
    fd = os.open(lock, flags, 0o600)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | (0 if wait else fcntl.LOCK_NB))
        yield
    finally:
        os.close(fd)


@contextlib.contextmanager
def _folder_locked(out: Path) -> Iterator[None]:
    """Hold an exclusive lock on the folder ``out`` itself while moving files in."""
    fd = os.open(out, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)
