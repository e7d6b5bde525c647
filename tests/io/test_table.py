"""The one CSV table reader: what it reads, and every refusal with its message."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.io import table as table_module
from skyquill.io.table import MAX_ROWS, read_table


def write(tmp_path: Path, data: str | bytes, name: str = "t.csv") -> Path:
    path = tmp_path / name
    if isinstance(data, str):
        path.write_text(data, encoding="utf-8")
    else:
        path.write_bytes(data)
    return path


def test_reads_required_then_present_optional_columns_in_callers_order(tmp_path: Path) -> None:
    path = write(tmp_path, " T ,note, X ,y\n0,a,1,2\n\n  ,  \n0.5,b,3,4\n")
    table = read_table(path, required=("x", "y"), optional=("z", "t"))
    assert table.name == "t.csv"
    assert table.columns == ("x", "y", "t")
    np.testing.assert_array_equal(table.data, [[1, 2, 0], [3, 4, 0.5]])
    np.testing.assert_array_equal(table.lines, [2, 5])
    assert table.n_rows == 2 and table.has("t") and not table.has("z")
    np.testing.assert_array_equal(table.column("t"), [0.0, 0.5])
    np.testing.assert_array_equal(table.select(("t", "x")), [[0, 1], [0.5, 3]])
    assert not table.data.flags.writeable
    with pytest.raises(InputError, match=r"t.csv: got no column.s. z, expected one of x,y,t"):
        table.column("z")


def test_utf8_byte_order_mark_is_accepted(tmp_path: Path) -> None:
    # Excel's "CSV UTF-8" starts with EF BB BF: without utf-8-sig the header would be "\ufeffx".
    path = write(tmp_path, "\ufeffx,y\n1,2\n".encode())
    assert read_table(path, required=("x", "y")).columns == ("x", "y")


def test_header_only_gives_an_empty_table(tmp_path: Path) -> None:
    table = read_table(write(tmp_path, "x,y\n"), required=("x", "y"))
    assert table.data.shape == (0, 2) and table.lines.shape == (0,)


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ("", "t.csv: got an empty file, expected a header line with columns x,y"),
        ("\n \n,\n", "t.csv: got an empty file"),
        ("x,y,x\n1,2,3\n", "t.csv: got column.s. 'x' more than once, expected each column once"),
        ("X, x ,y\n1,2,3\n", "got column.s. 'x' more than once"),
        ("x,y,,\n1,2,,\n", "got column.s. '' more than once"),
        (
            "a,b\n1,2\n",
            r"t.csv: got columns \['a', 'b'\], expected columns x,y \(optionally z; other "
            r"columns ignored\); missing x,y",
        ),
        ("x,z\n1,2\n", "missing y$"),
        ("x,y\n1,2\n3,oops\n", "t.csv line 3, column y: got 'oops', expected a number"),
        ("x,y\n1,2\n,4\n", "t.csv line 3, column x: got '', expected a number"),
        ("x,y\n1,nan\n", "t.csv line 2, column y: got 'nan', expected a finite number"),
        ("x,y\n1,-inf\n", "line 2, column y: got '-inf', expected a finite number"),
        ("x,y\n1,1e999\n", "line 2, column y: got '1e999', expected a finite number"),
        ("x,y\n1,2\n3\n", "t.csv line 3: got 1 columns, expected 2 .one per header column."),
        ("x,y\n1,2,3\n", "t.csv line 2: got 3 columns, expected 2"),
        ("x,y\n1,2\n\n\n4,5,\n", "t.csv line 5: got 3 columns, expected 2"),
        ('x,y\n"1,2\n', "t.csv line 2: got 1 columns, expected 2"),
        ("x,y\n1," + "9" * 200 + "x\n", "column y: got '9999.*\\.\\.\\.', expected a number"),
    ],
)
def test_bad_text_is_refused_naming_file_line_and_column(
    tmp_path: Path, data: str, message: str
) -> None:
    with pytest.raises(InputError, match=message):
        read_table(write(tmp_path, data), required=("x", "y"), optional=("z",))


def test_strings_in_ignored_columns_are_fine_but_not_in_read_ones(tmp_path: Path) -> None:
    path = write(tmp_path, "x,name\n1,alpha\n")
    assert read_table(path, required=("x",)).data.tolist() == [[1.0]]
    with pytest.raises(InputError, match=r"line 2, column name: got 'alpha', expected a number"):
        read_table(path, required=("x",), optional=("name",))


def test_unknown_columns_refused_when_asked(tmp_path: Path) -> None:
    path = write(tmp_path, "x,y,note\n1,2,3\n")
    with pytest.raises(
        InputError, match=r"t.csv: got unknown column.s. 'note', expected only x,y,z"
    ):
        read_table(path, required=("x", "y"), optional=("z",), unknown="refuse")


def test_utf16_and_binary_are_named_not_unicode_errors(tmp_path: Path) -> None:
    utf16 = write(tmp_path, "x,y\n1,2\n".encode("utf-16"), "u16.csv")
    with pytest.raises(InputError, match=r"u16.csv: got bytes that are not UTF-8 .a UTF-16 byte"):
        read_table(utf16, required=("x", "y"))
    # UTF-16 without a byte-order mark decodes as UTF-8 with NULs between the letters.
    bare = write(tmp_path, "x,y\n1,2\n".encode("utf-16-le"), "u16le.csv")
    with pytest.raises(InputError, match=r"u16le.csv: got a NUL character .binary data or UTF-16"):
        read_table(bare, required=("x", "y"))
    binary = write(tmp_path, b"x,y\n1,2\n" + bytes(range(128, 256)), "bin.csv")
    with pytest.raises(InputError, match=r"bin.csv: got bytes that are not UTF-8 .byte.s. 80 81"):
        read_table(binary, required=("x", "y"))
    latin1 = write(tmp_path, "x,y\n1,2\n# café\n".encode("latin-1"), "latin.csv")
    with pytest.raises(InputError, match=r"latin.csv: got bytes that are not UTF-8"):
        read_table(latin1, required=("x", "y"))


def test_missing_file_and_directory(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"points file: got '.*nope.csv', expected an existing"):
        read_table(tmp_path / "nope.csv", required=("x",), name="points file")
    with pytest.raises(InputError, match=r"got a folder, expected a CSV file \(a regular file\)"):
        read_table(tmp_path, required=("x",))


def test_a_named_pipe_is_refused_without_blocking(tmp_path: Path) -> None:
    pipe = tmp_path / "pipe.csv"
    os.mkfifo(pipe)
    with pytest.raises(InputError, match=r"pipe.csv: got a named pipe, expected a CSV file"):
        read_table(pipe, required=("x",))


@pytest.mark.parametrize(
    "cell", ["1_0", "٠.١", "０.５", "0x10", "1,5", "½", "²", "1e", "--1", "Infinity"]
)
def test_numbers_are_plain_ascii_decimals(tmp_path: Path, cell: str) -> None:
    path = write(tmp_path, f'x,y\n0,0\n"{cell}",1\n')
    with pytest.raises(InputError, match=r"t.csv line 3, column x: got .*, expected a"):
        read_table(path, required=("x", "y"))


def test_row_counts_are_bounded(tmp_path: Path) -> None:
    assert MAX_ROWS == 1_000_000
    path = write(tmp_path, "x\n" + "1\n" * 5)
    assert read_table(path, required=("x",), max_rows=5).n_rows == 5
    with pytest.raises(
        InputError, match=r"t.csv line 6: got more than 4 data rows, expected at most 4"
    ):
        read_table(path, required=("x",), max_rows=4)
    with pytest.raises(InputError, match=r"t.csv: got 5 data row\(s\), expected at least 6"):
        read_table(path, required=("x",), min_rows=6)


def test_huge_files_and_lines_are_refused_before_being_read(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    one_line = write(tmp_path, "x," + "1" * 200_000 + "\n")
    with pytest.raises(InputError, match=r"t.csv: got a line longer than 100000 characters"):
        read_table(one_line, required=("x",))
    monkeypatch.setattr(table_module, "MAX_BYTES", 100)
    big = write(tmp_path, "x\n" + "1\n" * 60, "big.csv")
    with pytest.raises(InputError, match=r"big.csv: got 122 bytes, expected a CSV file of at most"):
        read_table(big, required=("x",))


def check_outcome(path: Path) -> None:
    """Only a named InputError or a finite table of the asked shape may come out."""
    try:
        table = read_table(path, required=("x", "y"), optional=("t",))
    except InputError as exc:
        assert str(exc)
        return
    assert table.columns[:2] == ("x", "y")
    assert table.data.shape == (table.n_rows, len(table.columns))
    assert table.lines.shape == (table.n_rows,)
    assert np.all(np.isfinite(table.data))


@settings(max_examples=200, deadline=None)
@given(st.binary(max_size=300))
def test_random_bytes_give_input_error_or_a_table(data: bytes) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "r.csv"
        path.write_bytes(b"x,y,t\n" + data)
        check_outcome(path)


CELL = st.one_of(
    st.sampled_from(["1", "-2.5", "1e308", "nan", "inf", "", " ", '"', "x", "\x00", "1_0"]),
    st.text(max_size=5),
)


@settings(max_examples=200, deadline=None)
@given(
    header=st.sampled_from(["x,y", "y,x,t", "X, Y ,T,note", "x,x,y", "a", "\ufeffx,y"]),
    rows=st.lists(st.lists(CELL, max_size=5).map(",".join), max_size=6),
    encoding=st.sampled_from(["utf-8", "utf-8-sig", "utf-16"]),
)
def test_random_text_gives_input_error_or_a_table(
    header: str, rows: list[str], encoding: str
) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "r.csv"
        path.write_bytes("\n".join([header, *rows]).encode(encoding, errors="surrogatepass"))
        check_outcome(path)


PLAIN_CELL = st.one_of(
    st.text(alphabet="0123456789eE.+- \t", max_size=8),
    st.floats(allow_nan=False, allow_infinity=False).map(repr),
    st.floats(allow_nan=False, allow_infinity=False).map(lambda v: f"{v:.9g}"),
    st.sampled_from(["1e400", "-1e999", "", " ", "1,", "\r"]),
)


@settings(max_examples=300, deadline=None)
@given(
    header=st.sampled_from(["x,y", "y,x,t", "X, Y ,T,note", "x,x,y", "a", '"x",y']),
    rows=st.lists(st.lists(PLAIN_CELL, min_size=1, max_size=5).map(",".join), max_size=6),
    end=st.sampled_from(["", "\n", "\n\n"]),
)
def test_the_one_call_reading_is_the_row_by_row_reading(
    header: str, rows: list[str], end: str
) -> None:
    """A file the one NumPy call reads gives the table the row-by-row reader gives, bit for
    bit, or the same refusal (the one call leaves everything else to the row reader)."""
    lines = ("\n".join([header, *rows]) + end).splitlines(keepends=True)
    wanted = table_module._Wanted(("x", "y"), ("t",), "ignore")

    def outcome(read: Any) -> Any:
        try:
            return read()
        except InputError as exc:
            return str(exc)

    plain = outcome(lambda: table_module._parse_plain("r.csv", lines, wanted, 0))
    if plain is None:
        return
    rows_read = outcome(lambda: table_module._parse_rows("r.csv", iter(lines), wanted, 0, 10))
    if isinstance(plain, str):
        assert plain == rows_read
        return
    assert rows_read.columns == plain.columns
    assert rows_read.data.tobytes() == plain.data.tobytes()
    np.testing.assert_array_equal(rows_read.lines, plain.lines)
    assert not plain.data.flags.writeable


def test_a_plain_file_is_read_in_one_call_and_anything_else_row_by_row(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    calls: list[str] = []
    rows = table_module._parse_rows
    monkeypatch.setattr(table_module, "_parse_rows", lambda *a: calls.append("rows") or rows(*a))
    plain = write(tmp_path, "t,x,y\n0,1.5,-2e-3\n0.1, 2 ,\t3\n", "plain.csv")
    table = read_table(plain, required=("x", "y"), optional=("t",))
    np.testing.assert_array_equal(table.data, [[1.5, -2e-3, 0.0], [2.0, 3.0, 0.1]])
    np.testing.assert_array_equal(table.lines, [2, 3])
    assert calls == []
    for text in ("t,x,y\n0,1,2\n\n0,1,2\n", 't,x,y\n0,"1",2\n', "t,x,y\r\n0,1,2\r\n"):
        read_table(write(tmp_path, text, "other.csv"), required=("x", "y"))
    assert calls == ["rows"] * 3
