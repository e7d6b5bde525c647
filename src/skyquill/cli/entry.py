"""The ``skyquill`` console script: the app, with Ctrl+C covered from the first instant.

Importing the app takes most of a second (numpy, scipy, rich, typer). Ctrl+C in
that time would print a ``KeyboardInterrupt`` traceback, since the app's own
boundary (:class:`~skyquill.cli.boundary.OneLineGroup`) does not exist yet; this
module imports nothing heavy itself, so that it can say one line instead.

It is also the first moment a command that will draw its ``plot.png`` can start the
picture worker (:mod:`skyquill.viz.worker`): the worker imports matplotlib on the
other core while this process imports the program and plans.

Ctrl+C is held (blocked) while the program is imported and raised once it is: a
``KeyboardInterrupt`` raised inside a compiled module's initialisation (piqp's,
ruckig's) fails it with ``ImportError: initialization failed`` (a traceback, exit
status 1), crashes the interpreter (exit status -11), or is swallowed by piqp's
loader, which then loads another build of the module and the command runs to its
end: 3 of 200 runs with the signal sent 0.6-1.1 s after the start did one of these.
"""

from __future__ import annotations

import signal
import sys
from collections.abc import Iterator
from contextlib import contextmanager

#: Exit status of an interrupted command (128 + SIGINT); the same as the app's.
INTERRUPTED = 130
#: The commands whose ``plot.png`` the picture worker draws (``--no-pictures`` skips it).
DRAWN_BY_THE_WORKER = ("cover", "fit", "fly", "write")


def run() -> None:
    """Import and run the app; one line and exit status 130 on Ctrl+C, whenever it comes."""
    try:
        with _ctrl_c_held():
            if _will_draw(sys.argv[1:]):
                from skyquill.viz.worker import prestart

                prestart()
            from skyquill.cli.main import app
        app(prog_name="skyquill")
    except KeyboardInterrupt:
        sys.stderr.write("error: interrupted by Ctrl+C before anything was written\n")
        sys.exit(INTERRUPTED)


def _will_draw(args: list[str]) -> bool:
    """Whether the command line ``args`` runs a command that draws in the picture worker.

    Read before the program is imported, so from the words alone: the command first,
    no ``--no-pictures`` nor help. A wrong guess costs a worker started for nothing (a
    few milliseconds here) or a picture drawn in this process.
    """
    return (
        bool(args)
        and args[0] in DRAWN_BY_THE_WORKER
        and not {"--no-pictures", "--help"} & set(args)
    )


@contextmanager
def _ctrl_c_held() -> Iterator[None]:
    """Hold Ctrl+C (SIGINT blocked in this thread) inside the block; one that came in it
    is raised as the block ends, as ``KeyboardInterrupt``.

    Threads started inside the block (numpy's BLAS pool) keep it blocked: the signal
    is then always delivered to this thread. Without POSIX signal masks (Windows) the
    block runs as it is.
    """
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        # A pending Ctrl+C is delivered here, and raised at the next instruction.
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)
