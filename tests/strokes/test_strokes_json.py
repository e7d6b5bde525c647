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
from skyquill.strokes import load_stroke_json


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
    with pytest.raises(InputError, match=r"bad\.json: malformed JSON at line 1, column \d+"):
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
    with pytest.raises(InputError, match=r"nan\.json: stroke 0: got 1 NaN or infinite"):
        load_stroke_json(p)


def test_strings_are_refused(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="stroke 0: got values of type <U"):
        load_stroke_json(_write(tmp_path, {"strokes": [[["a", "b"], [1, 1]]]}))


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
_point = st.tuples(st.floats(-1e6, 1e6), st.floats(-1e6, 1e6)).map(list)
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
@given(raw=st.binary(max_size=40))
def test_random_bytes_give_input_error(tmp_path: Path, raw: bytes) -> None:
    p = tmp_path / "raw.json"
    p.write_bytes(raw)
    with contextlib.suppress(InputError):
        load_stroke_json(p)
