"""Skybrush Studio's zipped CSV: round trip, and every corruption an InputError naming where."""

from __future__ import annotations

import tempfile
import zipfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.export.skybrush import csv_file as skybrush_csv
from skyquill.export.skybrush.csv_file import HEADER, CsvDrone, read_csv_zip, write_csv_zip


def drone(name: str = "d1", n: int = 50) -> CsvDrone:
    t = np.arange(n, dtype=np.int64) * 10
    p = np.column_stack([np.sin(t / 300), np.cos(t / 300), 1 + t / 1e4])
    c = np.where((t >= 100)[:, None] & (t <= 200)[:, None], [255, 40, 0], 0).astype(np.int64)
    return CsvDrone(name, t, p, c)


def test_round_trip_to_the_micrometre(tmp_path: Path) -> None:
    drones = [drone("d1"), drone("d2", 30)]
    path = write_csv_zip(drones, tmp_path / "show.zip")
    with zipfile.ZipFile(path) as archive:
        assert archive.namelist() == ["d1.csv", "d2.csv"]
        assert archive.read("d1.csv").decode().splitlines()[0] == ",".join(HEADER)
    back = read_csv_zip(path)
    for a, b in zip(drones, back, strict=True):
        assert a.name == b.name and np.array_equal(a.t_ms, b.t_ms)
        assert np.abs(a.positions - b.positions).max() <= 5e-7
        assert np.array_equal(a.colors, b.colors)
    # Studio interpolates linearly between rows
    traj = back[0].trajectory()
    np.testing.assert_allclose(
        traj.evaluate(np.array([0.015])), [(back[0].positions[1] + back[0].positions[2]) / 2]
    )


def _zip(path: Path, members: dict[str, bytes]) -> Path:
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    return path


GOOD = b"Time_msec,x_m,y_m,z_m,Red,Green,Blue\n0,0,0,1,0,0,0\n10,0.1,0,1,255,0,0\n"


@pytest.mark.parametrize(
    ("members", "match"),
    [
        ({}, r"s.zip: got 0 member\(s\), expected 1 to 5000"),
        ({"a.txt": GOOD}, r"got the member 'a.txt', expected only .csv files"),
        ({"a.csv": GOOD, "x/a.csv": GOOD}, r"got repeated drone names"),
        (
            {"a.csv": b"time,x,y,z\n0,0,0,0\n1,0,0,0\n"},
            r"a.csv: got the header \['time', 'x', 'y', 'z'\]",
        ),
        ({"a.csv": GOOD + b"20,0.2,0,1,255\n"}, r"a.csv: line 4: got 5 values, expected 7"),
        (
            {"a.csv": GOOD + b"20,nan,0,1,0,0,0\n"},
            r"line 4: got \['20', 'nan', '0', '1', '0', '0', '0'\], expected numbers",
        ),
        ({"a.csv": GOOD + b"20,1e9,0,1,0,0,0\n"}, r"expected finite numbers within 100000 m"),
        (
            {"a.csv": GOOD + b"5,0.2,0,1,0,0,0\n"},
            r"line 4: got Time_msec 5 after 10, expected strictly",
        ),
        (
            {"a.csv": GOOD + b"10.5,0.2,0,1,0,0,0\n"},
            r"Time_msec: got '10.5', expected a whole number",
        ),
        ({"a.csv": GOOD + b"20,0.2,0,1,256,0,0\n"}, r"Red, Green, Blue = \['256', '0', '0'\]"),
        ({"a.csv": GOOD + b"20,0.2,0,1,1.5,0,0\n"}, r"line 4: got .*expected numbers"),
        ({"a.csv": GOOD + "20,0.2,0,1,0,0,0 é\n".encode()}, r"a.csv: got a non-ASCII byte"),
        (
            {"a.csv": GOOD.splitlines(keepends=True)[0] + b"0,0,0,1,0,0,0\n"},
            r"got 1 row\(s\), expected at least 2",
        ),
    ],
)
def test_a_corrupt_archive_is_named(tmp_path: Path, members: dict[str, bytes], match: str) -> None:
    with pytest.raises(InputError, match=match):
        read_csv_zip(_zip(tmp_path / "s.zip", members))


def test_not_a_zip_missing_or_truncated(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"expected an existing .zip file"):
        read_csv_zip(tmp_path / "none.zip")
    (tmp_path / "n.zip").write_text("hello", encoding="utf-8")
    with pytest.raises(InputError, match=r"n.zip: got a file that is not a ZIP"):
        read_csv_zip(tmp_path / "n.zip")
    whole = _zip(tmp_path / "t.zip", {"a.csv": GOOD * 200}).read_bytes()
    (tmp_path / "t.zip").write_bytes(whole[: len(whole) // 2])  # cut: the directory is gone
    with pytest.raises(InputError, match=r"t.zip: "):
        read_csv_zip(tmp_path / "t.zip")


def test_a_zip_bomb_is_refused_before_inflating(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(skybrush_csv, "MAX_MEMBER_BYTES", 10_000)
    bomb = _zip(tmp_path / "b.zip", {"a.csv": GOOD + b"\n" * 1_000_000})
    assert bomb.stat().st_size < 10_000
    with pytest.raises(
        InputError, match=r"b.zip: a.csv: got 1,000,0\d\d bytes, expected at most 10,000"
    ):
        read_csv_zip(bomb)


def test_bad_drones_are_refused_on_writing(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"drones: got nothing"):
        write_csv_zip([], tmp_path / "x.zip")
    with pytest.raises(InputError, match=r"drones: got the name '../x'"):
        write_csv_zip([drone("../x")], tmp_path / "x.zip")
    with pytest.raises(InputError, match=r"drones: got repeated names"):
        write_csv_zip([drone(), drone()], tmp_path / "x.zip")


def test_a_carriage_return_the_csv_reader_refuses_is_an_input_error(tmp_path: Path) -> None:
    """Found by the hypothesis test below: ``csv`` raises its own error on ``b'\\r\\x00'``."""
    path = tmp_path / "r.zip"
    _zip(path, {"a.csv": b"\r\x00"})
    with pytest.raises(InputError, match=r"r\.zip: a\.csv: got text the CSV reader refuses"):
        read_csv_zip(path)


@settings(max_examples=100, deadline=None)
@given(raw=st.binary(max_size=120), zipped=st.booleans())
def test_random_bytes_give_an_input_error(raw: bytes, zipped: bool) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "r.zip"
        if zipped:
            _zip(path, {"a.csv": raw})
        else:
            path.write_bytes(b"PK\x03\x04" + raw)
        with pytest.raises(InputError, match=r"r\.zip"):
            read_csv_zip(path)


ROW_VALUES = st.one_of(
    st.integers(-(2**60), 2**60).map(str),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.sampled_from(["", " 1", "1e3", "0x10", "256", "-1", "1.", ".5", "1_0", "nan"]),
)


@given(
    edits=st.lists(st.tuples(st.integers(0, 5), st.integers(0, 6), ROW_VALUES), max_size=3),
    blank=st.booleans(),
    crlf=st.booleans(),
)
@settings(max_examples=150, deadline=None)
def test_the_fast_reader_reads_what_the_row_by_row_reader_reads(
    edits: list[tuple[int, int, str]], blank: bool, crlf: bool
) -> None:
    """The numpy path (a file as written) and the row-by-row path agree on any member: the same
    columns where both read it; where the fast path declines, the checked path decides."""
    rows = [line.split(",") for line in skybrush_csv._csv_text(drone(n=6)).splitlines()]
    for row, column, value in edits:
        rows[1 + row][column] = value
    lines = [",".join(r) for r in rows]
    if blank:
        lines.insert(3, "")
    text = ("\r\n" if crlf else "\n").join(lines) + "\n"
    fast = skybrush_csv._plain_columns(text)
    try:
        checked = skybrush_csv._checked_drone("show.zip: d1.csv", "d1.csv", text)
    except InputError:
        assert fast is None
        return
    if fast is not None:
        t, positions, colors = fast
        assert np.array_equal(t, checked.t_ms) and np.array_equal(colors, checked.colors)
        assert np.array_equal(positions, checked.positions)


@given(
    st.lists(
        st.tuples(
            st.integers(-(2**53), 2**53),
            st.floats(-1e5, 1e5),
            st.floats(-1e5, 1e5),
            st.floats(-1e5, 1e5),
            st.integers(0, 255),
            st.integers(0, 255),
            st.integers(0, 255),
        ),
        min_size=1,
        max_size=20,
    )
)
@settings(max_examples=100, deadline=None)
def test_the_rows_formatted_at_once_are_the_rows_formatted_one_by_one(
    rows: list[tuple[int, float, float, float, int, int, int]],
) -> None:
    """One ``%`` call for all rows writes what formatting each row with an f-string writes."""
    table = np.array(rows, dtype=object)
    one = CsvDrone(
        "d",
        table[:, 0].astype(np.int64),
        table[:, 1:4].astype(float),
        table[:, 4:].astype(np.int64),
    )
    by_row = "".join(f"{t},{x:.6f},{y:.6f},{z:.6f},{r},{g},{b}\n" for t, x, y, z, r, g, b in rows)
    assert skybrush_csv._csv_text(one) == ",".join(HEADER) + "\n" + by_row
