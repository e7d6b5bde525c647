"""Skybrush Studio's zipped CSV show: one ``<drone>.csv`` per drone in a ZIP archive.

Columns, as Skybrush Studio for Blender documents and reads them (skybrush-io/studio-blender,
``doc/modules/ROOT/pages/panels/formations/formations.adoc``, "From zipped CSV files", and
``.../safety_and_export/export.adoc``, "Export to Skybrush .csv")::

    Time_msec,x_m,y_m,z_m,Red,Green,Blue

time in milliseconds, position in metres (the show frame: x, y horizontal, z up, which is
skyquill's world frame), the LED colour as integers 0..255. Studio's importer
(``src/modules/sbstudio/plugin/operators/add_markers_from_zipped_csv.py``,
``parse_compressed_csv_zip``) names a drone by its file's stem, skips a header that starts
with ``Time_msec``, and moves between rows by linear interpolation (``numpy.interp`` in
``src/modules/sbstudio/model/trajectory.py``, ``resample_in_place``; linear keyframes in
Blender): :meth:`CsvDrone.trajectory` is that reading.
"""

from __future__ import annotations

import csv
import io
import itertools
import math
import re
import zipfile
import zlib
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.export.skybrush import DEFLATE_LEVEL
from skyquill.io.atomic import atomic_path
from skyquill.io.numbers import parse_number
from skyquill.io.source import open_binary
from skyquill.trajectory import PiecewisePolynomial
from skyquill.validation import FloatArray

#: The columns, in order.
HEADER = ("Time_msec", "x_m", "y_m", "z_m", "Red", "Green", "Blue")
#: Most drones in one archive (Skybrush's ``MAX_DRONE_COUNT``).
MAX_DRONES = 5000
#: Largest CSV member, and largest archive content, bytes (checked before inflating).
MAX_MEMBER_BYTES = 64 * 2**20
MAX_TOTAL_BYTES = 256 * 2**20
#: Largest coordinate accepted, m (a value beyond is in the wrong unit).
MAX_COORDINATE_M = 1e5


@dataclass(frozen=True)
class CsvDrone:
    """One drone's rows.

    Attributes
    ----------
    name
        The drone's name (its file is ``<name>.csv``).
    t_ms
        Row times, shape (N,), integer ms, strictly increasing.
    positions
        Shape (N, 3), m, z up.
    colors
        Shape (N, 3), integers 0..255.
    """

    name: str
    t_ms: NDArray[np.int64]
    positions: FloatArray
    colors: NDArray[np.int64]

    def trajectory(self) -> PiecewisePolynomial:
        """The position as Studio interpolates the rows (linear), on a clock from the first row."""
        t = self.t_ms / 1000.0
        slope = np.diff(self.positions, axis=0) / np.diff(t)[:, None]
        return PiecewisePolynomial(t - t[0], np.stack([self.positions[:-1], slope], axis=1))


#: One row: the time and the colours as integers, the positions to the micrometre.
_ROW_FORMAT = "%d,%.6f,%.6f,%.6f,%d,%d,%d\n"


def _csv_text(drone: CsvDrone) -> str:
    # Python numbers, not numpy scalars: formatting those costs 40x more (a 1,000-drone
    # show writes millions of rows). All rows in one ``%`` call (the same conversions as
    # ``f"{x:.6f}"``, 0.70x the time of formatting row by row).
    columns = (drone.t_ms.tolist(), *drone.positions.T.tolist(), *drone.colors.T.tolist())
    values = tuple(itertools.chain.from_iterable(zip(*columns, strict=True)))
    return ",".join(HEADER) + "\n" + (_ROW_FORMAT * drone.t_ms.size) % values


def write_csv_zip(drones: Sequence[CsvDrone], path: str | Path) -> Path:
    """Write one ``<name>.csv`` per drone into the ZIP ``path`` (atomically); return the path.

    Positions are written to the micrometre.

    Raises
    ------
    InputError
        When ``drones`` is empty, names repeat, or a name is not a plain file stem.
    """
    if not drones:
        raise InputError("drones: got nothing, expected at least one drone")
    names = [d.name for d in drones]
    for name in names:
        if not name or PurePosixPath(name).name != name or "\\" in name or name.startswith("."):
            raise InputError(f"drones: got the name {name!r}, expected a plain file stem")
    if len(set(names)) != len(names):
        raise InputError(f"drones: got repeated names in {names[:10]}, expected unique names")
    target = Path(path)
    with (
        atomic_path(target) as tmp,
        zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED, compresslevel=DEFLATE_LEVEL) as archive,
    ):
        for drone in drones:
            archive.writestr(f"{drone.name}.csv", _csv_text(drone))
    return target


def read_csv_zip(path: str | Path) -> list[CsvDrone]:
    """Read a zipped CSV show, refusing what Studio's importer would choke on or misread.

    Returns
    -------
    list of CsvDrone
        In the archive's order.

    Raises
    ------
    InputError
        Naming the file, the member and the row: a missing file, not a ZIP (or a corrupt
        one), more than :data:`MAX_DRONES` members, a member that is not ``.csv`` or larger
        than :data:`MAX_MEMBER_BYTES` (in all :data:`MAX_TOTAL_BYTES`, checked before
        inflating), text that is not ASCII, a header other than :data:`HEADER`, a row with a
        wrong number of values, a value that is not a finite number (positions) or an
        integer in 0..255 (colours), times not strictly increasing, fewer than two rows.
    """
    file = Path(path)
    if not file.exists():
        raise InputError(f"csv zip: got {str(file)!r}, expected an existing .zip file")
    try:
        with (
            open_binary(
                file, "a zipped CSV show", max_bytes=MAX_TOTAL_BYTES, name=file.name
            ) as raw,
            zipfile.ZipFile(raw) as archive,
        ):
            members = [m for m in archive.infolist() if not m.is_dir()]
            _check_members(file.name, members)
            return [_drone(file.name, m.filename, archive.read(m)) for m in members]
    except InputError:
        raise
    except zipfile.BadZipFile:
        raise InputError(
            f"{file.name}: got a file that is not a ZIP, expected a zipped CSV show"
        ) from None
    except (OSError, EOFError, RuntimeError, NotImplementedError, zlib.error) as exc:
        raise InputError(
            f"{file.name}: a member cannot be extracted ({type(exc).__name__}: {exc}), "
            "expected a zipped CSV show"
        ) from None


def _check_members(name: str, members: list[zipfile.ZipInfo]) -> None:
    if not members or len(members) > MAX_DRONES:
        raise InputError(
            f"{name}: got {len(members)} member(s), expected 1 to {MAX_DRONES} CSV files"
        )
    stems = [PurePosixPath(m.filename).stem for m in members]
    if len(set(stems)) != len(stems):
        raise InputError(f"{name}: got repeated drone names in {stems[:10]}, expected unique names")
    total = 0
    for member in members:
        if not member.filename.lower().endswith(".csv"):
            raise InputError(
                f"{name}: got the member {member.filename!r}, expected only .csv files"
            )
        # Sizes in the directory are checked before inflating: a ZIP bomb claims gigabytes.
        if member.file_size > MAX_MEMBER_BYTES:
            raise InputError(
                f"{name}: {member.filename}: got {member.file_size:,} bytes, expected at most "
                f"{MAX_MEMBER_BYTES:,}"
            )
        total += member.file_size
    if total > MAX_TOTAL_BYTES:
        raise InputError(
            f"{name}: got {total:,} bytes of CSV, expected at most {MAX_TOTAL_BYTES:,}"
        )


def _drone(archive: str, member: str, raw: bytes) -> CsvDrone:
    where = f"{archive}: {member}"
    try:
        text = raw.decode("ascii")  # Studio decodes its CSVs as ASCII
    except UnicodeDecodeError as exc:
        raise InputError(
            f"{where}: got a non-ASCII byte at {exc.start}, expected ASCII text"
        ) from None
    plain = _plain_columns(text)
    if plain is not None:
        t, positions, colors = plain
        return CsvDrone(PurePosixPath(member).stem, t, positions, colors)
    return _checked_drone(where, member, text)


#: One row as the writer writes it: integers and plain decimals only (a subset of the
#: number grammar that ``float`` reads the same way).
_ROW = r"-?\d+,-?\d+(?:\.\d+)?,-?\d+(?:\.\d+)?,-?\d+(?:\.\d+)?,\d{1,3},\d{1,3},\d{1,3}"
_PLAIN_BODY = re.compile(rf"(?:{_ROW}\r?\n)*{_ROW}(?:\r?\n)?")


def _plain_columns(
    text: str,
) -> tuple[NDArray[np.int64], FloatArray, NDArray[np.int64]] | None:
    """The columns of a CSV written the way Studio and skyquill write it, read at numpy's speed;
    ``None`` for anything else (blank lines, other number forms, a value out of range, times
    not increasing), which the row-by-row reader then reads or refuses with the line."""
    header, _, body = text.partition("\n")
    if header.rstrip("\r").lower() != ",".join(HEADER).lower():
        return None
    if not _PLAIN_BODY.fullmatch(body):
        return None
    # numpy's C reader on the rows just matched (it converts as Python's float does: the
    # same floats as splitting the text and converting each value, at a quarter the time)
    table = np.loadtxt(
        io.StringIO(body.replace("\r", "").rstrip("\n")),
        delimiter=",",
        comments=None,
        ndmin=2,
        dtype=float,
    )
    if table.shape[0] < 2:
        return None
    t, positions, colors = table[:, 0], table[:, 1:4], table[:, 4:7]
    inside = (
        np.abs(t).max() <= 2**53
        and np.abs(positions).max() <= MAX_COORDINATE_M
        and colors.max() <= 255
        and np.all(np.diff(t) > 0)
    )
    if not inside:
        return None
    return t.astype(np.int64), positions, colors.astype(np.int64)


def _checked_drone(where: str, member: str, text: str) -> CsvDrone:
    """One member read row by row, every value checked, refused with its line."""
    try:
        rows = [(n, row) for n, row in enumerate(csv.reader(io.StringIO(text)), start=1) if row]
    except csv.Error as exc:  # e.g. a NUL byte, or a lone carriage return inside a field
        raise InputError(
            f"{where}: got text the CSV reader refuses ({exc}), expected CSV rows"
        ) from None
    if not rows or [c.strip().lower() for c in rows[0][1]] != [h.lower() for h in HEADER]:
        got = rows[0][1] if rows else []
        raise InputError(f"{where}: got the header {got!r:.80}, expected {','.join(HEADER)}")
    body = rows[1:]
    if len(body) < 2:
        raise InputError(f"{where}: got {len(body)} row(s), expected at least 2")
    t = np.empty(len(body), dtype=np.int64)
    positions = np.empty((len(body), 3))
    colors = np.empty((len(body), 3), dtype=np.int64)
    for i, (line, row) in enumerate(body):
        t[i], positions[i], colors[i] = _row(f"{where}: line {line}", row)
    steps = np.diff(t)
    if np.any(steps <= 0):
        i = int(np.argmax(steps <= 0))
        raise InputError(
            f"{where}: line {body[i + 1][0]}: got Time_msec {t[i + 1]} after {t[i]}, expected "
            "strictly increasing times"
        )
    return CsvDrone(PurePosixPath(member).stem, t, positions, colors)


def _row(where: str, row: list[str]) -> tuple[int, list[float], list[int]]:
    if len(row) != len(HEADER):
        raise InputError(
            f"{where}: got {len(row)} values, expected {len(HEADER)} ({','.join(HEADER)})"
        )
    try:
        t = parse_number(row[0])
        xyz = [parse_number(v) for v in row[1:4]]
        rgb = [int(v) if v.isascii() and v.isdigit() else int("not a colour") for v in row[4:7]]
    except ValueError:
        raise InputError(
            f"{where}: got {row!r:.80}, expected numbers (colours as integers)"
        ) from None
    if not math.isfinite(t) or t != int(t) or abs(t) > 2**53:
        raise InputError(f"{where}: Time_msec: got {row[0]!r}, expected a whole number of ms")
    if not all(math.isfinite(v) and abs(v) <= MAX_COORDINATE_M for v in xyz):
        raise InputError(
            f"{where}: got x, y, z = {row[1:4]!r}, expected finite numbers within "
            f"{MAX_COORDINATE_M:g} m"
        )
    if not all(0 <= c <= 255 for c in rgb):
        raise InputError(
            f"{where}: got Red, Green, Blue = {row[4:7]!r}, expected integers in 0..255"
        )
    return int(t), xyz, rgb
