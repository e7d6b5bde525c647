"""Staged outputs: files moved in whole, nobody else's file replaced, inputs never written over."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from skyquill.errors import InputError
from skyquill.io.outputs import MANIFEST, staged_output


def _run(out: Path, command: str, files: dict[str, str], **kwargs: object) -> None:
    with staged_output(out, command, **kwargs) as stage:  # type: ignore[arg-type]
        for name, text in files.items():
            (stage / name).write_text(text)


def test_files_move_in_and_the_manifest_records_who_wrote_them(tmp_path: Path) -> None:
    _run(tmp_path / "o", "fit", {"trajectory.csv": "a", "summary.json": "{}"})
    assert sorted(p.name for p in (tmp_path / "o").iterdir()) == [
        MANIFEST, "summary.json", "trajectory.csv"
    ]  # fmt: skip
    owners = json.loads((tmp_path / "o" / MANIFEST).read_text())["files"]
    assert owners == {"trajectory.csv": "fit", "summary.json": "fit"}


def test_the_same_command_replaces_its_own_files_and_drops_stale_ones(tmp_path: Path) -> None:
    out = tmp_path / "o"
    _run(out, "write", {"trajectory_0.csv": "a", "trajectory_1.csv": "b", "summary.json": "2"})
    _run(out, "write", {"trajectory.csv": "c", "summary.json": "1"})
    assert sorted(p.name for p in out.iterdir() if p.name != MANIFEST) == [
        "summary.json", "trajectory.csv"
    ]  # fmt: skip
    assert (out / "summary.json").read_text() == "1"


def test_another_commands_or_programs_file_is_not_replaced(tmp_path: Path) -> None:
    out = tmp_path / "o"
    _run(out, "fit", {"summary.json": "plan", "plot.png": "p"})
    refused = r"(summary|plot)\.\w+' exists and was written by skyquill fit"
    with pytest.raises(InputError, match=refused):
        _run(out, "fly", {"flight.csv": "f", "summary.json": "flight", "plot.png": "q"})
    assert (out / "summary.json").read_text() == "plan" and not (out / "flight.csv").exists()
    (out / "notes.txt").write_text("mine")
    with pytest.raises(InputError, match="written by another program"):
        _run(out, "fit", {"notes.txt": "x"})
    _run(out, "fit", {"notes.txt": "x"}, force=True)
    assert (out / "notes.txt").read_text() == "x"


def test_inputs_are_never_written_over_and_failures_leave_the_folder(tmp_path: Path) -> None:
    out = tmp_path / "o"
    _run(out, "export", {"a.json": "1"})
    with pytest.raises(InputError, match="one of this command's inputs"):
        _run(out, "export", {"a.json": "2"}, inputs=[out / "a.json"], force=True)
    with pytest.raises(RuntimeError), staged_output(out, "export") as stage:
        (stage / "a.json").write_text("half")
        raise RuntimeError("interrupted")
    assert (out / "a.json").read_text() == "1"
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "a.json"]  # no staging left


def test_an_existing_file_is_not_a_folder(tmp_path: Path) -> None:
    (tmp_path / "f").write_text("x")
    with pytest.raises(InputError, match="an existing file; expected a folder"):
        _run(tmp_path / "f", "fit", {})
