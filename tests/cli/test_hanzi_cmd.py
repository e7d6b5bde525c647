"""``skyquill hanzi``: the characters skyquill writes, all of them or those of a text."""

from __future__ import annotations

from pathlib import Path

from typer.testing import CliRunner

from skyquill.cli.main import app

runner = CliRunner()


def test_lists_every_shipped_character() -> None:
    result = runner.invoke(app, ["hanzi"])
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert lines[0].startswith("9,574 characters of hanzi-writer-data 2.0.1")
    listed = "".join(lines[1:])
    assert len(listed) == 9574 and "文" in listed and "永" in listed


def test_checks_a_text_and_names_what_is_missing() -> None:
    found = runner.invoke(app, ["hanzi", "永文"])
    assert found.exit_code == 0 and "all of '永文' are among" in found.output
    missing = runner.invoke(app, ["hanzi", "永𠀀"])
    assert missing.exit_code == 0
    text = " ".join(missing.output.split())
    assert "'𠀀' (U+20000)" in text and "--svg FILE" in text and "'永'" not in text


def test_write_names_a_missing_character_and_the_alternatives(tmp_path: Path) -> None:
    result = runner.invoke(app, ["write", "永𠀀", "--out", str(tmp_path / "o")])
    assert result.exit_code == 2
    text = " ".join(result.output.split())
    assert "'𠀀' (U+20000) not found" in text and "--hanzi FILE|DIR" in text
    assert "Traceback" not in result.output


def test_an_empty_text_is_refused_in_one_line() -> None:
    result = runner.invoke(app, ["hanzi", "  "])
    assert result.exit_code == 2
    assert "text: got '  ', expected characters to look up" in result.output
