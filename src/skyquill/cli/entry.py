"""The ``skyquill`` console script: the app, with Ctrl+C covered from the first instant.

Importing the app takes most of a second (numpy, scipy, rich, typer). Ctrl+C in
that time would print a ``KeyboardInterrupt`` traceback, since the app's own
boundary (:class:`~skyquill.cli.boundary.OneLineGroup`) does not exist yet; this
module imports nothing heavy itself, so that it can say one line instead.
"""

from __future__ import annotations

import sys

#: Exit status of an interrupted command (128 + SIGINT); the same as the app's.
INTERRUPTED = 130


def run() -> None:
    """Import and run the app; one line and exit status 130 on Ctrl+C, whenever it comes."""
    try:
        from skyquill.cli.main import app

        app(prog_name="skyquill")
    except KeyboardInterrupt:
        sys.stderr.write("error: interrupted by Ctrl+C before anything was written\n")
        sys.exit(INTERRUPTED)
