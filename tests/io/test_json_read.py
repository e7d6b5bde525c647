"""The one JSON parser every reader uses: encodings, depth, size and malformed text named."""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.io.json_read import MAX_DEPTH, _may_refuse, check_depth, parse_json, read_json_file

WHAT = "a test document"


@pytest.mark.parametrize(
    ("raw", "match"),
    [
        ("[" * 100_000 + "]" * 100_000, "got JSON nested too deeply"),
        ("[" * (MAX_DEPTH + 1) + "]" * (MAX_DEPTH + 1), f"got JSON nested more than {MAX_DEPTH}"),
        ('{"a": ' * (MAX_DEPTH + 1) + "1" + "}" * (MAX_DEPTH + 1), "got JSON nested more"),
        ("[1, 2", r"got malformed JSON at line 1, column 6 \(Expecting ',' delimiter\)"),
        ("[" + "9" * 5000 + "]", "got an unreadable number"),
        ("", r"got malformed JSON at line 1, column 1"),
    ],
)
def test_malformed_text_is_named(raw: str, match: str) -> None:
    with pytest.raises(InputError, match=rf"doc\.json: {match}"):
        parse_json(raw.encode(), "doc.json", WHAT)


@pytest.mark.parametrize(
    ("raw", "match"),
    [
        ('{"a": 1}'.encode("utf-16"), "got UTF-16 text, expected a test document in UTF-8"),
        ('{"a": 1}'.encode("utf-16-be").replace(b"\0{", b"\xfe\xff\0{", 1), "got UTF-16"),
        (b'{"a": "\xe9"}', r"got bytes that are not UTF-8 \(at offset 7\)"),
        (b"\x89PNG\r\n\x1a\n\x00", r"got binary data \(a NUL byte at offset 8\)"),
    ],
)
def test_encodings_other_than_utf8_are_named(raw: bytes, match: str) -> None:
    with pytest.raises(InputError, match=rf"doc\.json: {match}"):
        parse_json(raw, "doc.json", WHAT)


def test_a_byte_order_mark_and_deep_enough_nesting_are_accepted() -> None:
    assert parse_json(b'\xef\xbb\xbf{"a": [1]}', "doc.json", WHAT) == {"a": [1]}
    deepest = "[" * MAX_DEPTH + "]" * MAX_DEPTH
    assert parse_json(deepest.encode(), "doc.json", WHAT) is not None


def test_files_missing_or_too_large(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"none\.json: no such file, expected a test document"):
        read_json_file(tmp_path / "none.json", WHAT)
    big = tmp_path / "big.json"
    big.write_text("[" + "0," * 100 + "0]", encoding="utf-8")
    with pytest.raises(InputError, match=r"big\.json: got 203 bytes, expected .* at most 100"):
        read_json_file(big, WHAT, max_bytes=100)
    with pytest.raises(InputError, match=r"got a folder, expected a test document \(a regular"):
        read_json_file(tmp_path, WHAT)
    pipe = tmp_path / "pipe.json"
    os.mkfifo(pipe)
    with pytest.raises(InputError, match=r"pipe.json: got a named pipe, expected a test document"):
        read_json_file(pipe, WHAT)


@pytest.mark.parametrize(
    ("raw", "match"),
    [
        ('{"a": 1, "a": 2}', r"got the key 'a' twice in one object, expected .*each key once"),
        ('[{"b": {"c": 1, "c": 1}}]', r"got the key 'c' twice"),
        ("[NaN]", r"got NaN, expected .*not JSON"),
        ('{"x": -Infinity}', r"got -Infinity, expected"),
        ("[1e400]", r"got a number beyond the float range \(about 1.8e308\), expected"),
    ],
)
def test_what_json_forbids_and_python_allows_is_refused(raw: str, match: str) -> None:
    with pytest.raises(InputError, match=rf"doc\.json: {match}"):
        parse_json(raw.encode(), "doc.json", WHAT)


_json = st.recursive(
    st.one_of(
        st.none(),
        st.booleans(),
        st.floats(allow_nan=False, allow_infinity=False),
        st.integers(),
        st.text(max_size=4),
    ),
    lambda inner: st.one_of(
        st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=3), inner, max_size=3)
    ),
    max_leaves=30,
)


@settings(max_examples=200, deadline=None)
@given(doc=_json)
def test_any_json_document_round_trips(doc: object) -> None:
    text = json.dumps(doc)
    assert json.dumps(parse_json(text.encode(), "doc.json", WHAT)) == text


@settings(max_examples=300, deadline=None)
@given(raw=st.binary(max_size=64))
def test_random_bytes_give_a_document_or_an_input_error(raw: bytes) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "raw.json"
        path.write_bytes(raw)
        try:
            read_json_file(path, WHAT)
        except InputError as exc:
            assert "raw.json" in str(exc)


# Numbers written as JSON literals, huge ones included (Python reads 1e400 as infinity).
_literal = st.one_of(
    st.floats(allow_nan=False, allow_infinity=False).map(repr),
    st.integers(-(10**400), 10**400).map(str),
    st.builds(
        lambda digits, exponent: f"{digits}e{exponent}",
        st.integers(0, 10**120),
        st.integers(-400, 400).map(lambda e: f"{e:+d}" if e % 2 else str(e)),
    ),
    st.text(alphabet='[]{}"\\,:ab', max_size=6).map(json.dumps),  # brackets inside strings
)


def _nested(leaves: st.SearchStrategy[str]) -> st.SearchStrategy[str]:
    """JSON texts of ``leaves`` nested in arrays and objects, sometimes very deep."""
    shallow = st.recursive(
        leaves,
        lambda inner: st.one_of(
            st.lists(inner, max_size=3).map(lambda items: "[" + ",".join(items) + "]"),
            st.lists(inner, max_size=3).map(
                lambda items: "{" + ",".join(f'"k{i}": {v}' for i, v in enumerate(items)) + "}"
            ),
        ),
        max_leaves=12,
    )
    return st.builds(
        lambda depth, doc: "[" * depth + doc + "]" * depth, st.integers(0, MAX_DEPTH + 2), shallow
    )


@settings(max_examples=300, deadline=None)
@given(text=_nested(_literal))
def test_the_text_scan_finds_every_document_the_walk_refuses(text: str) -> None:
    # parse_json walks the document (check_depth) only where the scan of its text says
    # the walk could refuse it: the refusals must be the walk's, as before.
    try:
        data = json.loads(text)
    except RecursionError:
        return  # too deep for Python's parser: refused before the walk
    try:
        check_depth(data, "doc.json", WHAT)
    except InputError as exc:
        assert _may_refuse(text.encode())
        with pytest.raises(InputError) as refused:
            parse_json(text.encode(), "doc.json", WHAT)
        assert str(refused.value) == str(exc)
    else:
        assert json.dumps(parse_json(text.encode(), "doc.json", WHAT)) == json.dumps(data)
