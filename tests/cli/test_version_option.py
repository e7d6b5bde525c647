"""``skyquill --version``: the installed package's version, from its metadata."""

from __future__ import annotations

from importlib.metadata import version

from typer.testing import CliRunner

import skyquill
from skyquill.cli.main import app


def test_version_is_the_package_metadata() -> None:
    result = CliRunner().invoke(app, ["--version"])
    assert result.exit_code == 0
    assert result.output == f"skyquill {version('skyquill')}\n"
    assert skyquill.__version__ == version("skyquill")


def test_version_wins_over_a_command() -> None:
    # Eager: printed before any command runs (nothing is planned, nothing written).
    result = CliRunner().invoke(app, ["--version", "write", "永"])
    assert result.exit_code == 0 and result.output.startswith("skyquill ")
