"""``skyquill reproduce``: each study writes its figures and a summary."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from skyquill.cli.main import app

runner = CliRunner()


@pytest.mark.parametrize(
    ("study", "files"),
    [
        ("segments", {"fig7.png", "results.json", "summary.json"}),
        ("corridor", {"fig10.png", "corridor.png", "results.json", "summary.json"}),
    ],
)
def test_reproduce_commands_write_their_files(tmp_path: Path, study: str, files: set[str]) -> None:
    out = tmp_path / study
    result = runner.invoke(app, ["reproduce", study, "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert files <= {p.name for p in out.iterdir()}
    json.loads((out / "summary.json").read_text())
