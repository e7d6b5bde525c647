"""The strict reading of an SVG's geometry: what svgelements would drop or repair is an error.

svgelements parses leniently, as a browser renders: a ``transform`` it cannot read
is ignored, a ``<rect width="abc">`` is left out, a path command short of a
coordinate is dropped with the rest of the path, an odd coordinate of a polyline
is dropped, a negative radius is drawn as a positive one. A drawing read that way
is not the drawing its author made, so every such case is refused here, before
svgelements' shapes are used, naming the element (its tag and its ``id``, or its
place among the elements of its tag) and the attribute:

* ``transform`` (on any element): a list of ``matrix(6)``, ``translate(1|2)``,
  ``scale(1|2)``, ``rotate(1|3)``, ``skewX(1)``, ``skewY(1)``;
* ``d``: the path grammar of SVG 1.1 §8.3, every command with whole groups of its
  numbers (arc flags ``0`` or ``1``), starting with a move-to;
* ``points``: an even count of numbers;
* lengths (``x``, ``y``, ``width``, ``height``, ``cx``, ``cy``, ``r``, ``rx``,
  ``ry``, ``x1``, ``y1``, ``x2``, ``y2``): a number with an optional unit; sizes and
  radii not negative.

Numbers are those of :mod:`skyquill.io.numbers` (plain ASCII decimals: no ``NaN``,
no ``inf``).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from collections import Counter
from pathlib import Path

from skyquill.errors import InputError
from skyquill.io.numbers import NUMBER

_NUM = re.compile(NUMBER, re.ASCII)
_SEP = re.compile(r"[\x20\x09\x0a\x0d]*,?[\x20\x09\x0a\x0d]*")
_WSP = re.compile(r"[\x20\x09\x0a\x0d]*")
#: Numbers each path command takes, per repetition.
_PATH_ARGS = {"M": 2, "L": 2, "T": 2, "H": 1, "V": 1, "C": 6, "S": 4, "Q": 4, "A": 7, "Z": 0}
_ARC_FLAGS = (3, 4)
#: Numbers each transform function may take.
_TRANSFORM_ARGS = {
    "matrix": (6,),
    "translate": (1, 2),
    "scale": (1, 2),
    "rotate": (1, 3),
    "skewX": (1,),
    "skewY": (1,),
}
_TRANSFORM = re.compile(r"[\s,]*([A-Za-z]+)\s*\(([^()]*)\)[\s,]*", re.ASCII)
_LENGTH = re.compile(rf"\s*({NUMBER})\s*(px|mm|cm|in|pt|pc|em|ex|%)?\s*", re.ASCII)
#: Length attributes per shape, and which of them may not be negative.
_LENGTHS = {
    "rect": ("x", "y", "width", "height", "rx", "ry"),
    "circle": ("cx", "cy", "r"),
    "ellipse": ("cx", "cy", "rx", "ry"),
    "line": ("x1", "y1", "x2", "y2"),
}
_NOT_NEGATIVE = {"width", "height", "r", "rx", "ry"}


def check_svg_markup(p: Path, raw: bytes) -> None:
    """Refuse the SVG ``raw`` (read from ``p``) if any attribute breaks the rules above."""
    try:
        root = ET.fromstring(raw)
    except ET.ParseError:
        return  # svgelements has parsed it (its errors are reported there)
    seen: Counter[str] = Counter()
    for element in root.iter():
        if not isinstance(element.tag, str):
            continue  # a comment or processing instruction
        tag = element.tag.rsplit("}", 1)[-1]
        seen[tag] += 1
        problem = _problem(tag, element.attrib)
        if problem is not None:
            attribute, text, expected = problem
            ident = element.attrib.get("id")
            name = f"<{tag} id={ident!r}>" if ident else f"<{tag}> number {seen[tag]}"
            raise InputError(f"{p}: {name} {attribute}: got {_short(text)!r}, expected {expected}")


def _problem(tag: str, attributes: dict[str, str]) -> tuple[str, str, str] | None:
    """The first bad ``(attribute, value, what was expected)`` of one element, or None."""
    transform = attributes.get("transform")
    if transform is not None and not _transform_ok(transform):
        return (
            "transform",
            transform,
            (
                "a list of matrix(a,b,c,d,e,f), translate(x[,y]), scale(x[,y]), rotate(a[,x,y]), "
                "skewX(a) or skewY(a) with plain decimal numbers"
            ),
        )
    if tag == "path" and "d" in attributes:
        error = path_data_error(attributes["d"])
        if error is not None:
            return "d", attributes["d"], error
    if tag in ("polyline", "polygon") and "points" in attributes:
        numbers = _numbers(attributes["points"])
        if numbers is None or len(numbers) % 2:
            what = "plain decimal numbers" if numbers is None else f"{len(numbers)} numbers"
            return "points", attributes["points"], f"x,y pairs (an even count of numbers; {what})"
    for name in _LENGTHS.get(tag, ()):
        text = attributes.get(name)
        if text is None:
            continue
        match = _LENGTH.fullmatch(text)
        if match is None:
            return name, text, "a length: a plain decimal number, optionally with a unit (px, mm)"
        if name in _NOT_NEGATIVE and float(match.group(1)) < 0:
            return name, text, "a length >= 0 (a negative size or radius is an error in SVG)"
    return None


def path_data_error(d: str) -> str | None:
    """What is wrong with the path data ``d`` (SVG 1.1 §8.3), or None when it is whole."""
    at = _WSP.match(d, 0).end()  # type: ignore[union-attr]
    first = True
    while at < len(d):
        command = d[at]
        if command.upper() not in _PATH_ARGS:
            token = d[at : at + 12]
            return f"only numbers and path commands (character {at} starts {token!r})"
        if first and command not in "Mm":
            return "path data that starts with a move-to (M or m)"
        first = False
        count = _PATH_ARGS[command.upper()]
        at = _WSP.match(d, at + 1).end()  # type: ignore[union-attr]
        if count == 0:
            continue
        groups = 0
        while True:
            got, end = _group(d, at, count, command.upper() == "A")
            if got == count:
                groups, at = groups + 1, _SEP.match(d, end).end()  # type: ignore[union-attr]
                continue
            if got or not groups:
                return (
                    f"{count} numbers for each {command!r} (character {at} has {got}"
                    + (", then a token that is not a number" if end < len(d) else "")
                    + ")"
                )
            break
    return None


def _group(d: str, at: int, count: int, arc: bool) -> tuple[int, int]:
    """How many of one command's ``count`` numbers follow from ``at``, and where they end."""
    got = 0
    while got < count:
        if got:
            at = _SEP.match(d, at).end()  # type: ignore[union-attr]
        if arc and got in _ARC_FLAGS:
            if at < len(d) and d[at] in "01":
                got, at = got + 1, at + 1
                continue
            break
        match = _NUM.match(d, at)
        if match is None:
            break
        got, at = got + 1, match.end()
    return got, at


def _numbers(text: str) -> list[float] | None:
    """The numbers of a comma-or-space separated list (``1-2`` is 1 and -2, as in SVG);
    None if anything else is in it."""
    numbers: list[float] = []
    at = _WSP.match(text, 0).end()  # type: ignore[union-attr]
    while at < len(text):
        if numbers:
            at = _SEP.match(text, at).end()  # type: ignore[union-attr]
        match = _NUM.match(text, at)
        if match is None:
            return None
        numbers.append(float(match.group(0)))
        at = _WSP.match(text, match.end()).end()  # type: ignore[union-attr]
    return numbers


def _transform_ok(text: str) -> bool:
    at = 0
    while at < len(text):
        match = _TRANSFORM.match(text, at)
        if match is None or match.end() == at:
            return text[at:].strip(" \t\r\n,") == ""
        args = _numbers(match.group(2))
        allowed = _TRANSFORM_ARGS.get(match.group(1))
        if allowed is None or args is None or len(args) not in allowed:
            return False
        at = match.end()
    return True


def _short(text: str) -> str:
    return text if len(text) <= 40 else text[:37] + "..."
