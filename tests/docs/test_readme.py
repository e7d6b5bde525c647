"""The README is the front page: short, and every command in it runs.

Every fenced ``bash`` block of ``README.md`` is run here, command by command, as a user would run
it from the repository's root (in a scratch folder holding ``examples``, so ``out/`` lands there);
``.venv/bin/skyquill`` is the installed command line, run in-process. ``make run`` runs the
Makefile's own recipe; ``make test`` is this suite itself (CI runs it). The ``python`` block runs
as written. A command that fails, or a line that is not a command the tests know how to run,
fails the test: the README cannot promise what does not work.
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest
from typer.testing import CliRunner

from skyquill.cli.main import app

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
FENCE = re.compile(r"^```(\w+)\n(.*?)^```", re.DOTALL | re.MULTILINE)
SKYQUILL = ".venv/bin/skyquill"
#: The README is a front page; the rest is on the documentation site.
MAX_LINES = 300


def blocks(language: str, text: str | None = None) -> list[str]:
    """The fenced blocks of ``language`` in the README, in order."""
    text = README.read_text(encoding="utf-8") if text is None else text
    return [body for lang, body in FENCE.findall(text) if lang == language]


def commands(block: str) -> list[list[str]]:
    """The command lines of a shell block: continuations joined, comments dropped."""
    joined = re.sub(r"\\\n", " ", block)
    return [words for line in joined.splitlines() if (words := shlex.split(line, comments=True))]


def make_recipe(target: str) -> list[str]:
    """The skyquill command a Makefile target runs (``$(BIN)/skyquill ...``)."""
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    recipe = re.search(rf"^{target}:.*\n((?:\t.*\n)+)", makefile, re.MULTILINE)
    assert recipe, f"Makefile: no target {target!r}"
    lines = [ln.strip() for ln in recipe.group(1).splitlines() if "/skyquill " in ln]
    assert len(lines) == 1, f"Makefile {target}: expected one skyquill command, got {lines}"
    return shlex.split(lines[0])[1:]


def run(words: list[str]) -> None:
    """Run one README command line; fail with its output if it fails."""
    if words[:2] == ["make", "test"]:
        return  # the suite this test belongs to
    if words[:2] == ["make", "run"]:
        words = [SKYQUILL, *make_recipe("run")]
    assert words[0] == SKYQUILL, f"README command the tests cannot run: {shlex.join(words)}"
    result = CliRunner().invoke(app, words[1:])
    assert result.exit_code == 0, f"{shlex.join(words)} -> {result.exit_code}\n{result.output}"


@pytest.fixture
def repo_like(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A scratch folder that looks like the repository's root to the README's commands."""
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_readme_is_a_front_page() -> None:
    text = README.read_text(encoding="utf-8")
    assert len(text.splitlines()) < MAX_LINES
    # The first lines are what the hooks find: the title and the two commands.
    assert text.startswith("# skyquill\n")
    assert "make run    #" in text and "make test   #" in text
    assert "docs/images/" in text  # one picture


def test_commands_parse_as_the_tests_read_them() -> None:
    block = 'a --x 1 \\\n    --y "two words"   # comment\n\n# only a comment\nb\n'
    assert commands(block) == [["a", "--x", "1", "--y", "two words"], ["b"]]
    assert make_recipe("run")[0] == "demo"


@pytest.mark.slow
@pytest.mark.parametrize("index", range(len(blocks("bash"))))
def test_every_bash_block_runs(index: int, repo_like: Path) -> None:
    for words in commands(blocks("bash")[index]):
        run(words)


def test_the_python_block_runs(repo_like: Path) -> None:
    (code,) = blocks("python")
    namespace: dict[str, object] = {}
    exec(compile(code, "README.md", "exec"), namespace)
    result = namespace["result"]
    assert result.verification.max_excess == 0.0  # type: ignore[attr-defined]
