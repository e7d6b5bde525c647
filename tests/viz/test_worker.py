"""The picture worker (viz.worker): the same PNG as drawn here, failures reported, not fatal."""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from skyquill.cli.entry import _will_draw
from skyquill.cli.pictures import Pictures
from skyquill.viz import worker as worker_module
from skyquill.viz.sampled import FlightSamples
from skyquill.viz.worker import Drawing, PictureWorker, WorkerError, a_core_is_free

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _flight() -> Drawing:
    """A small synthetic flight's figure (numbers only: no plan to make)."""
    t = np.linspace(0.0, 4.0, 400)
    p_ref = np.column_stack([np.cos(t), np.sin(t), 1.0 + 0.1 * t])
    p = p_ref + 1e-3 * np.column_stack([np.sin(7 * t), np.cos(5 * t), np.zeros_like(t)])
    error = np.linalg.norm(p - p_ref, axis=1)
    samples = FlightSamples(
        t, p_ref, p, (p[:50],), error, float(np.sqrt(np.mean(error**2))), float(error.max()), 0,
        "test  se3 on skyquill",
    )  # fmt: skip
    return Drawing("skyquill.viz.flight_plot", "draw_flight", samples)


@pytest.fixture(scope="module")
def worker() -> Iterator[PictureWorker]:
    started = PictureWorker()
    yield started
    started.close()


@pytest.mark.timeout(120)
def test_the_worker_draws_the_same_png_as_this_process(
    worker: PictureWorker, tmp_path: Path
) -> None:
    _flight().draw(tmp_path / "here.png")
    worker.draw(_flight(), tmp_path / "there.png")
    assert (tmp_path / "there.png").read_bytes() == (tmp_path / "here.png").read_bytes()
    # The command's wait for a core until it asked for the drawing: never negative.
    assert worker.contention_s is not None and 0.0 <= worker.contention_s < 60.0


@pytest.mark.timeout(120)
def test_a_drawing_that_raises_is_reported_and_the_worker_goes_on(
    worker: PictureWorker, tmp_path: Path
) -> None:
    with pytest.raises(WorkerError, match="AttributeError: 'NoneType'"):
        worker.draw(Drawing("skyquill.viz.flight_plot", "draw_flight", None), tmp_path / "x.png")
    worker.draw(_flight(), tmp_path / "after.png")
    assert (tmp_path / "after.png").stat().st_size > 0


@pytest.mark.timeout(120)
def test_a_dead_worker_is_drawn_around_and_said(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    dead = PictureWorker()
    dead._process.kill()  # as the kernel would, out of memory
    dead._process.join()
    worker_module._PRESTARTED.append(dead)
    pictures = Pictures(True)
    with pictures.timing("plot.png"):
        pictures.draw(_flight(), tmp_path / "plot.png")
    entry = pictures.entry
    assert (tmp_path / "plot.png").stat().st_size > 0  # drawn here instead
    assert entry["process"] == "command" and "ended" in entry["worker_error"]
    assert entry["files"] == ["plot.png"] and entry["time_s"] >= dead.start_s
    assert "picture worker failed" in capsys.readouterr().err


@pytest.mark.timeout(60)
def test_no_pictures_closes_a_started_worker() -> None:
    started = PictureWorker()
    worker_module._PRESTARTED.append(started)
    assert Pictures(False).entry == {"drawn": False, "files": [], "time_s": 0.0}
    assert started._process.exitcode is not None  # ended, not left running
    assert worker_module.take() is None


def test_no_worker_when_no_process_can_start(monkeypatch: pytest.MonkeyPatch) -> None:
    def refused() -> PictureWorker:
        raise OSError(11, "Resource temporarily unavailable")

    monkeypatch.setattr(worker_module, "a_core_is_free", lambda: True)
    monkeypatch.setattr(worker_module, "PictureWorker", refused)
    worker_module.prestart()
    assert worker_module.take() is None  # the command draws itself


def test_only_drawing_commands_start_it() -> None:
    assert _will_draw(["fit", "a.csv", "--out", "o"])
    assert _will_draw(["write", "Hi", "--out", "o"])
    assert not _will_draw(["fit", "a.csv", "--out", "o", "--no-pictures"])
    assert not _will_draw(["fly", "--help"])
    assert _will_draw(["cover", "field.geojson", "--out", "o"])
    assert not _will_draw(["show", "show.toml", "--out", "o"])
    assert not _will_draw([])
    assert isinstance(a_core_is_free(), bool)


@pytest.mark.timeout(180)
@pytest.mark.parametrize(
    "command",
    [("fit", "spiral.csv"), ("cover", "coverage/l_field.geojson")],
    ids=lambda command: command[0],
)
def test_the_console_script_draws_in_the_worker(tmp_path: Path, command: tuple[str, str]) -> None:
    """As a user runs it (a core taken as free: the machine running the tests may be busy)."""
    script = (
        "import atexit, sys; import skyquill.viz.worker as w; w.a_core_is_free = lambda: True; "
        "atexit.register(lambda: print('matplotlib here:', 'matplotlib' in sys.modules)); "
        "from skyquill.cli.entry import run; run()"
    )
    out = tmp_path / "o"
    done = subprocess.run(
        [sys.executable, "-c", script, command[0], str(EXAMPLES / command[1]), "--out", str(out)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    pictures = json.loads((out / "summary.json").read_text())["pictures"]
    assert pictures["process"] == "worker" and "worker_error" not in pictures
    assert pictures["files"] == ["plot.png"] and (out / "plot.png").stat().st_size > 0
    assert pictures["time_s"] >= pictures["contention_s"] >= 0.0
    assert "matplotlib here: False" in done.stdout  # imported by the worker alone


#: Ctrl+C held (as the console script holds it while the program loads) and sent just
#: after the worker's process is forked, before it is given its work: the moment
#: multiprocessing's resource tracker, started with the first process, had unblocked it.
CTRL_C_AS_THE_WORKER_STARTS = """
import os, signal, sys
from multiprocessing import util
signal.signal(signal.SIGINT, signal.default_int_handler)
spawn = util.spawnv_passfds

def spawn_then_ctrl_c(path, args, passfds):
    pid = spawn(path, args, passfds)
    if any("spawn_main" in str(arg) for arg in args):  # the worker, not the tracker
        os.kill(os.getpid(), signal.SIGINT)
    return pid

util.spawnv_passfds = spawn_then_ctrl_c
from skyquill.cli.entry import _ctrl_c_held
from skyquill.viz.worker import PictureWorker
try:
    with _ctrl_c_held():
        PictureWorker()
        sys.stdout.write("started\\n")
except KeyboardInterrupt:
    sys.exit(130)
"""


@pytest.mark.timeout(120)
def test_ctrl_c_while_the_worker_starts_comes_after_its_start() -> None:
    """The Ctrl+C was raised between the worker's fork and its work: the worker, given
    nothing, printed ``EOFError: Ran out of input`` under the command's one line."""
    done = subprocess.run(
        [sys.executable, "-c", CTRL_C_AS_THE_WORKER_STARTS],
        capture_output=True,
        text=True,
        timeout=110,
        check=False,
    )
    assert done.returncode == 130, done.stderr
    assert done.stdout == "started\n"
    assert done.stderr == ""


def test_the_samples_unpickle_without_matplotlib_or_the_core() -> None:
    """What the worker imports to read the samples: numpy, not the planner (0.5 s more)."""
    probe = (
        "import sys, skyquill.viz.sampled; "
        "print(sorted(m for m in sys.modules if m.startswith(('matplotlib', 'scipy', "
        "'skyquill.limits', 'skyquill.optimize'))))"
    )
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"
