"""Every ``skyquill`` command line shown on the documentation site names a real command and
real options (the README's commands are run in full by ``test_readme.py``; the site's guides
show longer jobs, so they are checked against the program's own options instead)."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest
import typer

from skyquill.cli.main import app

DOCS = Path(__file__).resolve().parents[2] / "docs"
FENCE = re.compile(r"^```bash\n(.*?)^```", re.DOTALL | re.MULTILINE)


def doc_commands() -> list[tuple[str, list[str]]]:
    """``(page, words after "skyquill")`` for every skyquill command in the docs' bash blocks."""
    found = []
    for page in sorted(DOCS.rglob("*.md")):
        for block in FENCE.findall(page.read_text(encoding="utf-8")):
            for line in re.sub(r"\\\n", " ", block).splitlines():
                words = shlex.split(line, comments=True)
                if words and words[0].endswith("bin/skyquill"):
                    found.append((str(page.relative_to(DOCS)), words[1:]))
    return found


def options_of(words: list[str]) -> tuple[str, set[str]]:
    """The command named by ``words`` and every option it accepts."""
    command = typer.main.get_command(app)
    ctx = typer.Context(command, info_name="skyquill")
    name = "skyquill"
    while words and hasattr(command, "get_command") and not words[0].startswith("-"):
        sub = command.get_command(ctx, words[0])
        assert sub is not None, f"no command {name} {words[0]}"
        command, name, words = sub, f"{name} {words[0]}", words[1:]
        ctx = typer.Context(command, info_name=name, parent=ctx)
    opts = {o for p in command.get_params(ctx) for o in (*p.opts, *p.secondary_opts)}
    return name, opts


@pytest.mark.parametrize(("page", "words"), doc_commands())
def test_doc_command_names_real_options(page: str, words: list[str]) -> None:
    name, opts = options_of(words)
    unknown = [w.split("=")[0] for w in words if w.startswith("--") and w.split("=")[0] not in opts]
    assert not unknown, f"{page}: {name} has no {unknown}"


def test_the_docs_show_commands() -> None:
    assert len(doc_commands()) > 30
