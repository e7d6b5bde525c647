"""docs/ceilings.md is generated from the constants that enforce each ceiling: never stale."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _tool():  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location("ceilings_tool", ROOT / "tools" / "ceilings.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_page_says_what_the_constants_say() -> None:
    tool = _tool()
    page = (ROOT / "docs" / "ceilings.md").read_text(encoding="utf-8")
    assert page == tool.render(), "docs/ceilings.md is stale: run python tools/ceilings.py"


def test_the_numbers_a_user_meets_are_on_the_page() -> None:
    """Issue 25: the README said 64 drones for write, the code 100."""
    from skyquill.calligraphy.show import MAX_DRONES
    from skyquill.cli.check_cmd import MAX_DRONES as CHECK_DRONES
    from skyquill.optimize.fit import MAX_SPANS

    page = (ROOT / "docs" / "ceilings.md").read_text(encoding="utf-8")
    assert f"{MAX_DRONES:,} drones (`--grid`" in page
    assert f"{CHECK_DRONES:,} drones" in page
    assert f"{MAX_SPANS:,} knot spans" in page


def test_the_readme_links_to_the_page_instead_of_a_copy() -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert "docs/ceilings.md" in readme
    assert not re.search(r"^\| `write` \|", readme, re.MULTILINE)


def test_the_explanation_links_to_the_page_instead_of_a_copy() -> None:
    """The site's page on errors, ceilings and outputs held a stale copy of the table."""
    page = (ROOT / "docs" / "explanations" / "errors-and-outputs.md").read_text(encoding="utf-8")
    assert "(../ceilings.md)" in page
    assert "| what | ceiling |" not in page


def test_the_page_is_in_the_site_navigation() -> None:
    nav = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    assert re.search(r"^\s*- Ceilings: ceilings\.md$", nav, re.MULTILINE)
