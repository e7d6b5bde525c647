"""load_stroke_json on small files written in tmp_path."""

from __future__ import annotations

import contextlib
import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.io.json_read import MAX_DEPTH
from skyquill.strokes import load_stroke_json
from skyquill.strokes.model import MAX_POINTS, MAX_STROKES


def _write(tmp_path: Path, data: object, name: str = "pad.json") -> Path:
    p = tmp_path / name
    p.write_text(json.dumps(data), encoding="utf-8")
    return p


def test_loads_strokes_and_times(tmp_path: Path) -> None:
    p = _write(
        tmp_path,
        {"strokes": [[[0, 0], [1, 2], [3, 2]], [[5, 5], [6, 5]]], "t": [[0, 0.1, 0.2], [1, 1.5]]},
    )
    s = load_stroke_json(p)
    assert s.n_strokes == 2
    np.testing.assert_array_equal(s.paths[0], [[0, 0], [1, 2], [3, 2]])
    assert s.times is not None
    np.testing.assert_array_equal(s.times[1], [1.0, 1.5])
    assert s.source == "pad.json"


def test_times_are_optional(tmp_path: Path) -> None:
    assert load_stroke_json(_write(tmp_path, {"strokes": [[[0, 0], [1, 1]]]})).times is None
    assert (
        load_stroke_json(_write(tmp_path, {"strokes": [[[0, 0], [1, 1]]], "t": None})).times is None
    )


def test_malformed_json(tmp_path: Path) -> None:
    p = tmp_path / "bad.json"
    p.write_text('{"strokes": [[[0, 0], [1, 1]]', encoding="utf-8")
    with pytest.raises(InputError, match=r"bad\.json: got malformed JSON at line 1, column \d+"):
        load_stroke_json(p)


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"nope\.json: no such file"):
        load_stroke_json(tmp_path / "nope.json")


def test_top_level_must_be_object(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="got a JSON list at top level"):
        load_stroke_json(_write(tmp_path, [[[0, 0], [1, 1]]]))


def test_missing_strokes_key(tmp_path: Path) -> None:
    with pytest.raises(InputError, match='no "strokes" key'):
        load_stroke_json(_write(tmp_path, {}))


def test_unknown_key_is_named(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"unknown key\(s\) \['times'\]"):
        load_stroke_json(_write(tmp_path, {"strokes": [[[0, 0], [1, 1]]], "times": [[0, 1]]}))


def test_empty_stroke_list(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"pad\.json: paths: got an empty list of strokes"):
        load_stroke_json(_write(tmp_path, {"strokes": []}))


def test_one_point_stroke(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"pad\.json: stroke 1: got 1 point\(s\)"):
        load_stroke_json(_write(tmp_path, {"strokes": [[[0, 0], [1, 1]], [[2, 2]]]}))


def test_repeated_points(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"stroke 0: got 2 points all equal to \(4, 4\)"):
        load_stroke_json(_write(tmp_path, {"strokes": [[[4, 4], [4, 4]]]}))


def test_nan(tmp_path: Path) -> None:
    p = tmp_path / "nan.json"
    p.write_text('{"strokes": [[[0, 0], [NaN, 1]]]}', encoding="utf-8")
    with pytest.raises(InputError, match=r"nan\.json: got NaN, expected .*not JSON"):
        load_stroke_json(p)


def test_strings_are_refused(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r'"strokes"\[0\]\[0\]: got \[\'a\', \'b\'\], expected'):
        load_stroke_json(_write(tmp_path, {"strokes": [[["a", "b"], [1, 1]]]}))


def test_numeric_strings_are_refused_not_converted(tmp_path: Path) -> None:
    p = _write(tmp_path, {"strokes": [[[0, 0], ["1", "2"]]]})
    with pytest.raises(
        InputError, match=r'"strokes"\[0\]\[1\]: got \[\'1\', \'2\'\], expected \[x, y\] of two'
    ):
        load_stroke_json(p)


def test_string_times_are_refused(tmp_path: Path) -> None:
    p = _write(tmp_path, {"strokes": [[[0, 0], [1, 1]]], "t": [["0", "1"]]})
    with pytest.raises(
        InputError, match=r'"t"\[0\]: got \[\'0\', \'1\'\], expected a list of JSON'
    ):
        load_stroke_json(p)


def test_deep_nesting_is_named(tmp_path: Path) -> None:
    p = tmp_path / "deep.json"
    p.write_text("[" * 100_000 + "]" * 100_000, encoding="utf-8")
    with pytest.raises(InputError, match=r"deep\.json: got JSON nested too deeply"):
        load_stroke_json(p)
    p.write_text('{"strokes": ' + "[" * 80 + "]" * 80 + "}", encoding="utf-8")
    with pytest.raises(
        InputError, match=rf"deep\.json: got JSON nested more than {MAX_DEPTH} deep"
    ):
        load_stroke_json(p)


def test_too_many_strokes_are_refused(tmp_path: Path) -> None:
    p = _write(tmp_path, {"strokes": [[[0, 0], [1, 1]]] * 10_000})
    with pytest.raises(
        InputError, match=rf'"strokes": got 10,000 strokes, expected at most {MAX_STROKES:,}'
    ):
        load_stroke_json(p)


def test_too_many_points_are_refused(tmp_path: Path) -> None:
    p = _write(tmp_path, {"strokes": [[[i, 0] for i in range(MAX_POINTS + 1)]]})
    with pytest.raises(InputError, match=rf"got more than {MAX_POINTS:,} points by stroke 0"):
        load_stroke_json(p)


def test_huge_integer_literal_is_named(tmp_path: Path) -> None:
    p = tmp_path / "int.json"
    p.write_text('{"strokes": [[[' + "1" * 5000 + ", 0], [1, 1]]]}", encoding="utf-8")
    with pytest.raises(InputError, match=r"int\.json: got an unreadable number"):
        load_stroke_json(p)


@pytest.mark.parametrize(
    ("raw", "match"),
    [
        ('{"strokes": [[[0, 0], [1, 1]]]}'.encode("utf-16"), "got UTF-16 text, expected"),
        (b"\x89PNG\r\n\x1a\n\x00\x00\x00", r"got binary data \(a NUL byte at offset 8\)"),
        (b'{"strokes": "\xe9"}', r"got bytes that are not UTF-8 \(at offset 13\)"),
    ],
)
def test_text_that_is_not_utf8_is_named(tmp_path: Path, raw: bytes, match: str) -> None:
    p = tmp_path / "enc.json"
    p.write_bytes(raw)
    with pytest.raises(InputError, match=rf"enc\.json: {match}"):
        load_stroke_json(p)


def test_byte_order_mark_is_accepted(tmp_path: Path) -> None:
    p = tmp_path / "bom.json"
    p.write_bytes(b"\xef\xbb\xbf" + b'{"strokes": [[[0, 0], [1, 1]]]}')
    assert load_stroke_json(p).n_points == 2


def test_times_not_increasing(tmp_path: Path) -> None:
    p = _write(tmp_path, {"strokes": [[[0, 0], [1, 1], [2, 0]]], "t": [[0.0, 0.2, 0.1]]})
    with pytest.raises(InputError, match=r"t\[1\] = 0.2 followed by t\[2\] = 0.1"):
        load_stroke_json(p)


_scalars = st.one_of(
    st.floats(allow_nan=False, allow_infinity=False),
    st.integers(min_value=-(10**25), max_value=10**25),
    st.booleans(),
    st.none(),
    st.text(max_size=3),
)
_json = st.recursive(
    _scalars,
    lambda inner: st.one_of(
        st.lists(inner, max_size=5), st.dictionaries(st.text(max_size=3), inner, max_size=3)
    ),
    max_leaves=40,
)
_point = st.one_of(
    st.tuples(st.floats(-1e6, 1e6), st.floats(-1e6, 1e6)).map(list),
    st.lists(st.one_of(st.floats(), st.text(st.characters(categories=["Nd"]), max_size=2))),
)
_stroke = st.lists(st.one_of(_point, _point, _json), max_size=6)
_doc = st.one_of(
    _json,
    st.fixed_dictionaries(
        {"strokes": st.one_of(st.lists(_stroke, max_size=4), _json)},
        optional={"t": st.one_of(_json, st.lists(st.lists(st.floats(0, 10), max_size=6)))},
    ),
)


@settings(
    max_examples=300, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(doc=_doc)
def test_random_json_gives_strokes_or_input_error(tmp_path: Path, doc: object) -> None:
    p = _write(tmp_path, doc, "random.json")
    try:
        s = load_stroke_json(p)
    except InputError as exc:
        assert "random.json" in str(exc)
        return
    assert s.n_strokes >= 1
    assert all(np.all(np.isfinite(path)) and path.shape[0] >= 2 for path in s.paths)


@settings(
    max_examples=100, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    raw=st.one_of(
        st.binary(max_size=40),
        st.builds(
            lambda head, body, tail: head + body + tail,
            st.sampled_from([b"", b"\xef\xbb\xbf", b"\xff\xfe", b"{", b"[" * 70]),
            st.binary(max_size=40),
            st.sampled_from([b"", b"}", b"]" * 70]),
        ),
    )
)
def test_random_bytes_give_input_error(tmp_path: Path, raw: bytes) -> None:
    p = tmp_path / "raw.json"
    p.write_bytes(raw)
    with contextlib.suppress(InputError):
        load_stroke_json(p)
