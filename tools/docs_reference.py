"""Generate the documentation site's reference pages while ``mkdocs build`` runs.

The ``gen-files`` plugin (``mkdocs.yml``) runs this file; the pages exist only in the build,
nothing is written into ``docs/``:

* ``reference/cli/index.md`` and ``reference/cli/<command>.md``: the ``skyquill`` command line,
  one page per command, generated from the typer app by typer's own Markdown generator (the
  text ``skyquill <command> --help`` shows: usage, arguments, options and their defaults);
* ``reference/api/<package>/<module>.md``: one page per public module of ``src/skyquill`` (every
  module whose dotted name has no part starting with ``_``), rendered by mkdocstrings from its
  numpydoc docstrings; a package's page shows its docstring and what it exports, whose details
  are on the pages of the modules that define them;
* ``reference/cli/SUMMARY.md`` and ``reference/api/SUMMARY.md``: their navigation (literate-nav).

``tests/docs/test_site.py`` builds the site and checks that every command and every public
module got its page.
"""

from __future__ import annotations

import ast
import json
import re
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"
PROG = "skyquill"


def public_modules(src: Path = SRC) -> list[str]:
    """Dotted names of skyquill's public modules and packages under ``src``, sorted."""
    names: set[str] = set()
    for path in (src / "skyquill").rglob("*.py"):
        parts = list(path.relative_to(src).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        if not any(part.startswith("_") for part in parts):
            names.add(".".join(parts))
    return sorted(names)


def api_page(module: str) -> str:
    """Path of ``module``'s page under ``reference/api/`` (``skyquill/io/atomic.md``)."""
    return "/".join(module.split(".")) + ".md"


def defined_names(module: str, src: Path = SRC) -> list[str]:
    """Public names a package's ``__init__.py`` defines itself (not those it imports)."""
    tree = ast.parse((src / Path(*module.split(".")) / "__init__.py").read_text(encoding="utf-8"))
    names: list[str] = []
    for node in tree.body:
        if isinstance(node, ast.FunctionDef | ast.ClassDef):
            names.append(node.name)
        elif isinstance(node, ast.Assign):
            names += [t.id for t in node.targets if isinstance(t, ast.Name)]
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.append(node.target.id)
    return [n for n in names if not n.startswith("_") and n != "__all__"]


def api_markdown(module: str, src: Path = SRC) -> str:
    """The page of one module: the mkdocstrings directive that renders it, titled by its name."""
    options = ""
    if (src / Path(*module.split(".")) / "__init__.py").exists():
        # A package re-exports what its modules define, and those are documented on the
        # modules' own pages: render only what the package itself defines (rendering every
        # export twice would double the build time for nothing).
        own = defined_names(module, src)
        options = f"    options:\n      members: {json.dumps(own) if own else 'false'}\n"
    return f"::: {module}\n{options}"


_CODE = re.compile(r"(```.*?```|`[^`]*`)", re.DOTALL)


def escape_brackets(markdown: str) -> str:
    """``[`` and ``]`` outside code escaped: help texts hold ``[default: 1.0]`` and ``x,y[,t]``,
    which the site would otherwise read as references to other pages."""
    parts = _CODE.split(markdown)
    return "".join(
        part if i % 2 else part.replace("[", "\\[").replace("]", "\\]")
        for i, part in enumerate(parts)
    )


def cli_pages() -> dict[str, str]:
    """``{page name: Markdown}`` for the command line: ``index`` and one page per command."""
    import typer
    from typer.cli import get_docs_for_click
    from typer.core import TyperGroup

    from skyquill.cli.main import app

    # typer carries its own copy of click: its Context and TyperGroup, not click's.
    root = typer.main.get_command(app)
    assert isinstance(root, TyperGroup)
    ctx = typer.Context(root, info_name=PROG)
    pages = {}
    rows = []
    for name in root.list_commands(ctx):
        command = root.get_command(ctx, name)
        assert command is not None
        sub_ctx = typer.Context(command, info_name=name, parent=ctx)
        pages[name] = escape_brackets(
            get_docs_for_click(obj=command, ctx=sub_ctx, name=f"{PROG} {name}")
        )
        rows.append(f"| [`{PROG} {name}`]({name}.md) | {command.get_short_help_str(120)} |")
    options = [
        escape_brackets(f"* `{rec[0]}`: {rec[1]}")
        for param in root.get_params(ctx)
        if (rec := param.get_help_record(ctx)) is not None
    ]
    pages["index"] = "\n".join(
        [
            f"# `{PROG}`: the command line",
            "",
            root.help or "",
            "",
            f"```console\n$ {PROG} [OPTIONS] COMMAND [ARGS]...\n```",
            "",
            "**Options**:",
            "",
            *options,
            "",
            "Every command has its page, generated from the program itself (the text "
            f"`{PROG} COMMAND --help` prints):",
            "",
            "| command | what it does |",
            "|---|---|",
            *rows,
            "",
        ]
    )
    return pages


def write_pages() -> None:
    """Write every generated page and the two navigation files into the build."""
    import mkdocs_gen_files

    cli = cli_pages()
    cli_nav = ["* [skyquill](index.md)"] + [f"* [{n}]({n}.md)" for n in cli if n != "index"]
    for name, text in cli.items():
        with mkdocs_gen_files.open(f"reference/cli/{name}.md", "w") as fd:
            fd.write(text)
    with mkdocs_gen_files.open("reference/cli/SUMMARY.md", "w") as fd:
        fd.write("\n".join(cli_nav) + "\n")

    api_nav = mkdocs_gen_files.Nav()
    for module in public_modules():
        page = api_page(module)
        api_nav[tuple(module.split("."))] = page
        with mkdocs_gen_files.open(f"reference/api/{page}", "w") as fd:
            fd.write(api_markdown(module))
    with mkdocs_gen_files.open("reference/api/SUMMARY.md", "w") as fd:
        fd.writelines(api_nav.build_literate_nav())


# gen-files runs this file with runpy.run_path, whose module name is "<run_path>"; the tests
# import it by path to share public_modules() and write nothing.
if __name__ == "<run_path>":
    write_pages()
