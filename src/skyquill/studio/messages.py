"""What the page tells a person: every error in the page's own words, at the field it is about.

The API's ``detail`` names request fields as the JSON does (``vmax: got -1, ...``),
for programs. A person reads the page, whose fields are labelled "Speed, m/s",
"Text", "Drawing": this module turns each error into that language -- the field
as labelled, what came, and what to do *in the page* (never a command-line flag,
a Python function or a paper's number) -- in one place, so that the wording of
the page's messages can be read and changed together.

* :class:`StudioInputError` -- an error the studio raises itself, with both texts;
* :func:`validation_message` -- a request the models refuse (pydantic's errors);
* :func:`for_person` -- any other ``"name: ..."`` message: the label for the name.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any

from skyquill.errors import InputError
from skyquill.studio.models import (
    FIELD_LABELS,
    MAX_DRONES,
    MAX_POINTS,
    MAX_STROKE_POINTS,
    MAX_STROKES,
    MAX_TEXT,
    field_of,
)

#: What each field takes, said as the page would (for "expected ..." messages).
FIELD_RANGES = {
    "size_m": "a size from 0.05 to 5 m",
    "vmax": "a speed above 0 and at most 20 m/s",
    "amax": "an acceleration above 0 and at most 50 m/s²",
    "jmax": "a jerk above 0 and at most 1000 m/s³",
    "drones": f"a whole number of drones from 1 to {MAX_DRONES}",
    "board": "one of the surfaces in the list",
    "target": "one of the vehicles in the list",
}
#: What to do about a drawing that is too large, in the page's words.
SMALLER_DRAWING = "Undo some strokes or press Clear, and draw less"


class StudioInputError(InputError):
    """A request the studio refuses, with its message for programs and for a person.

    Parameters
    ----------
    detail
        ``"field: got X, expected Y"`` naming the request field (the API's ``detail``).
    field
        The request field it is about (``None``: no one field).
    person
        The same in the page's words: the field as labelled and what to do in the page.
    """

    def __init__(self, detail: str, field: str | None, person: str) -> None:
        super().__init__(detail)
        self.field = field
        self.person = person


def label(field: str) -> str:
    """A request field as the page labels it, without its unit (``vmax`` -> ``Speed``)."""
    return FIELD_LABELS.get(field, field).split(",")[0]


def for_person(detail: str, field: str | None = None) -> str:
    """``detail`` (``"name: ..."``) with the request field's name replaced by its label.

    A message of the studio's own (:class:`StudioInputError`) is already in the
    page's words; this is the fallback for the core's messages, whose name
    (``vmax``, ``strokes``, ``stroke 0``, ``t[0]``) is a field of the request.
    """
    name = field or field_of(detail)
    if name is None:
        return _capitalised(detail)
    found = re.match(r"^(?:strokes from studio drawing|[a-z_]+(?: \d+)?)(?:\[[^\]]*\])*", detail)
    if found is None:
        return f"{label(name)}: {detail}"
    return label(name) + detail[found.end() :]


def _capitalised(text: str) -> str:
    return text[:1].upper() + text[1:]


def validation_message(errors: Sequence[Any]) -> str:
    """The first problem of a refused request, for a person (the page shows one at a time)."""
    if not errors:
        return "The request could not be read; reload the page and try again"
    error = errors[0]
    loc = [part for part in error.get("loc", ()) if part != "body"]
    kind = str(error.get("type", ""))
    name = loc[0] if loc and isinstance(loc[0], str) else None
    if name in ("strokes", "t"):
        return _drawing_message(kind, loc, error)
    if name == "text":
        return _text_message(kind, error)
    if name in FIELD_RANGES:
        return f"{label(name)}: got {_shown(error.get('input'))}, expected {FIELD_RANGES[name]}"
    message = str(error.get("msg", "invalid")).removeprefix("Value error, ")
    if name is None:  # the model's own checks ("got both of strokes and text, ...")
        return for_person(message)
    return f"{label(name)}: {message}"


def _drawing_message(kind: str, loc: list[Any], error: Any) -> str:
    """A drawing the model refuses: too many strokes or points, or a malformed one."""
    if kind == "too_long" and len(loc) == 1:
        got = error.get("ctx", {}).get("actual_length")
        many = f"{got} strokes" if got is not None else "too many strokes"
        return f"Drawing: {many}, at most {MAX_STROKES} can be planned. {SMALLER_DRAWING}"
    if kind == "too_long":
        return (
            f"Drawing: a stroke of more than {MAX_STROKE_POINTS:,} points, at most that many "
            "can be planned. Undo it and draw it as several shorter strokes"
        )
    message = str(error.get("msg", "")).removeprefix("Value error, ")
    if "points in all" in message:
        return (
            f"Drawing: more than {MAX_POINTS:,} points in all, at most that many can be "
            f"planned. {SMALLER_DRAWING}"
        )
    return (
        "Drawing: the page sent strokes the studio cannot read "
        f"({for_person(message) if message else kind}); press Clear and draw again"
    )


def _text_message(kind: str, error: Any) -> str:
    if kind == "string_too_long":
        got = len(str(error.get("input", "")))
        return f"Text: {got} characters, at most {MAX_TEXT}; shorten it"
    if kind == "string_type":
        return "Text: expected letters or Chinese characters"
    return "Text: type at least one letter or character, or empty the field to fly the drawing"


def _shown(value: Any) -> str:
    """A value as a person typed it (``-1``, ``"abc"``), kept short."""
    text = repr(value) if isinstance(value, str) else str(value)
    return text if len(text) <= 24 else text[:21] + "..."


def unwritable_text(text: str, missing: str, *, chinese: bool, bundled: int) -> StudioInputError:
    """The error for ``text`` holding characters the studio cannot write (``missing``)."""
    shown = " ".join(missing[:8]) + (" ..." if len(missing) > 8 else "")
    codes = ", ".join(f"U+{ord(c):04X}" for c in missing[:8])
    detail = f"text: got {shown!r} ({codes}) in {text!r}, expected characters the studio can write"
    if chinese and any(c.isascii() for c in missing):
        person = (
            f"Text: {shown} cannot be written beside Chinese characters; type Chinese "
            "characters alone or Latin text alone"
        )
    elif chinese:
        person = (
            f"Text: {shown} {'is' if len(missing) == 1 else 'are'} not among the {bundled:,} "
            "Chinese characters the studio can write. Remove it, or empty the Text field "
            "and draw it on the canvas"
        )
    else:
        person = (
            f"Text: {shown} cannot be written; the studio writes Latin letters, digits and "
            "punctuation, or Chinese characters. Remove it, or empty the Text field and draw it "
            "on the canvas"
        )
    return StudioInputError(detail, "text", person)


def too_many_drones(drones: int, units: int, *, text: bool) -> StudioInputError:
    """The error for more drones than strokes (a drawing) or characters / words (text)."""
    what = "character or word" if text else "stroke"
    detail = (
        f"drones: got {drones} drones for {units} {what}(s), expected at most one drone per {what}"
    )
    fix = "type more" if text else "draw more strokes"
    person = (
        f"Drones: {drones} drones for {units} {what}{'' if units == 1 else 's'}; each drone "
        f"writes at least one {what}. Choose at most {units} drone{'' if units == 1 else 's'}, "
        f"or {fix}"
    )
    return StudioInputError(detail, "drones", person)
