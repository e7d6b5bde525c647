"""The one number grammar of every text skyquill reads: plain ASCII decimal literals.

A number in a CSV cell, an SVG attribute, a WKT polygon, a TOML show script or on
the command line is written the way every program that made it writes one::

    [+-]? ( digits [. digits?] | . digits ) ( [eE] [+-]? digits )?      digits: [0-9]+

Python's ``float()`` takes much more -- ``1_0`` (10), Arabic-Indic ``٠.١`` and
full-width ``０.５`` digits, surrounding Unicode spaces, ``nan``, ``Infinity`` --
and would read a typo or a locale's digits as a number without a word. This
module is the regular expression, and the only conversion of text to a number
in a reader. JSON keeps its own grammar (stricter still: no ``+``, no ``.5``);
:mod:`skyquill.io.json_read` only refuses the ``NaN`` and ``Infinity`` Python
adds to it, and numbers that overflow.
"""

from __future__ import annotations

import math
import re

#: A plain ASCII decimal literal (the whole text, nothing around it).
NUMBER = r"[-+]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][-+]?[0-9]+)?"
_NUMBER = re.compile(NUMBER, re.ASCII)
#: Words for the non-finite values options may name (``--trail inf``); never in files.
_NON_FINITE = re.compile(r"[-+]?(?:inf|infinity|nan)", re.ASCII | re.IGNORECASE)
#: Longest literal read: more digits than any float holds is not a measurement.
MAX_CHARS = 400

#: What the grammar is, in words, for messages.
EXPECTED = "a number in plain decimal digits (such as 1.5, -2 or 3e-4)"


def parse_number(text: str) -> float:
    """``text`` (surrounding ASCII spaces allowed) as a finite float.

    Raises
    ------
    ValueError
        The text is not a plain ASCII decimal literal, or its value overflows a
        float (``1e400``). The message is a short reason; readers name the file,
        line and column around it.
    """
    stripped = text.strip(" \t")
    if len(stripped) > MAX_CHARS or _NUMBER.fullmatch(stripped) is None:
        if _NON_FINITE.fullmatch(stripped):
            raise ValueError(f"expected a finite number, {EXPECTED}")
        raise ValueError(f"expected {EXPECTED}")
    value = float(stripped)
    if not math.isfinite(value):
        raise ValueError("expected a finite number within the float range (about 1.8e308)")
    return value


def is_number(text: str) -> bool:
    """Whether ``text`` is a plain decimal literal (:func:`parse_number` would accept it)."""
    try:
        parse_number(text)
    except ValueError:
        return False
    return True


def is_literal(text: str, *, non_finite: bool = False) -> bool:
    """Whether ``text`` follows the grammar (its value may overflow to infinity).

    ``non_finite``: also accept ``inf``, ``-inf`` and ``nan`` spelled out, which an
    option's own range check then accepts or refuses by name (``--trail inf``).
    """
    stripped = text.strip(" \t")
    if len(stripped) > MAX_CHARS:
        return False
    if _NUMBER.fullmatch(stripped) is not None:
        return True
    return non_finite and _NON_FINITE.fullmatch(stripped) is not None
