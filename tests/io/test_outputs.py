"""Staged outputs: files moved in whole, nobody else's file replaced, inputs never written over."""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
import shutil
import stat
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.io import outputs
from skyquill.io.outputs import MANIFEST, STAGING_PREFIX, shown_path, staged_output


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
    assert {name: r["command"] for name, r in owners.items()} == {
        "trajectory.csv": "fit",
        "summary.json": "fit",
    }
    digest = hashlib.sha256(b"a").hexdigest()
    assert owners["trajectory.csv"]["sha256"] == digest
    assert owners["trajectory.csv"]["inode"] == (tmp_path / "o" / "trajectory.csv").stat().st_ino


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


def _manifest(out: Path, files: object) -> None:
    out.mkdir(parents=True, exist_ok=True)
    (out / MANIFEST).write_text(json.dumps({"files": files}))


def _tree(root: Path) -> dict[str, bytes]:
    """Every file under ``root`` (links as their target's name) and its bytes."""
    seen = {}
    for path in sorted(root.rglob("*")):
        if path.is_symlink():
            seen[str(path.relative_to(root))] = os.readlink(path).encode()
        elif path.is_file():
            seen[str(path.relative_to(root))] = path.read_bytes()
    return seen


def _crafted(victim: Path, notes: Path) -> list[object]:
    """Manifests a plan folder received from someone else might hold."""
    real = hashlib.sha256(notes.read_bytes()).hexdigest()
    entry = {"command": "fit", "sha256": real, "inode": notes.stat().st_ino}
    return [
        {"../../victim/victim.txt": "fit", "notes.txt": "fit"},  # the old format
        {"../../victim/victim.txt": entry, "notes.txt": dict(entry, inode=0)},
        {str(victim): entry, "notes.txt": dict(entry, sha256="0" * 64)},
        {"./notes.txt": entry, "sub/../notes.txt": entry, "..": entry, "": entry},
        {"link.txt": entry, "notes.txt": {"command": "fit"}},
        [["notes.txt", "fit"]],
        "notes.txt",
    ]


def test_a_crafted_manifest_touches_nothing_outside_out_and_no_user_file(tmp_path: Path) -> None:
    """Whatever the manifest says, only the command's own, unchanged files are acted on."""
    victim = tmp_path / "victim" / "victim.txt"
    victim.parent.mkdir()
    victim.write_text("outside --out")
    for k in range(len(_crafted(victim, victim))):
        out = tmp_path / "a" / "b" / f"out{k}"
        out.mkdir(parents=True)
        notes = out / "notes.txt"
        notes.write_text("the user's own notes")
        (out / "link.txt").symlink_to(victim)
        _manifest(out, _crafted(victim, notes)[k])
        _run(out, "fit", {"trajectory.csv": "t", "summary.json": "{}"})
        assert victim.read_text() == "outside --out"
        assert notes.read_text() == "the user's own notes"
        assert os.readlink(out / "link.txt") == str(victim)


def test_a_file_changed_since_it_was_written_is_the_users(tmp_path: Path) -> None:
    out = tmp_path / "o"
    _run(out, "write", {"trajectory_0.csv": "a", "trajectory_1.csv": "b", "summary.json": "2"})
    (out / "trajectory_1.csv").write_text("edited by hand")
    _run(out, "write", {"trajectory.csv": "c", "summary.json": "1"})
    assert (out / "trajectory_1.csv").read_text() == "edited by hand"  # not dropped as stale
    assert not (out / "trajectory_0.csv").exists()
    (out / "trajectory.csv").write_text("edited")
    with pytest.raises(InputError, match="was changed since skyquill write wrote it"):
        _run(out, "write", {"trajectory.csv": "d"})


def test_a_copied_plan_folder_is_another_programs(tmp_path: Path) -> None:
    """New inodes: the records do not hold for the copy, so nothing is replaced unasked."""
    _run(tmp_path / "o", "fit", {"trajectory.csv": "a", "summary.json": "{}"})
    copy = tmp_path / "copy"
    copy.mkdir()
    for path in (tmp_path / "o").iterdir():
        (copy / path.name).write_bytes(path.read_bytes())
    with pytest.raises(InputError, match=r"trajectory.csv' exists and .*--force to replace it"):
        _run(copy, "fit", {"trajectory.csv": "b", "summary.json": "{}"})


def test_a_link_in_out_is_replaced_never_followed(tmp_path: Path) -> None:
    victim = tmp_path / "victim.txt"
    victim.write_text("keep")
    out = tmp_path / "o"
    out.mkdir()
    (out / "trajectory.csv").symlink_to(victim)
    with pytest.raises(InputError, match="written by another program"):
        _run(out, "fit", {"trajectory.csv": "new"})
    _run(out, "fit", {"trajectory.csv": "new"}, force=True)
    assert victim.read_text() == "keep"
    assert not (out / "trajectory.csv").is_symlink()
    assert (out / "trajectory.csv").read_text() == "new"


_names = st.one_of(
    st.sampled_from(["notes.txt", "../victim.txt", "../../victim.txt", ".", "..", "", "/", "link"]),
    st.text(alphabet="./\\abn\x00", max_size=12),
)
_entries = st.one_of(
    st.sampled_from(["fit", None, 1, [], {}]),
    st.fixed_dictionaries(
        {"command": st.sampled_from(["fit", "fly"]), "sha256": st.text(max_size=64)},
        optional={"inode": st.integers(min_value=-1, max_value=2**62)},
    ),
)


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(files=st.dictionaries(_names, _entries, max_size=6))
def test_any_manifest_leaves_other_files_alone(tmp_path: Path, files: dict[str, object]) -> None:
    root = tmp_path / "case"
    shutil.rmtree(root, ignore_errors=True)
    (root / "out").mkdir(parents=True)
    (root / "victim.txt").write_text("outside")
    (root / "out" / "notes.txt").write_text("mine")
    (root / "out" / "link").symlink_to(root / "victim.txt")
    _manifest(root / "out", files)
    before = {k: v for k, v in _tree(root).items() if MANIFEST not in k}
    _run(root / "out", "fit", {"trajectory.csv": "t"})
    after = _tree(root)
    assert all(after.get(k) == v for k, v in before.items() if k != "out/trajectory.csv")


def test_a_killed_runs_staging_folder_is_cleared_by_the_next_run(tmp_path: Path) -> None:
    out = tmp_path / "o"
    out.mkdir()
    code = (
        "import os, sys; from pathlib import Path; from skyquill.io.outputs import staged_output\n"
        "with staged_output(Path(sys.argv[1]), 'fit') as stage:\n"
        "    (stage / 'trajectory.csv').write_text('half')\n"
        "    os._exit(9)\n"
    )
    done = subprocess.run([sys.executable, "-c", code, str(out)], check=False, timeout=60)
    assert done.returncode == 9
    assert [p.name for p in out.iterdir() if p.name.startswith(STAGING_PREFIX)]
    _run(out, "fit", {"trajectory.csv": "whole"})
    assert not [p.name for p in out.iterdir() if p.name.startswith(STAGING_PREFIX)]
    assert (out / "trajectory.csv").read_text() == "whole"


def test_a_live_runs_staging_folder_is_left_alone(tmp_path: Path) -> None:
    out = tmp_path / "o"
    with staged_output(out, "fit") as stage:
        _run(out, "fly", {"flight.csv": "f"})
        assert stage.is_dir()
        (stage / "trajectory.csv").write_text("t")
    assert (out / "trajectory.csv").read_text() == "t"


def test_a_run_whose_new_folder_another_cleanup_took_stages_in_another(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The race two runs into one folder hit (a CI run of session 41): a run has created its
    # staging folder's lock file but not locked it yet when the other run's cleanup takes
    # the folder for a dead run's and removes it; the run wrote into a folder that was gone.
    # Played here in order: the cleanup runs right before the run's first lock.
    out = tmp_path / "o"
    out.mkdir()
    taken: list[Path] = []

    class CleanupFirst:
        LOCK_EX, LOCK_NB = fcntl.LOCK_EX, fcntl.LOCK_NB

        @staticmethod
        def flock(fd: int, operation: int) -> None:
            is_file = stat.S_ISREG(os.fstat(fd).st_mode)  # (not the folder's own lock)
            if not taken and is_file and not operation & fcntl.LOCK_NB:
                taken.extend(p for p in out.iterdir() if p.name.startswith(STAGING_PREFIX))
                outputs._clear_leftovers(out)
            fcntl.flock(fd, operation)

    monkeypatch.setattr(outputs, "fcntl", CleanupFirst)
    with staged_output(out, "fit") as stage:
        assert stage.is_dir() and stage not in taken
        (stage / "trajectory.csv").write_text("whole")
    assert len(taken) == 1 and not taken[0].exists()
    assert (out / "trajectory.csv").read_text() == "whole"
    assert not [p.name for p in out.iterdir() if p.name.startswith(STAGING_PREFIX)]


def test_staging_paths_are_shown_as_the_out_folders() -> None:
    assert shown_path(f"/o/{STAGING_PREFIX}ab12_x/plot.png") == "/o/plot.png"
