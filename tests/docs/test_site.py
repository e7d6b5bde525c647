"""The documentation site builds with ``mkdocs build --strict``, and its reference is complete.

``--strict`` turns every warning into a failure: a link to a missing page or anchor, a reference
to a Python object that does not exist, a docstring mkdocstrings cannot collect. The site is
built once into a scratch folder; then every command of the ``skyquill`` program and every public
module of the package (found here by ``pkgutil``, independently of the generator's own walk over
the source tree) must have its page.
"""

from __future__ import annotations

import importlib.util
import os
import pkgutil
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest
import typer
import yaml

import skyquill
from skyquill.cli.main import app

ROOT = Path(__file__).resolve().parents[2]


def _generator() -> ModuleType:
    """``tools/docs_reference.py``, imported by path (it writes pages only inside a build)."""
    spec = importlib.util.spec_from_file_location(
        "docs_reference", ROOT / "tools" / "docs_reference.py"
    )
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _pages(nav: object) -> list[str]:
    """Every file the ``nav`` of ``mkdocs.yml`` names."""
    if isinstance(nav, str):
        return [nav]
    if isinstance(nav, dict):
        return [p for v in nav.values() for p in _pages(v)]
    if isinstance(nav, list):
        return [p for v in nav for p in _pages(v)]
    return []


def public_modules() -> list[str]:
    """skyquill's modules whose dotted names have no part starting with ``_``."""
    found = ["skyquill"] + [m.name for m in pkgutil.walk_packages(skyquill.__path__, "skyquill.")]
    return sorted(n for n in found if not any(p.startswith("_") for p in n.split(".")))


def test_help_text_brackets_are_escaped_outside_code() -> None:
    escape = _generator().escape_brackets
    assert escape("x,y[,t] `a[0]` [default: 1]") == r"x,y\[,t\] `a[0]` \[default: 1\]"
    assert escape("```\n[keep]\n```") == "```\n[keep]\n```"


def test_packages_render_only_what_they_define() -> None:
    gen = _generator()
    assert "EXPORTERS" in gen.defined_names("skyquill.export")
    assert gen.defined_names("skyquill.optimize") == []  # it only re-exports
    assert "members: false" in gen.api_markdown("skyquill.optimize")


@pytest.mark.slow
def test_site_builds_strict_with_a_page_per_command_and_module(tmp_path: Path) -> None:
    site = tmp_path / "site"
    env = os.environ | {"NO_MKDOCS_2_WARNING": "1", "DISABLE_MKDOCS_2_WARNING": "true"}
    build = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert build.returncode == 0, build.stderr[-5000:]

    root = typer.main.get_command(app)
    ctx = typer.Context(root, info_name="skyquill")
    names = root.list_commands(ctx)  # type: ignore[attr-defined]
    assert {"write", "fit", "cover", "paint", "show", "check", "export", "fly"} <= set(names)
    for name in names:
        page = (site / "reference" / "cli" / name / "index.html").read_text(encoding="utf-8")
        assert f"skyquill {name}" in page and "Usage" in page, name
    index = (site / "reference" / "cli" / "index.html").read_text(encoding="utf-8")
    assert "--version" in index

    modules = public_modules()
    assert len(modules) > 100 and "skyquill.calligraphy.mission" in modules
    assert modules == _generator().public_modules()
    for module in modules:
        html = site / "reference" / "api" / Path(*module.split(".")) / "index.html"
        assert module in html.read_text(encoding="utf-8"), module

    # What the issue asks of the site's content: each page is built and in the navigation.
    nav = set(_pages(yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))["nav"]))
    for page in (
        "getting-started",
        "guides/calligraphy",
        "guides/light-painting",
        "guides/coverage",
        "guides/wall-painting",
        "guides/studio",
        "guides/crazyflie",
        "guides/skybrush",
        "guides/px4",
        "formats/trajectory-json",
        "formats/summary-json",
        "show-format",
        "explanations/limits",
        "explanations/verified",
        "architecture",
        "explanations/papers",
    ):
        assert (site / page / "index.html").is_file(), page
        assert f"{page}.md" in nav, f"{page} is not in the navigation"
