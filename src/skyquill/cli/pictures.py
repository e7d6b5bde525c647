"""The pictures a command draws, timed for ``summary.json``, and ``--no-pictures`` to skip them.

Every planning command draws what a person would rather see than read
(``plot.png``; for light painting ``long_exposure.png`` and ``preview.gif``). On a
batch of plans the pictures are often not looked at, so every planning command
takes ``--no-pictures``. Either way ``summary.json`` says what happened, under
``pictures``: ``drawn`` (false with ``--no-pictures``), the ``files`` drawn and
``time_s``, the time spent drawing them, s (so a user sees what they cost).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated, Any

import typer

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

    @contextmanager
    def timing(self, *names: str) -> Iterator[None]:
        """Time the drawing of the files ``names`` (call it only when :attr:`drawn`)."""
        clock = time.perf_counter()
        yield
        self.entry["time_s"] += time.perf_counter() - clock
        self.entry["files"].extend(names)
