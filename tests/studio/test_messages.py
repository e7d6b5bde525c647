"""The page's words: every refusal names the field as labelled and says what to do in the page."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.studio.messages import StudioInputError, for_person
from skyquill.studio.models import PlanRequest
from skyquill.studio.planner import check_text, parts_of

#: What a person's message never holds: command-line flags, Python names, paper numbers.
JARGON = ("--", "load_svg", "skyquill ", "paper 0", "hanzi-writer", "Hershey", "futural", "()")


@pytest.mark.parametrize(
    ("text", "starts"),
    [
        ("龘", "Text: 龘 is not among the 9,574 Chinese characters"),
        ("𠀀", "Text: 𠀀 is not among"),
        ("Hi 😀", "Text: 😀 cannot be written; the studio writes Latin letters"),
        ("永a", "Text: a cannot be written beside Chinese characters"),
    ],
)
def test_text_the_studio_cannot_write_is_named(text: str, starts: str) -> None:
    with pytest.raises(StudioInputError) as caught:
        check_text(text)
    error = caught.value
    assert error.field == "text" and error.person.startswith(starts)
    assert not any(word in error.person for word in JARGON)
    assert str(error).startswith("text: got ")  # the API's words for programs


def test_text_the_studio_can_write_passes() -> None:
    check_text("Hello, world 42!")
    check_text("永 中")


@pytest.mark.parametrize(
    ("body", "field", "says"),
    [
        ({"text": "Hi", "drones": 3}, "drones", "Choose at most 1 drone, or type more"),
        ({"strokes": [[[0, 0], [1, 1]]], "drones": 2}, "drones", "or draw more strokes"),
    ],
)
def test_more_drones_than_parts_say_what_to_change(body: dict, field: str, says: str) -> None:
    with pytest.raises(StudioInputError) as caught:
        parts_of(PlanRequest.model_validate(body))
    assert caught.value.field == field and says in caught.value.person


@pytest.mark.parametrize(
    ("detail", "field", "person"),
    [
        ("vmax: got -1, expected > 0", None, "Speed: got -1, expected > 0"),
        ("stroke 3: got 2 points all equal", None, "Drawing: got 2 points all equal"),
        ("strokes[0][1]: got 'a'", "strokes", "Drawing: got 'a'"),
        ("planning took longer than 120 s", None, "Planning took longer than 120 s"),
    ],
)
def test_a_core_message_gets_the_fields_label(detail: str, field: str | None, person: str) -> None:
    assert for_person(detail, field) == person


@given(st.text(max_size=60), st.sampled_from([None, "vmax", "text", "strokes", "limits"]))
def test_any_message_can_be_put_in_the_pages_words(detail: str, field: str | None) -> None:
    out = for_person(detail, field)
    assert isinstance(out, str)


def test_a_studio_error_is_an_input_error() -> None:
    """The CLI's and the job runner's boundaries treat it as bad input (exit 2, a 422)."""
    assert issubclass(StudioInputError, InputError)
