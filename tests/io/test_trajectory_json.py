"""trajectory.json: every kind with its pen windows and limits; version 1 still read."""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.io.trajectory_json import (
    PlannedTrajectory,
    read_trajectory_json,
    write_trajectory_json,
)
from skyquill.limits import BoxLimit, CylinderLimit, NormLimit
from skyquill.trajectory import SplineTrajectory

SPLINE = SplineTrajectory(np.arange(18, dtype=float).reshape(6, 3), 5, 2.0)


def test_limits_and_pen_round_trip(tmp_path: Path) -> None:
    limits = (NormLimit(1, 1.5), BoxLimit.symmetric(2, 2.0, 3), CylinderLimit(3, 4.0, -1.0, 1.0))
    write_trajectory_json(tmp_path / "t.json", PlannedTrajectory(SPLINE, ((0.1, 0.5),), limits))
    back = read_trajectory_json(tmp_path / "t.json")
    assert back.pen_windows_s == ((0.1, 0.5),)
    assert [lim.label for lim in back.limits] == [lim.label for lim in limits]
    np.testing.assert_array_equal(back.pen(np.array([0.0, 0.3])), [0.0, 1.0])


def test_a_colour_per_window_round_trips(tmp_path: Path) -> None:
    windows, colors = ((0.1, 0.5), (0.8, 1.0)), ((255, 0, 0), (0, 10, 255))
    write_trajectory_json(tmp_path / "t.json", PlannedTrajectory(SPLINE, windows, (), colors))
    back = read_trajectory_json(tmp_path / "t.json")
    assert back.pen_rgb == colors
    np.testing.assert_array_equal(
        back.light(np.array([0.0, 0.3, 0.9]), (1, 1, 1)), [[0, 0, 0], [255, 0, 0], [0, 10, 255]]
    )
    plain = PlannedTrajectory(SPLINE, windows)
    assert plain.colors((7, 7, 7)) == ((7, 7, 7), (7, 7, 7))


def test_a_colour_count_that_is_not_the_window_count_is_named(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"pen_rgb: got 1 colours, expected one per pen window"):
        PlannedTrajectory(SPLINE, ((0.1, 0.5), (0.8, 1.0)), (), ((255, 0, 0),))
    data = json.loads(_written(tmp_path))
    data["pen_rgb"] = [[1, 2, 3], [4, 5]]
    (tmp_path / "bad.json").write_text(json.dumps(data))
    with pytest.raises(InputError, match=r"bad.json: pen_rgb\[1\]: got \[4, 5\]"):
        read_trajectory_json(tmp_path / "bad.json")


def _written(tmp_path: Path) -> str:
    write_trajectory_json(tmp_path / "w.json", PlannedTrajectory(SPLINE, ((0.1, 0.5), (0.8, 1.0))))
    return (tmp_path / "w.json").read_text()


def test_version_1_is_read(tmp_path: Path) -> None:
    legacy = {
        "format": "skyquill-bspline",
        "version": 1,
        "degree": 5,
        "duration_s": 2.0,
        "control_points": SPLINE.control_points.tolist(),
        "pen_windows_s": [[0.0, 1.0]],
    }
    (tmp_path / "old.json").write_text(json.dumps(legacy))
    back = read_trajectory_json(tmp_path / "old.json")
    assert isinstance(back.trajectory, SplineTrajectory) and back.pen_windows_s == ((0.0, 1.0),)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("{", "got malformed JSON at line 1, column 2"),
        ("[" * 100_000 + "]" * 100_000, "nested too deeply"),
        ('{"format": "other"}', "got format 'other'"),
        ('{"format": "skyquill-trajectory", "trajectory": {"kind": "x"}}', "kind: got 'x'"),
        ('{"format": "skyquill-trajectory", "trajectory": {}, "limits": {}}', "limits: got a JSON"),
    ],
)
def test_malformed_files_are_named(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "bad.json"
    path.write_text(text)
    with pytest.raises(InputError, match=message):
        read_trajectory_json(path)


def test_bad_limits_and_windows_are_named(tmp_path: Path) -> None:
    good = json.loads(json.dumps({"format": "skyquill-trajectory", "version": 2}))
    good["trajectory"] = {"kind": "bspline", "degree": 5, "duration_s": 2.0,
                          "control_points": SPLINE.control_points.tolist()}  # fmt: skip
    for field, value, message in (
        ("limits", [{"type": "Magic"}], "expected one of"),
        ("limits", [{"type": "BoxLimit", "order": 1}], "expected"),
        ("pen_windows_s", [[1.0, 0.5]], "overlapping or reversed"),
    ):
        (tmp_path / "x.json").write_text(json.dumps(good | {field: value}))
        with pytest.raises(InputError, match=message):
            read_trajectory_json(tmp_path / "x.json")


def _v2(trajectory: object, **extra: object) -> str:
    return json.dumps(
        {"format": "skyquill-trajectory", "version": 2, "trajectory": trajectory, **extra}
    )


_CTRL = SPLINE.control_points.tolist()


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            _v2(
                {
                    "kind": "bspline",
                    "degree": 5,
                    "duration_s": 2.0,
                    "control_points": [*_CTRL, [1, 2]],
                }
            ),
            r"bad\.json: trajectory 'bspline', field 'control_points': got a ragged or non-numeric",
        ),
        (
            _v2(
                {
                    "kind": "bspline",
                    "degree": 5,
                    "duration_s": 2.0,
                    "control_points": [[str(v) for v in row] for row in _CTRL],
                }
            ),
            r"field 'control_points': got a ragged or non-numeric array",
        ),
        (
            _v2({"kind": "sampled", "t": [0, 1], "p": [[0, 0, 0], [1, 1]]}),
            r"trajectory 'sampled', field 'p': got a ragged or non-numeric",
        ),
        (
            _v2(
                {"kind": "bspline", "degree": 5, "duration_s": 2.0, "control_points": _CTRL},
                pen_windows_s=[[0, 1], [1]],
            ),
            r"bad\.json: pen_windows_s: got \[\[0, 1\], \[1\]\], expected a rectangular array",
        ),
        (
            '{"format": "skyquill-trajectory", "trajectory": ' + "[" * 70 + "]" * 70 + "}",
            r"bad\.json: got JSON nested more than 64",
        ),
        ("\ufeff{", r"bad\.json: got malformed JSON at line 1, column 2"),
    ],
)
def test_ragged_strings_and_deep_are_named(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "bad.json"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(InputError, match=message):
        read_trajectory_json(path)


def test_utf16_is_named(tmp_path: Path) -> None:
    path = tmp_path / "u.json"
    path.write_bytes('{"format": "skyquill-trajectory"}'.encode("utf-16"))
    with pytest.raises(InputError, match=r"u\.json: got UTF-16 text"):
        read_trajectory_json(path)


_leaf = st.one_of(st.floats(), st.integers(-(10**20), 10**20), st.text(max_size=3), st.none())
_value = st.recursive(_leaf, lambda inner: st.lists(inner, max_size=4), max_leaves=20)
_trajectory = st.fixed_dictionaries(
    {"kind": st.sampled_from(["bspline", "polynomial", "sampled", "retimed", "sequence", "x"])},
    optional={
        key: _value
        for key in (
            "degree",
            "duration_s",
            "control_points",
            "t",
            "p",
            "v",
            "a",
            "j",
            "breaks",
            "coefficients",
            "pieces",
            "knots",
        )
    },
)


@settings(max_examples=200, deadline=None)
@given(
    trajectory=st.one_of(_trajectory, _value),
    windows=_value,
    limits=st.one_of(_value, st.lists(st.dictionaries(st.sampled_from(["type", "order"]), _leaf))),
)
def test_random_documents_give_a_trajectory_or_an_input_error(
    trajectory: object, windows: object, limits: object
) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "r.json"
        path.write_text(_v2(trajectory, pen_windows_s=windows, limits=limits), encoding="utf-8")
        try:
            read_trajectory_json(path)
        except InputError as exc:
            assert str(exc).startswith("r.json: ")


@settings(max_examples=100, deadline=None)
@given(raw=st.binary(max_size=60))
def test_random_bytes_give_an_input_error(raw: bytes) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "raw.json"
        path.write_bytes(raw)
        with pytest.raises(InputError, match=r"^raw\.json: "):
            read_trajectory_json(path)
