"""hanzi_file: one character's hanzi-writer-data file, the character named by the file."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.strokes import hanzi_file, hanzi_strokes

# 一.json as the hanzi-writer-data package ships it: outlines, medians, radical strokes.
YI = {
    "strokes": [
        "M 518 382 Q 572 385 623 389 Q 758 399 900 383 Q 928 379 935 390 Q 944 405 931 "
        "419 Q 866 464 747 441 Q 539 418 287 400 Q 176 392 137 394 Q 109 394 113 376 "
        "Q 122 354 151 341 Q 197 320 231 329 Q 287 345 518 382 Z"
    ],
    "medians": [[[121, 393], [155, 374], [215, 365], [483, 397], [821, 415], [921, 401]]],
    "radStrokes": [0],
}


def _file(tmp_path: Path, name: str, data: object) -> Path:
    p = tmp_path / name
    p.write_text(json.dumps(data, ensure_ascii=False), encoding="utf-8")
    return p


def test_file_named_after_its_character(tmp_path: Path) -> None:
    s = hanzi_file(_file(tmp_path, "一.json", YI))
    assert s.source == "hanzi 一"
    np.testing.assert_array_equal(s.paths[0], YI["medians"][0])


def test_bundled_character_written_out_reads_back(tmp_path: Path) -> None:
    yong = hanzi_strokes("永")
    data = {"strokes": ["M 0 0 Z"] * yong.n_strokes, "medians": [p.tolist() for p in yong.paths]}
    back = hanzi_file(_file(tmp_path, "永.json", data))
    assert back.n_strokes == yong.n_strokes
    for a, b in zip(back.paths, yong.paths, strict=True):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize(
    ("name", "data", "message"),
    [
        ("yi.json", YI, r"got the name 'yi', expected a file named after its one character"),
        ("一二.json", YI, r"got the name '一二', expected a file named after its one character"),
        ("一.json", [1, 2], r'got a JSON list, expected an object with a "medians" list'),
        (
            "一.json",
            {"strokes": []},
            r"got a JSON dict with keys \['strokes'\], expected an object with a \"medians\"",
        ),
        ("一.json", {"medians": "M 0 0"}, r'expected an object with a "medians" list'),
        ("一.json", YI | {"strokes": []}, r'got 0 "strokes" and 1 "medians", expected one median'),
        ("一.json", {"medians": []}, r"paths: got an empty list of strokes, expected at least one"),
        ("一.json", {"medians": [[[0, 0]]]}, r"stroke 0: got 1 point\(s\), expected at least 2"),
    ],
)
def test_wrong_files_are_refused(tmp_path: Path, name: str, data: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        hanzi_file(_file(tmp_path, name, data))


def test_a_directory_or_nothing_is_refused(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"got a directory, expected one character's"):
        hanzi_file(tmp_path)
    with pytest.raises(InputError, match=r"got no such file, expected one character's"):
        hanzi_file(tmp_path / "永.json")


def test_not_json_is_refused(tmp_path: Path) -> None:
    p = tmp_path / "永.json"
    p.write_text("<svg/>", encoding="utf-8")
    with pytest.raises(InputError, match=r"永\.json"):
        hanzi_file(p)


JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=5),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner),
    max_leaves=30,
)


@settings(
    max_examples=80, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(medians=JSON, strokes=JSON)
def test_any_json_gives_strokes_or_input_error(
    tmp_path: Path, medians: object, strokes: object
) -> None:
    p = _file(tmp_path, "永.json", {"strokes": strokes, "medians": medians})
    try:
        s = hanzi_file(p)
    except InputError as exc:
        assert "expected" in str(exc)
    else:
        assert s.n_strokes == len(medians)  # type: ignore[arg-type]


def test_one_characters_file_writes_that_character_only(tmp_path: Path) -> None:
    """Issue 25: `write 永一 --hanzi one.json` wrote the one file's strokes for both."""
    from skyquill.strokes import typed_strokes

    named = _file(tmp_path, "一.json", YI)
    assert hanzi_strokes("一", named).source == "hanzi 一"
    with pytest.raises(InputError, match=r"'永' \(U\+6C38\) not found; looked in .*一\.json"):
        hanzi_strokes("永", named)
    anonymous = _file(tmp_path, "one.json", YI)
    with pytest.raises(InputError, match=r"one\.json: got one character's hanzi-writer data in a"):
        typed_strokes("永一", "futural", anonymous)
