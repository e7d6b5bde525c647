"""MkDocs hooks of the documentation site (``mkdocs.yml``: ``hooks``).

skyquill's docstrings are numpydoc with Sphinx cross-reference roles (``:class:`Trajectory```,
``:func:`~skyquill.verify.verify```), which mkdocstrings renders as code but leaves the role's
name in front of it (``:class:BoxLimit``). The role is dropped from the page and the name stays
as code, shortened as Sphinx shortens it (``~skyquill.verify.verify`` reads ``verify``).
"""

from __future__ import annotations

import re
from typing import Any

_ROLE = re.compile(r":(?:class|func|meth|mod|attr|data|exc|obj|const):<code>(~?)([^<]*)</code>")


def _code(match: re.Match[str]) -> str:
    name = match.group(2)
    return f"<code>{name.rsplit('.', 1)[-1] if match.group(1) else name}</code>"


def on_page_content(html: str, **_: Any) -> str:
    """The page's HTML without the Sphinx role names before inline code."""
    return _ROLE.sub(_code, html)
