"""hanzi_strokes / hanzi_text: Make Me a Hanzi medians."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from skyquill.errors import InputError
from skyquill.strokes import bundled_hanzi, hanzi_strokes, hanzi_text
from skyquill.strokes.hanzi import BENCHMARK_HANZI, missing_hanzi

_YI = {"strokes": ["M 0 0 Z"], "medians": [[[121, 393], [417, 402], [920, 401]]]}


def test_every_shipped_character_loads_inside_its_em_box() -> None:
    chars = bundled_hanzi()
    assert len(chars) == 9574 and "文" in chars and "永" in chars
    assert set(BENCHMARK_HANZI) <= set(chars)
    for c in chars:
        s = hanzi_strokes(c)
        assert s.n_strokes >= 1
        lo, hi = s.bounds()
        # inside the em box: x in [0, 1024], y in [-124, 900]
        assert lo[0] >= 0 and hi[0] <= 1024 and lo[1] >= -124 and hi[1] <= 900


def test_stroke_counts() -> None:
    assert hanzi_strokes("永").n_strokes == 5
    assert hanzi_strokes("一").n_strokes == 1
    assert hanzi_strokes("先").n_strokes == 6


def test_medians_are_y_up_in_writing_direction() -> None:
    yong = hanzi_strokes("永")
    assert yong.source == "hanzi 永"
    # the first stroke of 永 is the dot on top: above everything else
    others = np.concatenate(yong.paths[1:])
    assert yong.paths[0][:, 1].min() > others[:, 1].max() - 100
    # 一 is written left to right
    yi = hanzi_strokes("一").paths[0]
    assert yi[-1, 0] > yi[0, 0] + 500


def test_unknown_character_is_named_with_places_and_alternatives() -> None:
    message = r"'𠀀' \(U\+20000\) not found; looked in the 9,574 characters of hanzi-writer-data"
    with pytest.raises(InputError, match=message) as info:
        hanzi_strokes("𠀀")  # CJK extension B: not in the data set
    assert "--svg FILE" in str(info.value) and "--font" in str(info.value)


def test_one_character_only() -> None:
    with pytest.raises(InputError, match="expected exactly one character"):
        hanzi_strokes("永光")


def test_source_file_in_hanzi_writer_format(tmp_path: Path) -> None:
    f = tmp_path / "一.json"
    f.write_text(json.dumps(_YI), encoding="utf-8")
    s = hanzi_strokes("一", source=f)
    np.testing.assert_array_equal(s.paths[0], _YI["medians"][0])


def test_source_directory(tmp_path: Path) -> None:
    (tmp_path / "一.json").write_text(json.dumps(_YI), encoding="utf-8")
    assert hanzi_strokes("一", source=tmp_path).paths[0].shape == (3, 2)
    # source is exclusive: a character missing there is not taken from the bundle
    with pytest.raises(InputError, match=rf"'永' \(U\+6C38\) not found; looked in {tmp_path}; "):
        hanzi_strokes("永", source=tmp_path)


def test_source_mapping_file(tmp_path: Path) -> None:
    f = tmp_path / "mine.json"
    f.write_text(json.dumps({"一": _YI["medians"], "二": {"medians": _YI["medians"] * 2}}))
    assert hanzi_strokes("一", source=f).n_strokes == 1
    assert hanzi_strokes("二", source=f).n_strokes == 2


def test_env_directory_then_bundle(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    fake = {"medians": [[[0, 0], [10, 10]]]}
    (tmp_path / "永.json").write_text(json.dumps(fake), encoding="utf-8")
    monkeypatch.setenv("SKYQUILL_HANZI_DIR", str(tmp_path))
    assert hanzi_strokes("永").n_strokes == 1  # the directory wins
    assert hanzi_strokes("光").n_strokes == 6  # not there: the bundle
    with pytest.raises(InputError, match=r"looked in .*SKYQUILL_HANZI_DIR.*; the 9,574 characters"):
        hanzi_strokes("𠀀")


def test_env_directory_missing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SKYQUILL_HANZI_DIR", str(tmp_path / "nowhere"))
    with pytest.raises(InputError, match="nowhere: got no such file or directory, expected"):
        hanzi_strokes("永")


def test_malformed_source(tmp_path: Path) -> None:
    f = tmp_path / "一.json"
    f.write_text('{"medians": [[[0, 0], [1, 1]]', encoding="utf-8")
    with pytest.raises(InputError, match="malformed JSON"):
        hanzi_strokes("一", source=tmp_path)
    f.write_text('{"medians": [[[0, 0]]]}', encoding="utf-8")
    with pytest.raises(InputError, match=r"hanzi 一: stroke 0: got 1 point\(s\)"):
        hanzi_strokes("一", source=tmp_path)
    f.write_text('{"medians": 3}', encoding="utf-8")
    with pytest.raises(InputError, match="expected a list of strokes"):
        hanzi_strokes("一", source=tmp_path)


def test_hanzi_text_lays_characters_left_to_right() -> None:
    s = hanzi_text("一马当先")
    parts = [hanzi_strokes(c) for c in "一马当先"]
    assert s.n_strokes == sum(p.n_strokes for p in parts)
    np.testing.assert_array_equal(s.paths[0], parts[0].paths[0])
    np.testing.assert_array_equal(s.paths[1], parts[1].paths[0] + [1024, 0])
    np.testing.assert_array_equal(s.paths[-1], parts[3].paths[-1] + [3 * 1024, 0])
    spaced = hanzi_text("一 一", advance=1000)
    np.testing.assert_array_equal(spaced.paths[1], parts[0].paths[0] + [2000, 0])


def test_hanzi_text_errors() -> None:
    with pytest.raises(InputError, match="expected at least one character"):
        hanzi_text("  ")
    with pytest.raises(InputError, match="advance: got 0, expected a number > 0"):
        hanzi_text("一", advance=0)
    with pytest.raises(InputError, match="'𠀀'"):
        hanzi_text("一𠀀")


def test_the_shipped_medians_are_the_packages_own() -> None:
    """Values as hanzi-writer-data 2.0.1 gives them (永's first stroke, and a stroke of
    懂 whose coordinates are not integers: the packing is exact)."""
    assert hanzi_strokes("永").paths[0][:3].tolist() == [[428, 824], [503, 781], [533, 756]]
    fractional = np.concatenate(hanzi_strokes("懂").paths)
    assert np.any(fractional != np.round(fractional))
    assert np.allclose(fractional * 36, np.round(fractional * 36), atol=1e-9)


def test_missing_hanzi_names_each_missing_character_once() -> None:
    assert missing_hanzi("永文 永") == ""
    assert missing_hanzi("a永𠀀a") == "a𠀀"
