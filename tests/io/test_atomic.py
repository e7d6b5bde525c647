"""Atomic writes: the old file whole or the new one whole, never half."""

from __future__ import annotations

from pathlib import Path

import pytest

from skyquill.io.atomic import atomic_path, write_json, write_text


def test_a_failed_write_leaves_the_old_file(tmp_path: Path) -> None:
    target = tmp_path / "summary.json"
    write_json(target, {"run": 1})
    with pytest.raises(RuntimeError), atomic_path(target) as tmp:
        tmp.write_text("half")
        raise RuntimeError("interrupted")
    assert target.read_text() == '{\n  "run": 1\n}\n'
    assert [p.name for p in tmp_path.iterdir()] == ["summary.json"]  # no temporary left


def test_the_temporary_keeps_the_suffix_and_nan_is_refused(tmp_path: Path) -> None:
    with atomic_path(tmp_path / "plot.png") as tmp:
        assert tmp.suffix == ".png" and tmp.parent == tmp_path
        tmp.write_bytes(b"x")
    assert (tmp_path / "plot.png").read_bytes() == b"x"
    write_text(tmp_path / "a.txt", "é")
    assert (tmp_path / "a.txt").read_text(encoding="utf-8") == "é"
    with pytest.raises(ValueError):
        write_json(tmp_path / "n.json", {"x": float("nan")})


def test_files_get_the_mode_the_users_umask_gives(tmp_path: Path) -> None:
    """Not the 0600 of a temporary file: a plan is shared like any other file."""
    import os
    import stat

    from skyquill.io import atomic

    path = tmp_path / "summary.json"
    atomic.write_json(path, {"a": 1})
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~atomic._UMASK
    assert stat.S_IMODE(path.stat().st_mode) != 0o600 or atomic._UMASK == 0o066
    assert os.umask(atomic._UMASK) == atomic._UMASK  # read back, left as it was
