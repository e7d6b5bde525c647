"""``--no-pictures`` on every planning command: nothing drawn, and summary.json says so.

With pictures, ``summary.json``'s ``pictures`` lists the files drawn (each on disk) and
the time they took; with ``--no-pictures`` it says ``drawn: false`` and no picture is
written. The workloads are the smallest examples (a few seconds each).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from skyquill.cli.main import app

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
PICTURE_SUFFIXES = {".png", ".gif", ".svg", ".pdf"}

#: Every planning command on a small input; ``{out}``: its output folder, ``{plan}``: a fit plan.
COMMANDS: dict[str, list[str]] = {
    "fit": ["fit", str(EXAMPLES / "spiral.csv")],
    "write": ["write", "I"],
    "write sky": ["write", "I", "--board", "sky"],
    "cover": ["cover", str(EXAMPLES / "coverage" / "square_10m.geojson"), "--rate", "50"],
    "paint": ["paint", str(EXAMPLES / "painting" / "paper_140.csv"), "--localization", "truth"],
    "show": ["show", str(EXAMPLES / "show_small.toml")],
    "fly": ["fly", "{plan}"],
}

runner = CliRunner()
pytestmark = pytest.mark.slow  # seven commands end to end (a few seconds of CPU each)


@pytest.fixture(scope="module")
def plan(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A fit plan for ``fly`` (drawn without pictures: only its trajectory is flown)."""
    out = tmp_path_factory.mktemp("plan") / "spiral"
    result = runner.invoke(app, [*COMMANDS["fit"], "--out", str(out), "--no-pictures"])
    assert result.exit_code == 0, result.output
    return out


def _run(name: str, out: Path, plan: Path, *extra: str) -> dict[str, Any]:
    args = [a.format(plan=plan) for a in COMMANDS[name]]
    result = runner.invoke(app, [*args, "--out", str(out), *extra])
    assert result.exit_code == 0, result.output
    summary: dict[str, Any] = json.loads((out / "summary.json").read_text())
    return summary


def _pictures_in(out: Path) -> list[str]:
    return sorted(p.name for p in out.rglob("*") if p.suffix in PICTURE_SUFFIXES)


@pytest.mark.timeout(300)
@pytest.mark.parametrize("name", list(COMMANDS))
def test_no_pictures_draws_none_and_says_so(name: str, tmp_path: Path, plan: Path) -> None:
    summary = _run(name, tmp_path / "out", plan, "--no-pictures")
    assert summary["pictures"] == {"drawn": False, "files": [], "time_s": 0.0}
    assert _pictures_in(tmp_path / "out") == []


@pytest.mark.timeout(300)
@pytest.mark.parametrize("name", ["fit", "write sky"])
def test_pictures_are_listed_and_timed(name: str, tmp_path: Path, plan: Path) -> None:
    summary = _run(name, tmp_path / "out", plan)
    pictures = summary["pictures"]
    assert pictures["drawn"] is True and pictures["time_s"] > 0.0
    assert sorted(pictures["files"]) == _pictures_in(tmp_path / "out")
