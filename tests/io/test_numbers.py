"""The one number grammar (issue 25): plain ASCII decimal literals, nothing float() adds."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.io.numbers import MAX_CHARS, is_literal, is_number, parse_number


@pytest.mark.parametrize(
    ("text", "value"),
    [("1.5", 1.5), ("-2", -2.0), ("+3e-4", 3e-4), (".5", 0.5), ("5.", 5.0), (" 7 ", 7.0),
     ("1E3", 1000.0), ("-0", -0.0)],
)  # fmt: skip
def test_plain_decimal_literals_are_read(text: str, value: float) -> None:
    assert parse_number(text) == value


@pytest.mark.parametrize(
    "text",
    ["1_0", "٠.١", "０.５", "0x10", "nan", "-inf", "Infinity", "", " ", "1e", "e5", ".", "+-1",
     "1.2.3", "1,5", "\u00a01", "1\u2009", "²", "1e999", "-1e400", "1" * (MAX_CHARS + 1)],
)  # fmt: skip
def test_what_float_takes_beyond_the_grammar_is_refused(text: str) -> None:
    with pytest.raises(ValueError, match="expected"):
        parse_number(text)
    assert not is_number(text)


def test_non_finite_words_only_where_an_option_asks_for_them() -> None:
    assert not is_literal("inf") and is_literal("inf", non_finite=True)
    assert is_literal("1e999")  # the grammar holds; the value's range is the reader's to refuse
    assert not is_literal("1_0", non_finite=True)


@settings(max_examples=300, deadline=None)
@given(st.floats(allow_nan=False, allow_infinity=False))
def test_every_float_python_writes_is_read_back_exactly(value: float) -> None:
    assert parse_number(repr(value)) == value
    assert parse_number(f"{value:.17e}") == value


@settings(max_examples=300, deadline=None)
@given(st.text(max_size=12))
def test_any_text_is_a_finite_number_or_one_value_error(text: str) -> None:
    try:
        value = parse_number(text)
    except ValueError:
        return
    assert math.isfinite(value)
    assert text.strip(" \t").isascii()
