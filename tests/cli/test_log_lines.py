"""What the program logs reaches the terminal as plain lines: no level or module names unless
``--verbose`` (a fresh process: logging is configured once per process)."""

from __future__ import annotations

import subprocess
import sys

import pytest

_SCRIPT = """
import logging, sys
from skyquill.cli.main import main
main(verbose={verbose}, version=False)
logging.getLogger("skyquill.coverage.plan.pieces").warning("a plain warning")
logging.getLogger("skyquill.coverage.plan.pieces").info("piece of 108 m2: zigzag instead")
"""


@pytest.mark.parametrize("verbose", [False, True])
def test_log_lines(verbose: bool) -> None:
    run = subprocess.run(
        [sys.executable, "-c", _SCRIPT.format(verbose=verbose)],
        capture_output=True,
        text=True,
        check=True,
        timeout=120,
    )
    lines = run.stderr.splitlines()
    if verbose:  # names and levels help whoever debugs
        assert "WARNING:skyquill.coverage.plan.pieces:a plain warning" in lines
        assert "INFO:skyquill.coverage.plan.pieces:piece of 108 m2: zigzag instead" in lines
    else:  # a person's terminal: the message alone, the pieces' fallbacks not at all
        assert lines == ["a plain warning"]
