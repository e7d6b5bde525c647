"""``skyquill hanzi``: which Chinese characters skyquill can write, all or of a text."""

from __future__ import annotations

import textwrap
from typing import Annotated

import typer

from skyquill.cli.main import app, user_errors
from skyquill.errors import InputError

#: Characters per line of the listing.
LINE = 40


@app.command()
def hanzi(
    text: Annotated[
        str | None,
        typer.Argument(help="Characters to look up; without it every shipped one is listed."),
    ] = None,
) -> None:
    """List the Chinese characters skyquill writes (hanzi-writer-data 2.0.1), or check TEXT."""
    from skyquill.strokes.hanzi import ALTERNATIVES, bundled_hanzi, missing_hanzi

    with user_errors():
        chars = bundled_hanzi()
        source = (
            f"{len(chars):,} characters of hanzi-writer-data 2.0.1 (Make Me a Hanzi, "
            "Arphic Public License)"
        )
        if text is None:
            typer.echo(f"{source}, by code point:")
            typer.echo("\n".join(textwrap.wrap(chars, LINE)))
            return
        if not text.strip():
            raise InputError(
                f"text: got {text!r}, expected characters to look up (or none, to list them all)"
            )
        missing = missing_hanzi(text)
        if not missing:
            typer.echo(f"all of {text.strip()!r} are among the {source}")
            return
        named = ", ".join(f"{c!r} (U+{ord(c):04X})" for c in missing)
        typer.echo(f"not among the {source}: {named}; {ALTERNATIVES}")
