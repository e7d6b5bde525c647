"""The picture worker: a second process that imports matplotlib while the command plans.

Run from a shell, ``skyquill fit`` (or ``fly``, ``write``, ``cover``) spends about a second
importing skyquill and a fraction of one planning; its picture then costs matplotlib's
import (about 0.5 s of CPU, paid once per process) and the drawing (0.4-0.5 s). Both are
CPU work under the GIL: a thread would only take turns with the command. A process runs
on the machine's second core instead. The console script (:mod:`skyquill.cli.entry`)
starts one (:func:`prestart`) before it imports the program, when the command will draw;
the worker imports matplotlib and the drawing modules and draws a small figure to load
the fonts while the command imports and plans; the command then hands it the samples
(:mod:`skyquill.viz.sampled`, pickled) and waits for the PNG.

Only with a core free (:func:`a_core_is_free`): on a machine whose cores are all
busy the worker only takes turns with the command, and costs it more than drawing
in-process would (its interpreter's start, numpy's import again, the warm-up), measured
on the shared 2-core machine at load 3: ``fit``'s wall time 1.17x drawing in-process.

Started with ``spawn``: a fresh interpreter, nothing inherited (``fork`` would copy
BLAS's threads' locks and the command's status-line thread). It ignores Ctrl+C (the
command reports it) and ends when the command closes it or ends. POSIX only (signal
masks): elsewhere the command draws its pictures itself.

The command's picture time (``summary.json``'s ``pictures.time_s``) counts what the
pictures cost the command, as the outside view (the command with and without
``--no-pictures``, ``bench/pictures.py``) sees it: starting the worker, sending the
samples and waiting for the file, and what the worker's work took from the command
while both ran. On two free cores that is nothing; on a busy machine the command waits
for a core. :attr:`PictureWorker.contention_s` bounds that from above by all of the
command's wait for a core from the worker's start to its first drawing (Linux's
run-queue delay, ``/proc/self/schedstat``): on a busy machine part of it is other
programs', so it overstates there. Not the worker's CPU time: traced on the shared
2-core machine at load 3, the worker's 0.53 s of CPU cost the command 1.2 s more of
waiting for a core (the other programs kept their shares of the cores too). Without
``/proc`` it is the worker's CPU time, which can understate on a busy machine.
"""

from __future__ import annotations

import importlib
import os
import signal
import time
from contextlib import suppress
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from multiprocessing.connection import Connection

#: The modules that draw in the worker (imported there before any drawing is asked for).
DRAWING_MODULES = (
    "skyquill.viz.coverage_plot",
    "skyquill.viz.fit_plot",
    "skyquill.viz.flight_plot",
    "skyquill.viz.writing_plot",
)
#: Seconds to wait for a drawing before the worker is taken for dead.
DRAWING_TIMEOUT_S = 600.0


class WorkerError(RuntimeError):
    """The worker did not draw: it died, or its drawing raised (the message says which)."""


@dataclass(frozen=True)
class Drawing:
    """A picture to draw: ``module.function(samples, path)``.

    The function is named, not passed: importing its module imports matplotlib, which
    the command's process leaves to the worker.
    """

    module: str
    function: str
    samples: Any

    def draw(self, path: Path) -> None:
        """Draw it to ``path`` in this process."""
        getattr(importlib.import_module(self.module), self.function)(self.samples, path)


class PictureWorker:
    """A started worker process and the command's end of its pipe.

    Attributes
    ----------
    start_s
        Wall time the command spent starting it, s (importing :mod:`multiprocessing`
        included: it is imported here, for the pictures only).
    contention_s
        What the worker's work took from the command before its first drawing, s (see
        the module's text); ``None`` until then.
    """

    def __init__(self) -> None:
        clock = time.perf_counter()
        import multiprocessing  # a tenth of a second: counted in start_s
        from multiprocessing import resource_tracker

        self._queued_s = _run_queue_s()
        context = multiprocessing.get_context("spawn")
        self._connection, theirs = context.Pipe()
        self._process = context.Process(
            target=_serve, args=(theirs, DRAWING_MODULES), name="skyquill-pictures", daemon=True
        )
        # Ctrl+C reaches the worker too (one process group): blocked while it starts, the
        # signal stays blocked in it from its first instruction (the mask survives exec),
        # and is delivered here once the caller's mask is back, not lost. multiprocessing
        # starts its resource tracker with the first process and *unblocks* SIGINT after
        # it, whatever the mask was: a Ctrl+C then came in the middle of the worker's
        # start (the worker, given nothing, printed a traceback). So the tracker first
        # (a Ctrl+C held until then is raised there, before the worker exists), then the
        # mask again for the worker's start.
        caller = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        try:
            resource_tracker.ensure_running()
            signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
            self._process.start()
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, caller)
        theirs.close()
        self.start_s = time.perf_counter() - clock
        self.contention_s: float | None = None

    def draw(self, drawing: Drawing, path: Path) -> None:
        """Have the worker draw ``drawing`` to ``path``; return when the file is written.

        Raises
        ------
        WorkerError
            The worker died, or the drawing raised there (its type and message).
        """
        queued = _run_queue_s()
        try:
            self._connection.send((drawing, str(path)))
            if not self._connection.poll(DRAWING_TIMEOUT_S):
                raise WorkerError(f"no answer in {DRAWING_TIMEOUT_S:g} s")
            error, cpu_before_s = self._connection.recv()
        except (OSError, EOFError) as exc:  # the pipe broke: the worker is gone
            code = self._process.exitcode
            raise WorkerError(f"the picture worker ended (exit code {code}): {exc!r}") from exc
        if self.contention_s is None:
            if queued is None or self._queued_s is None:
                self.contention_s = cpu_before_s
            else:
                self.contention_s = queued - self._queued_s
        if error is not None:
            raise WorkerError(error)

    def close(self) -> None:
        """End the worker (it exits at once) and wait for it."""
        with suppress(OSError):  # gone already
            self._connection.send(None)
        self._connection.close()
        self._process.join(timeout=5.0)
        if self._process.is_alive():
            self._process.kill()
            self._process.join()


def _serve(connection: Connection, modules: tuple[str, ...]) -> None:
    """The worker: import ``modules``, warm up, then draw what comes until told to stop."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl+C is the command's to report
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})  # ignored now: no need
    for module in modules:
        importlib.import_module(module)
    _warm_up()
    while True:
        try:
            job = connection.recv()
        except (EOFError, OSError):  # the command is gone
            break
        if job is None:
            break
        cpu_before_s = time.process_time()  # all of it before the first drawing
        drawing, path = job
        try:
            drawing.draw(Path(path))
        except Exception as exc:  # reported to the command, which decides
            connection.send((f"{type(exc).__name__}: {exc}", cpu_before_s))
        else:
            connection.send((None, cpu_before_s))
    connection.close()
    # Nothing to flush or free: skip the interpreter's teardown of matplotlib's modules.
    os._exit(0)


def _warm_up() -> None:
    """Draw a small figure with text: the first drawing loads the fonts and their caches."""
    from io import BytesIO

    from skyquill.viz.figures import new_figure

    fig = new_figure((2.0, 1.5))
    ax = fig.add_axes((0.25, 0.25, 0.7, 0.6))
    ax.plot([0.0, 1.0], [0.0, 1.0], label="warm")
    ax.set(xlabel="t [s]", ylabel="x [m]", title="warm-up")
    ax.legend(fontsize=8)
    fig.suptitle("warm-up")
    fig.savefig(BytesIO(), format="png", dpi=50)


def _run_queue_s() -> float | None:
    """Time this process's main thread has waited for a core, s (Linux); ``None`` elsewhere."""
    try:
        with open("/proc/self/schedstat", encoding="ascii") as stats:
            return int(stats.read().split()[1]) * 1e-9
    except (OSError, IndexError, ValueError):
        return None


#: The worker :func:`prestart` started, until :func:`take` hands it over.
_PRESTARTED: list[PictureWorker] = []


def a_core_is_free() -> bool:
    """Whether fewer programs are running right now than this process may use cores.

    Linux's instantaneous count of running tasks (``/proc/loadavg``, this process
    included); elsewhere, whether there is more than one core.
    """
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    try:
        with open("/proc/loadavg", encoding="ascii") as load:
            running = int(load.read().split()[3].split("/")[0])
    except (OSError, IndexError, ValueError):
        return (cores or 1) > 1
    return running < (cores or 1)


def prestart() -> None:
    """Start the worker now, for the command about to run, if a core is free for it
    (:func:`take` hands it over).

    Without POSIX signal masks, or when no process can be started (the system's
    limits), there is none: the command draws its pictures itself, as it would anyway.
    """
    if _PRESTARTED or not hasattr(signal, "pthread_sigmask") or not a_core_is_free():
        return
    try:
        _PRESTARTED.append(PictureWorker())
    except OSError:
        return


def take() -> PictureWorker | None:
    """The worker :func:`prestart` started, if any (handed over once)."""
    return _PRESTARTED.pop() if _PRESTARTED else None
