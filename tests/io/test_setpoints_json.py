"""Setpoints JSON: round trip and validation."""

from __future__ import annotations

import json
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.io.points import TRAJECTORY_COLUMNS, trajectory_table
from skyquill.io.setpoints_json import FRAME, read_setpoints_json, write_setpoints_json
from skyquill.trajectory import SplineTrajectory


def spline(dim: int = 3) -> SplineTrajectory:
    ctrl = np.random.default_rng(3).uniform(-0.5, 0.5, (12, dim))
    return SplineTrajectory(ctrl, 5, 4.0)


def test_round_trip(tmp_path: Path) -> None:
    traj = spline()
    path = tmp_path / "sp.json"
    n = write_setpoints_json(traj, path, 25.0)
    data = json.loads(path.read_text(encoding="utf-8"))
    assert data["frame"] == FRAME
    assert data["rate_hz"] == 25.0
    assert data["columns"] == list(TRAJECTORY_COLUMNS)
    assert len(data["rows"]) == n == 101
    back = read_setpoints_json(path)
    assert back.rate_hz == 25.0
    table = trajectory_table(traj, 25.0)
    got = back.trajectory
    assert got.j is not None
    np.testing.assert_array_equal(np.column_stack([got.t, got.p, got.v, got.a, got.j]), table)
    assert got.duration == pytest.approx(traj.duration)


def test_2d_gets_z_zero(tmp_path: Path) -> None:
    path = tmp_path / "flat.json"
    write_setpoints_json(spline(dim=2), path, 10.0)
    back = read_setpoints_json(path).trajectory
    assert np.all(back.p[:, 2] == 0.0)


def test_any_rate(tmp_path: Path) -> None:
    path = tmp_path / "sp.json"
    assert write_setpoints_json(spline(), path, 3.0) == 13  # 0, 1/3, ..., 4 s
    assert read_setpoints_json(path).rate_hz == 3.0


def test_bad_rate_on_write(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="rate: got -1, expected a number > 0"):
        write_setpoints_json(spline(), tmp_path / "x.json", -1.0)


def good(tmp_path: Path) -> dict[str, Any]:
    path = tmp_path / "good.json"
    write_setpoints_json(spline(), path, 5.0)
    data: dict[str, Any] = json.loads(path.read_text(encoding="utf-8"))
    return data


def write(tmp_path: Path, data: Any) -> Path:
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    return path


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"frame": "NED"}, r"bad.json: frame: got 'NED', expected 'world ENU z-up, SI'"),
        ({"columns": ["t", "x"]}, r"bad.json: columns: got \['t', 'x'\]"),
        ({"rate_hz": 0}, r"bad.json: rate_hz: got 0, expected a number > 0"),
        ({"rate_hz": "fast"}, r"rate_hz: got 'fast'"),
        ({"rows": []}, r"rows: got 0 row\(s\), expected a list of 2 to 1,000,000 rows"),
        ({"rows": "none"}, r"rows: got 'none'"),
    ],
)
def test_bad_fields(tmp_path: Path, change: dict[str, Any], match: str) -> None:
    with pytest.raises(InputError, match=match):
        read_setpoints_json(write(tmp_path, {**good(tmp_path), **change}))


def test_bad_rows(tmp_path: Path) -> None:
    data = good(tmp_path)
    data["rows"][2] = data["rows"][2][:5]
    with pytest.raises(InputError, match=r"rows\[2\]: got .*expected a list of 13 numbers"):
        read_setpoints_json(write(tmp_path, data))
    data = good(tmp_path)
    data["rows"][3][2] = None
    with pytest.raises(InputError, match=r"rows\[3\] column y: got None, expected a finite"):
        read_setpoints_json(write(tmp_path, data))
    data = good(tmp_path)
    data["rows"][1][0] = data["rows"][0][0]
    with pytest.raises(InputError, match=r"rows\[1\] column t: got 0 after 0"):
        read_setpoints_json(write(tmp_path, data))


def test_bad_files(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="expected an existing JSON file"):
        read_setpoints_json(tmp_path / "missing.json")
    path = tmp_path / "text.json"
    path.write_text("not json", encoding="utf-8")
    with pytest.raises(InputError, match=r"text\.json: got malformed JSON at line 1, column 1"):
        read_setpoints_json(path)
    with pytest.raises(InputError, match="got list, expected a JSON object"):
        read_setpoints_json(write(tmp_path, [1, 2]))


def test_strings_and_ragged_rows_are_named(tmp_path: Path) -> None:
    data = good(tmp_path)
    data["rows"][1][3] = "0.5"
    with pytest.raises(InputError, match=r"bad\.json: rows\[1\] column z: got '0.5', expected a"):
        read_setpoints_json(write(tmp_path, data))
    data = good(tmp_path)
    data["rows"][4] = [*data["rows"][4], 1.0]
    with pytest.raises(InputError, match=r"bad\.json: rows\[4\]: got .*expected a list of 13"):
        read_setpoints_json(write(tmp_path, data))


def test_deep_and_undecodable_files_are_named(tmp_path: Path) -> None:
    path = tmp_path / "deep.json"
    path.write_text('{"rows": ' + "[" * 100_000 + "]" * 100_000 + "}", encoding="utf-8")
    with pytest.raises(InputError, match=r"^deep\.json: got JSON nested too deeply"):
        read_setpoints_json(path)
    data = good(tmp_path)
    data["rows"][0] = _nest(70)
    with pytest.raises(InputError, match=r"^bad\.json: got JSON nested more than 64"):
        read_setpoints_json(write(tmp_path, data))
    path.write_bytes(json.dumps(good(tmp_path)).encode("utf-16"))
    with pytest.raises(InputError, match=r"^deep\.json: got UTF-16 text"):
        read_setpoints_json(path)


def _nest(depth: int) -> Any:
    value: Any = []
    for _ in range(depth):
        value = [value]
    return value


_cell = st.one_of(
    st.floats(), st.integers(-(10**20), 10**20), st.text(max_size=3), st.none(), st.booleans()
)
_row = st.one_of(
    st.lists(st.floats(-10, 10), min_size=13, max_size=13), st.lists(_cell, max_size=14)
)


@settings(max_examples=150, deadline=None)
@given(rows=st.lists(_row, max_size=5), rate=_cell)
def test_random_rows_give_setpoints_or_an_input_error(rows: list[Any], rate: Any) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        doc = {"frame": FRAME, "rate_hz": rate, "columns": list(TRAJECTORY_COLUMNS), "rows": rows}
        path = Path(tmp) / "r.json"
        path.write_text(json.dumps(doc), encoding="utf-8")
        try:
            back = read_setpoints_json(path)
        except InputError as exc:
            assert str(exc).startswith("r.json: ")
            return
    assert back.rate_hz > 0 and back.trajectory.t.shape == (len(rows),)


@settings(max_examples=100, deadline=None)
@given(raw=st.binary(max_size=60))
def test_random_bytes_give_an_input_error(raw: bytes) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "raw.json"
        path.write_bytes(raw)
        with pytest.raises(InputError, match=r"^raw\.json: "):
            read_setpoints_json(path)
