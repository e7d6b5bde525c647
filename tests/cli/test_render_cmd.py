"""``skyquill render``: pictures of a written plan, from the files; bad input in one line."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from PIL import Image
from typer.testing import CliRunner

from skyquill.cli.main import app

runner = CliRunner()


@pytest.fixture(scope="module")
def plan(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("render") / "plan"
    args = ["write", "A B", "--drones", "2", "--board", "wall", "--out", str(out)]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    return out


def test_render_writes_the_photograph_the_preview_and_a_summary(plan: Path, tmp_path: Path) -> None:
    out = tmp_path / "pics"
    args = ["render", str(plan), "--out", str(out), "--azimuth", "-55", "--trail", "inf"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["drones"] == 2 and summary["lit_windows"] >= 5
    assert summary["view"]["azimuth_deg"] == -55.0
    assert Image.open(out / "long_exposure.png").size == (1280, 720)
    assert Image.open(out / "preview.gif").n_frames == summary["preview_frames"]


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--trail", "-1"], "--trail: got -1, expected a number of seconds >= 0 or inf"),
        (["--light", "300,0,0"], "--light: got '300,0,0'"),
        (["--elevation", "95"], "--elevation: got 95, expected -89 to 89"),
        (["--fov", "0"], "--fov: got 0, expected 1 to 170 degrees"),
    ],
)
def test_bad_views_exit_2_in_one_line(
    plan: Path, tmp_path: Path, extra: list[str], message: str
) -> None:
    result = runner.invoke(app, ["render", str(plan), "--out", str(tmp_path / "o"), *extra])
    assert result.exit_code == 2 and message in result.output
    assert "Traceback" not in result.output and not (tmp_path / "o" / "summary.json").exists()


def test_a_missing_plan_is_named(tmp_path: Path) -> None:
    result = runner.invoke(app, ["render", str(tmp_path / "nope"), "--out", str(tmp_path / "o")])
    assert result.exit_code == 2 and "nope" in result.output
