"""Read a numeric CSV table: one reader, one set of refusals, for every CSV skyquill takes.

The first non-blank line is the header (names stripped and lower-cased, so ``" X "`` is
``x``); every later non-blank line is a row with one cell per header column. The caller
names the columns it needs (``required``), the ones it takes when present (``optional``)
and whether other columns are ignored or refused; only those columns are parsed, as
finite floats written as plain ASCII decimal literals (:mod:`skyquill.io.numbers`: not
``1_0``, ``٠.١`` or ``０.５``, which Python's ``float()`` would take). The file is opened
by :mod:`skyquill.io.source` (a regular file: a named pipe or a device is refused) and
is UTF-8, with or without the byte-order mark spreadsheets write.

Everything else is an :class:`~skyquill.errors.InputError` naming the file (and the line
and column where there is one): a missing file, bytes that are not UTF-8 (UTF-16, binary),
an empty file, a repeated or missing column, an unknown column when refused, a row with
the wrong number of cells, a cell that is not a finite number, or a file too large: more
than :data:`MAX_BYTES` bytes (refused before reading), a line longer than
:data:`MAX_LINE_CHARS` or more than :data:`MAX_ROWS` rows (refused as soon as the first
character or row too many is read, so a huge file is never read whole).
"""

from __future__ import annotations

import csv
import io
import re
from array import array
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from itertools import chain, islice
from pathlib import Path
from typing import Any, Literal, TextIO

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.io.numbers import MAX_CHARS, parse_number
from skyquill.io.source import open_text
from skyquill.validation import FloatArray

#: Most data rows one CSV may hold: 1,000,000 rows is 2.8 h of a 100 Hz trajectory and
#: ~100 MB of text; a larger file is refused before it is read whole.
MAX_ROWS = 1_000_000

#: Largest file accepted, bytes (512 MiB): checked before anything is read.
MAX_BYTES = 512 * 2**20
#: Longest line accepted, characters: a file without line breaks is refused after this
#: many characters instead of being read whole into one line.
MAX_LINE_CHARS = 100_000

#: What to do with columns that are neither required nor optional.
Unknown = Literal["ignore", "refuse"]


@dataclass(frozen=True)
class Table:
    """The numeric columns of a CSV file.

    Attributes
    ----------
    name
        The file's name, for messages (``"points.csv"``).
    columns
        The columns read, in the caller's order: every required column, then the optional
        ones the file has.
    data
        Values, shape (N, len(columns)), finite floats in the file's units; read-only.
    lines
        Line number in the file of each row, shape (N,) (1 is the header's line when the
        file starts with it), for messages about a row.
    """

    name: str
    columns: tuple[str, ...]
    data: FloatArray
    lines: NDArray[np.int64]

    @property
    def n_rows(self) -> int:
        """Number of data rows N."""
        return int(self.data.shape[0])

    def has(self, column: str) -> bool:
        """Whether ``column`` was read (a required one, or an optional one present)."""
        return column in self.columns

    def column(self, column: str) -> FloatArray:
        """The values of ``column``, shape (N,); InputError if it was not read."""
        return self.select([column])[:, 0]

    def select(self, columns: Sequence[str]) -> FloatArray:
        """The values of ``columns`` in that order, shape (N, len(columns))."""
        absent = [c for c in columns if c not in self.columns]
        if absent:
            raise InputError(
                f"{self.name}: got no column(s) {','.join(absent)}, expected one of "
                f"{','.join(self.columns)}"
            )
        return self.data[:, [self.columns.index(c) for c in columns]]


def read_table(
    path: str | Path,
    *,
    required: Sequence[str],
    optional: Sequence[str] = (),
    unknown: Unknown = "ignore",
    min_rows: int = 0,
    max_rows: int = MAX_ROWS,
    name: str = "csv file",
) -> Table:
    """Read the numeric columns ``required`` (+ ``optional``) of the CSV file ``path``.

    Parameters
    ----------
    path
        The CSV file (UTF-8, an optional byte-order mark, ``,`` separated, a header line).
    required
        Lower-case column names the file must have.
    optional
        Lower-case column names read when the file has them.
    unknown
        ``"ignore"``: other columns are skipped (and may hold anything);
        ``"refuse"``: another column is an error.
    min_rows
        Fewest data rows accepted.
    max_rows
        Most data rows accepted (default :data:`MAX_ROWS`).
    name
        What the file is to the caller (``"points file"``), for the message when it does
        not exist; other messages name the file itself.

    Returns
    -------
    Table
        The columns read, shape (N, k), and each row's line number.

    Raises
    ------
    InputError
        See the module docstring; the message names the file and says what came and what
        was expected.
    """
    file = Path(path)
    if not file.exists():
        raise InputError(f"{name}: got {str(file)!r}, expected an existing CSV file")
    wanted = _Wanted(tuple(required), tuple(optional), unknown)
    try:
        with open_text(file, "a CSV file", max_bytes=MAX_BYTES, name=file.name) as handle:
            return _parse(file.name, _lines(file.name, handle), wanted, min_rows, max_rows)
    except UnicodeDecodeError as exc:
        raise InputError(
            f"{file.name}: got bytes that are not UTF-8 ({_describe_bytes(exc)}), "
            "expected UTF-8 text (save the CSV as 'CSV UTF-8')"
        ) from None
    except OSError as exc:
        raise InputError(
            f"{file.name}: got a file that cannot be read ({exc.strerror}), expected a CSV file"
        ) from None


@dataclass(frozen=True)
class _Wanted:
    required: tuple[str, ...]
    optional: tuple[str, ...]
    unknown: Unknown

    def describe(self) -> str:
        """The expected columns, in words."""
        text = f"columns {','.join(self.required)}"
        notes = []
        if self.optional:
            notes.append(f"optionally {','.join(self.optional)}")
        if self.unknown == "ignore":
            notes.append("other columns ignored")
        return text + (f" ({'; '.join(notes)})" if notes else "")


def _parse(name: str, text: Iterator[str], wanted: _Wanted, min_rows: int, max_rows: int) -> Table:
    """Header, then the rows; stops at the first refusal."""
    # At most a header and max_rows lines are held at once: a longer file is read row by row
    # and refused at its first row too many.
    head = list(islice(text, max_rows + 2))
    plain = None if len(head) > max_rows + 1 else _parse_plain(name, head, wanted, min_rows)
    if plain is not None:
        return plain
    return _parse_rows(name, chain(head, text), wanted, min_rows, max_rows)


#: Everything a plain numeric table may hold: a character outside this set sends the file
#: through the row-by-row reader (which names what is wrong, or reads quoted cells).
_NOT_PLAIN = re.compile(r"[^0-9eE.+\-, \t\n]", re.ASCII)


def _parse_plain(name: str, lines: list[str], wanted: _Wanted, min_rows: int) -> Table | None:
    """The table of a plain file in one NumPy call, or ``None`` to read it row by row.

    A plain file (what skyquill writes: a header on line 1, then rows of numbers with
    one cell per header column, no quotes, blank lines or carriage returns, every line
    shorter than a literal may be) is read by :func:`numpy.loadtxt`, whose C parser takes
    Python's own decimal conversion: the same floats as :func:`_parse_rows`, bit for bit.
    Within the characters allowed here (digits, ``eE.+-``, spaces and tabs) a cell that
    converts is exactly a literal of :mod:`skyquill.io.numbers` (there is no ``_``, ``inf``
    or ``nan`` to spell); a cell that does not, a ragged row or a value that overflows
    sends the file to :func:`_parse_rows`, which refuses it by name.
    """
    if len(lines) < 2 or '"' in lines[0] or not lines[0].strip():
        return None
    header = [h.strip().lower() for h in next(csv.reader(lines[:1]))]
    data = lines[1:]
    if len(data) < min_rows:
        return None
    body = "".join(data)
    commas = len(header) - 1
    plain = _NOT_PLAIN.search(body) is None and all(
        len(line) <= MAX_CHARS and line.count(",") == commas and line.strip() for line in data
    )
    if not plain:
        return None
    columns = _check_header(name, header, wanted)
    try:
        values = np.loadtxt(
            io.StringIO(body),
            delimiter=",",
            comments=None,
            usecols=[header.index(c) for c in columns],
            ndmin=2,
            dtype=float,
        )
    except ValueError:
        return None
    if not np.isfinite(values).all():
        return None
    values.setflags(write=False)
    return Table(name, columns, values, _frozen(array("q", range(2, len(data) + 2))))


def _parse_rows(
    name: str, text: Iterator[str], wanted: _Wanted, min_rows: int, max_rows: int
) -> Table:
    """Header, then the rows one by one (any CSV); stops at the first refusal."""
    reader = csv.reader(text)
    values: array[float] = array("d")
    lines: array[int] = array("q")
    try:
        rows = _non_blank(reader)
        header = next(rows, None)
        if header is None:
            raise InputError(
                f"{name}: got an empty file, expected a header line with {wanted.describe()}"
            )
        header = [h.strip().lower() for h in header]
        columns = _check_header(name, header, wanted)
        index = [(c, header.index(c)) for c in columns]
        for row in rows:
            line = reader.line_num
            _check_row(f"{name} line {line}", len(row), len(header), len(lines), max_rows)
            values.extend(_row_values(name, line, row, index))
            lines.append(line)
    except csv.Error as exc:
        raise InputError(
            f"{name} line {reader.line_num}: got malformed CSV ({exc}), expected a CSV table"
        ) from None
    if len(lines) < min_rows:
        raise InputError(f"{name}: got {len(lines)} data row(s), expected at least {min_rows}")
    return Table(name, columns, _frozen(values, (len(lines), len(columns))), _frozen(lines))


def _check_row(where: str, cells: int, columns: int, rows_before: int, max_rows: int) -> None:
    """Refuse a row beyond ``max_rows`` or with another number of cells than the header."""
    if rows_before == max_rows:
        raise InputError(
            f"{where}: got more than {max_rows} data rows, expected at most {max_rows}"
        )
    if cells != columns:
        raise InputError(
            f"{where}: got {cells} columns, expected {columns} (one per header column)"
        )


def _frozen(values: array[Any], shape: tuple[int, ...] | None = None) -> Any:
    """A read-only NumPy copy of ``values`` (float or int64), reshaped to ``shape``."""
    out = np.array(values)
    if shape is not None:
        out = out.reshape(shape)
    out.setflags(write=False)
    return out


def _lines(name: str, handle: TextIO) -> Iterator[str]:
    """The lines of ``handle``, each read with a length limit; refuses NUL characters."""
    while line := handle.readline(MAX_LINE_CHARS + 1):
        if len(line) > MAX_LINE_CHARS:
            raise InputError(
                f"{name}: got a line longer than {MAX_LINE_CHARS} characters, expected CSV "
                "lines (is this a CSV file?)"
            )
        if "\x00" in line:
            raise InputError(
                f"{name}: got a NUL character (binary data or UTF-16 text), expected UTF-8 text"
            )
        yield line


def _non_blank(reader: Iterator[list[str]]) -> Iterator[list[str]]:
    """The rows with at least one non-blank cell."""
    return (row for row in reader if "".join(row).strip())


def _check_header(name: str, header: list[str], wanted: _Wanted) -> tuple[str, ...]:
    """The columns to read, in the caller's order; InputError for a header that will not do."""
    repeated = sorted({c for c in header if header.count(c) > 1})
    if repeated:
        raise InputError(
            f"{name}: got column(s) {_names(repeated)} more than once, expected each column once"
        )
    missing = [c for c in wanted.required if c not in header]
    if missing:
        raise InputError(
            f"{name}: got columns {_shorten(str(header), 200)}, expected {wanted.describe()}; "
            f"missing {','.join(missing)}"
        )
    known = wanted.required + wanted.optional
    extra = [c for c in header if c not in known]
    if extra and wanted.unknown == "refuse":
        raise InputError(
            f"{name}: got unknown column(s) {_names(extra)}, expected only {','.join(known)}"
        )
    return wanted.required + tuple(c for c in wanted.optional if c in header)


def _row_values(name: str, line: int, row: list[str], index: list[tuple[str, int]]) -> list[float]:
    """The cells ``index`` (column, position) of ``row`` as finite floats."""
    try:
        return [parse_number(row[i]) for _, i in index]
    except ValueError:  # the named error is found only on failure
        return [_cell(name, line, c, row, i) for c, i in index]


def _cell(name: str, line: int, column: str, row: Sequence[str], i: int) -> float:
    """Cell ``i`` of a CSV ``row`` as a finite float; InputError naming file, line, column."""
    text = row[i].strip()
    try:
        return parse_number(text)
    except ValueError as exc:
        raise InputError(
            f"{name} line {line}, column {column}: got {_shorten(text)!r}, {exc}"
        ) from None


def _names(columns: Sequence[str]) -> str:
    """Column names as written in messages: quoted, so that an empty name shows."""
    return _shorten(",".join(map(repr, columns)), 200)


def _shorten(text: str, limit: int = 40) -> str:
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _describe_bytes(exc: UnicodeDecodeError) -> str:
    """What the undecodable bytes look like: a UTF-16 byte-order mark, or where they are."""
    head = exc.object[:2]
    if head in (b"\xff\xfe", b"\xfe\xff"):
        return "a UTF-16 byte-order mark"
    bad = exc.object[exc.start : exc.start + 4].hex(" ")
    return f"byte(s) {bad} where text was expected"
