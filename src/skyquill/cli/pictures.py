"""The pictures a command draws, timed for ``summary.json``, and ``--no-pictures`` to skip them.

Every planning command draws what a person would rather see than read
(``plot.png``; for light painting ``long_exposure.png`` and ``preview.gif``). On a
batch of plans the pictures are often not looked at, so every planning command
takes ``--no-pictures``. Either way ``summary.json`` says what happened, under
``pictures``: ``drawn`` (false with ``--no-pictures``), the ``files`` drawn and
``time_s``, the time spent drawing them, s (so a user sees what they cost).

Run from a shell with a core free, ``fit``, ``fly``, ``write`` and ``cover`` draw ``plot.png`` in
the picture worker (:mod:`skyquill.viz.worker`), started by the console script before
the program's imports, so that matplotlib's import and the fonts' loading are done on
the free core while the command plans. ``process`` then says ``"worker"``, and
``time_s`` counts starting the worker, sampling the plan, waiting for the file and
``contention_s``, what the worker's work took from the command while both ran. Should
the worker fail (it died, or its drawing raised), the picture is drawn here instead, as
without it, ``process`` says ``"command"`` and ``worker_error`` why: the plan's files
never depend on the worker.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated, Any

import typer

from skyquill.cli.boundary import console
from skyquill.viz.worker import Drawing, PictureWorker, WorkerError, take

NoPictures = Annotated[
    bool,
    typer.Option(
        "--no-pictures",
        help="Draw no pictures (plot.png and the others), for batch runs; summary.json "
        "records it under 'pictures'.",
    ),
]


class Pictures:
    """The pictures of one command: drawn and timed, or skipped.

    Parameters
    ----------
    draw
        ``False`` with ``--no-pictures``: nothing is drawn.

    Attributes
    ----------
    entry
        ``summary.json``'s ``pictures``: ``drawn``, ``files``, ``time_s`` and what
        the drawing functions report. Filled in as the pictures are drawn, so put it
        into the summary before the summary is written.
    """

    def __init__(self, draw: bool) -> None:
        self.entry: dict[str, Any] = {"drawn": draw, "files": [], "time_s": 0.0}
        self._worker: PictureWorker | None = take()
        if self._worker is not None and not draw:  # started on a wrong guess: not needed
            self._worker.close()
            self._worker = None
        if self._worker is not None:
            self.entry |= {"time_s": self._worker.start_s, "process": "worker"}

    @property
    def drawn(self) -> bool:
        """Whether pictures are drawn at all."""
        return bool(self.entry["drawn"])

    def plot(
        self, draw: Callable[[Path], None], name: str = "plot.png"
    ) -> Callable[[Path], None] | None:
        """``draw`` timed (for a writer that takes a plot function), or ``None`` when skipped."""
        if not self.drawn:
            return None

        def timed(path: Path) -> None:
            with self.timing(name):
                draw(path)

        return timed

    def sampled(
        self, sample: Callable[[], Drawing], name: str = "plot.png"
    ) -> Callable[[Path], None] | None:
        """:meth:`plot` of a picture that ``sample`` samples, drawn where :meth:`draw` says."""
        return self.plot(lambda path: self.draw(sample(), path), name)

    def draw(self, drawing: Drawing, path: Path) -> None:
        """Draw ``drawing`` to ``path``: in the worker if there is one, else (or should the
        worker fail) in this process. Time it with :meth:`timing` or :meth:`plot`."""
        worker = self._worker
        if worker is not None:
            try:
                worker.draw(drawing, path)
                return
            except WorkerError as exc:
                worker.close()
                self._worker = None
                self.entry |= {"process": "command", "worker_error": str(exc)}
                console.print(
                    f"warning: the picture worker failed ({exc}); drawing here",
                    markup=False,
                    highlight=False,
                )
            finally:
                self._count_contention(worker)
        drawing.draw(path)

    def _count_contention(self, worker: PictureWorker) -> None:
        """Count, once, what the worker's work took from the command before it drew."""
        if worker.contention_s is not None and "contention_s" not in self.entry:
            self.entry["contention_s"] = worker.contention_s
            self.entry["time_s"] += worker.contention_s

    @contextmanager
    def timing(self, *names: str) -> Iterator[None]:
        """Time the drawing of the files ``names`` (call it only when :attr:`drawn`)."""
        clock = time.perf_counter()
        yield
        self.entry["time_s"] += time.perf_counter() - clock
        self.entry["files"].extend(names)
