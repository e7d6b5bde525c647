"""The command line's outer edge (issue 25): what a row of the hostile table cannot express.

Ctrl+C at any moment, warnings and finalizer noise, operating-system errors naming the file
the user knows, a crafted manifest in --out, two runs into one folder at once, check's
drone ceiling.
"""

from __future__ import annotations

import errno
import hashlib
import json
import os
import signal
import subprocess
import sys
import time
import warnings
from collections.abc import Callable
from pathlib import Path

import pytest
from typer._click.core import Command
from typer.testing import CliRunner

from skyquill.cli import check_cmd, fit_cmd
from skyquill.cli.boundary import as_options, os_error_line
from skyquill.cli.main import app
from skyquill.errors import InputError
from skyquill.io.outputs import MANIFEST

runner = CliRunner()
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SPIRAL = str(EXAMPLES / "spiral.csv")
TRAJ = "t,x,y,z,vx,vy,vz,ax,ay,az\n0,0,0,1,0,0,0,0,0,0\n1,0.5,0,1,0,0,0,0,0,0\n"


def _one_line(text: str) -> str:
    lines = [line for line in text.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), text
    return lines[0]


def _ctrl_c() -> None:
    raise KeyboardInterrupt


def _ctrl_c_in_a_compiled_module_s_start() -> None:
    """What a pybind11 module's import raises when Ctrl+C lands in its initialisation."""
    try:
        raise KeyboardInterrupt
    except KeyboardInterrupt as exc:
        raise ImportError("initialization failed") from exc


@pytest.mark.parametrize(
    ("owner", "name", "raised"),
    [
        (fit_cmd, "read_points_csv", _ctrl_c),  # inside the command
        # While the options are read: typer itself turned this moment (it imports pydantic
        # then) into a silent status 130.
        (Command, "parse_args", _ctrl_c),
        # A compiled module imported inside the command (matplotlib, for a picture drawn
        # in the command's process), whose failed start said "internal error ... a bug in
        # skyquill" with exit status 1.
        (fit_cmd, "read_points_csv", _ctrl_c_in_a_compiled_module_s_start),
    ],
    ids=["inside a command", "while the options are read", "in a compiled module's start"],
)
def test_ctrl_c_is_one_line_and_130(
    monkeypatch: pytest.MonkeyPatch, owner: object, name: str, raised: Callable[[], None]
) -> None:
    def interrupted(*_: object) -> None:
        raised()

    monkeypatch.setattr(owner, name, interrupted)
    result = runner.invoke(app, ["fit", SPIRAL, "--out", "unused"])
    assert result.exit_code == 130
    assert "interrupted by Ctrl+C" in _one_line(result.output)


@pytest.mark.timeout(120)
def test_ctrl_c_while_the_program_starts_is_one_line_and_130(tmp_path: Path) -> None:
    """Issue 25: Ctrl+C in the first 0.6 s (the imports) printed a traceback.

    The child says when it has imported the console script's entry module, just before
    ``run()`` imports the program; the signal then lands in those imports (they take most
    of a second), whatever the load (a delay from the child's start did not: under load a
    ``fit`` ended before it).
    """
    # As the console script starts from a shell: Ctrl+C raises KeyboardInterrupt (a
    # pytest-xdist worker ignores SIGINT, and its children inherit that: the signal was
    # lost and the fit finished), the small entry module imported, then run().
    start = (
        "import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
        "from skyquill.cli.entry import run; sys.stderr.write('started\\n'); "
    )
    child = subprocess.Popen(
        [sys.executable, "-c", start + "sys.stderr.flush(); run()", "fit",
         SPIRAL, "--out", str(tmp_path / "o")],
        stderr=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
    )  # fmt: skip
    assert child.stderr is not None
    assert child.stderr.readline() == b"started\n"
    time.sleep(0.2)  # past the few instructions before run(); its imports take over 0.5 s
    child.send_signal(signal.SIGINT)
    _, err = child.communicate(timeout=110)
    text = err.decode()
    assert child.returncode == 130, text
    assert "Traceback" not in text and "interrupted by Ctrl+C" in _one_line(text)


#: A child that imports the program as the console script does, through a module whose
#: start is hit by Ctrl+C and swallows it, as piqp's loader does: the signal is sent from
#: inside the import of the program, then a "compiled module's start" runs.
SWALLOWED_AT_START = """
import os, signal, sys, time
signal.signal(signal.SIGINT, signal.default_int_handler)

class Swallowing:
    def find_spec(self, name, path=None, target=None):
        if name == "skyquill.cli.main":
            try:
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.5)
            except KeyboardInterrupt:
                sys.stderr.write("swallowed\\n")
        return None

sys.meta_path.insert(0, Swallowing())
from skyquill.cli.entry import run
run()
"""


@pytest.mark.timeout(120)
def test_ctrl_c_inside_a_compiled_module_s_start_is_raised_after_the_imports() -> None:
    """Ctrl+C in piqp's or ruckig's initialisation failed it (``ImportError:
    initialization failed``, a traceback), crashed the interpreter (-11), or was swallowed
    by piqp's loader and the command ran to its end (3 of 200 runs): held while the program
    is imported, it is raised after, in the program's own code."""
    child = subprocess.run(
        [sys.executable, "-c", SWALLOWED_AT_START, "--version"],
        capture_output=True,
        timeout=110,
        check=False,
    )
    text = child.stderr.decode()
    assert child.returncode == 130, text
    assert "swallowed" not in text
    assert "Traceback" not in text and "interrupted by Ctrl+C" in _one_line(text)


def test_warnings_before_an_error_are_not_printed(monkeypatch: pytest.MonkeyPatch) -> None:
    """Issue 25: scipy and shapely warnings came on stderr before the error line."""

    def noisy(*_: object) -> None:
        warnings.warn("invalid value encountered in divide", RuntimeWarning, stacklevel=1)
        raise InputError("points: got nothing, expected points")

    monkeypatch.setattr(fit_cmd, "read_points_csv", noisy)
    result = runner.invoke(app, ["fit", SPIRAL, "--out", "unused"])
    assert result.exit_code == 2
    assert "points: got nothing" in _one_line(result.output)


def test_os_errors_name_the_file_in_out_not_the_staging_folder() -> None:
    exc = OSError(errno.ENOSPC, "No space left on device", "/o/.staging-x1y2/plot.png")
    assert os_error_line(exc) == (
        "/o/plot.png: got 'No space left on device' from the operating system, expected free "
        "space on its disk"
    )
    assert "expected a shorter name" in os_error_line(
        OSError(errno.ENAMETOOLONG, "File name too long", "x" * 300)
    )


def test_core_argument_names_are_shown_as_the_options_typed() -> None:
    assert as_options("size_m: got 1e-06 m") == "--size: got 1e-06 m"
    assert as_options("tolerance_m: a shorter knot_interval or best_effort") == (
        "--tolerance: a shorter --knot-interval or --best-effort"
    )
    assert as_options("spiral.csv line 3: weight") == "spiral.csv line 3: weight"


def test_a_crafted_manifest_in_out_touches_nothing_outside_or_the_users(tmp_path: Path) -> None:
    """Issue 25: fit deleted ../../../victim/victim.txt and the user's notes.txt."""
    victim = tmp_path / "victim" / "victim.txt"
    victim.parent.mkdir()
    victim.write_text("outside")
    out = tmp_path / "a" / "b" / "out"
    out.mkdir(parents=True)
    (out / "notes.txt").write_text("mine")
    digest = hashlib.sha256(b"mine").hexdigest()
    files = {
        "../../../victim/victim.txt": "fit",
        str(victim): {"command": "fit", "sha256": digest, "inode": victim.stat().st_ino},
        "notes.txt": {"command": "fit", "sha256": "0" * 64, "inode": 1},
        "plot.png": "fit",
    }
    (out / MANIFEST).write_text(json.dumps({"files": files}))
    result = runner.invoke(app, ["fit", SPIRAL, "--out", str(out), "--rate", "20"])
    assert result.exit_code == 0, result.output
    assert victim.read_text() == "outside" and (out / "notes.txt").read_text() == "mine"
    written = json.loads((out / MANIFEST).read_text())["files"]
    assert "notes.txt" not in written and not any("/" in name for name in written)


@pytest.mark.timeout(300)
def test_two_runs_into_one_folder_each_end_whole(tmp_path: Path) -> None:
    code = (
        "import sys; from pathlib import Path; from skyquill.io.outputs import staged_output\n"
        "for k in range(15):\n"
        "    with staged_output(Path(sys.argv[1]), 'fit') as stage:\n"
        "        (stage / 'trajectory.csv').write_text(sys.argv[2] * 100_000)\n"
        "        (stage / 'summary.json').write_text('{}')\n"
    )
    out = tmp_path / "o"
    out.mkdir()
    runs = [subprocess.Popen([sys.executable, "-c", code, str(out), mark]) for mark in ("a", "b")]
    assert [r.wait(timeout=280) for r in runs] == [0, 0]
    text = (out / "trajectory.csv").read_text()
    assert text in ("a" * 100_000, "b" * 100_000)
    assert set(json.loads((out / MANIFEST).read_text())["files"]) == {
        "trajectory.csv",
        "summary.json",
    }
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "summary.json", "trajectory.csv"]


def test_check_refuses_more_drones_than_its_ceiling(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    for k in range(3):
        (tmp_path / f"d{k}.csv").write_text(TRAJ.replace("0,0,1,", f"{5 * k},0,1,"))
    monkeypatch.setattr(check_cmd, "MAX_DRONES", 2)
    result = runner.invoke(app, ["check", *(str(tmp_path / f"d{k}.csv") for k in range(3))])
    assert result.exit_code == 2
    assert "PATH: got 3 drones, expected at most 2" in _one_line(result.output)


def test_outputs_get_the_mode_the_umask_gives(tmp_path: Path) -> None:
    previous = os.umask(0o027)
    os.umask(previous)
    result = runner.invoke(app, ["fit", SPIRAL, "--out", str(tmp_path / "o"), "--rate", "20"])
    assert result.exit_code == 0, result.output
    from skyquill.io import atomic

    mode = (tmp_path / "o" / "summary.json").stat().st_mode & 0o777
    assert mode == 0o666 & ~atomic._UMASK


def test_a_skyc_of_too_many_drones_is_refused_before_it_is_played_back(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Counted from show.json: playing 2,000 drones back took most of 20 minutes."""
    import numpy as np

    from skyquill.export.skybrush import playback
    from skyquill.export.skybrush.keyframes import skybrush_keyframes
    from skyquill.export.skybrush.skyc_file import SkycDrone, write_skyc
    from skyquill.trajectory import SplineTrajectory

    ctrl = np.column_stack([np.linspace(0.0, 2.0, 8), np.zeros(8), np.ones(8)])
    paths = [SplineTrajectory(ctrl + np.array([5.0 * k, 0, 0]), 5, 4.0) for k in range(3)]
    drones = [SkycDrone(f"d{k}", skybrush_keyframes(p)) for k, p in enumerate(paths)]
    write_skyc(drones, tmp_path / "s.skyc")

    def never(*_: object) -> None:
        raise AssertionError("played back")

    monkeypatch.setattr(playback, "played_trajectory", never)
    monkeypatch.setattr(check_cmd, "MAX_DRONES", 2)
    result = runner.invoke(app, ["check", str(tmp_path / "s.skyc")])
    assert result.exit_code == 2
    assert "PATH: got s.skyc of 3 drones, expected at most 2" in _one_line(result.output)
