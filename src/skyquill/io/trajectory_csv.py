"""Read ``trajectory.csv`` back into a trajectory that can be flown; write ``flight.csv``.

``trajectory.csv`` is what every planning command writes
(:data:`skyquill.io.points.TRAJECTORY_COLUMNS`): ``t,x,y,z,vx,vy,vz,ax,ay,az``
and optionally ``jx,jy,jz``, SI units, z-up world frame, one row per sample.
:func:`read_trajectory_csv` turns those samples into a
:class:`SampledTrajectory` that a simulator can fly; :func:`write_flight_csv`
writes the time series of a :class:`~skyquill.sim.Flight`.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from skyquill.errors import InputError
from skyquill.io.points import parse_cell
from skyquill.sim.result import Flight
from skyquill.trajectory.sampled import MAX_VALUE, MIN_STEP_S, SampledTrajectory
from skyquill.validation import FloatArray

#: Columns :func:`read_trajectory_csv` needs (jerk ``jx,jy,jz`` is optional).
REQUIRED_COLUMNS = ("t", "x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az")
JERK_COLUMNS = ("jx", "jy", "jz")

#: ``flight.csv``: reference and flown state, commands; SI units, z-up world frame.
FLIGHT_COLUMNS = (
    "t",
    "x_ref",
    "y_ref",
    "z_ref",
    "x",
    "y",
    "z",
    "vx_ref",
    "vy_ref",
    "vz_ref",
    "vx",
    "vy",
    "vz",
    "ax_cmd",
    "ay_cmd",
    "az_cmd",
    "thrust",
    "tilt",
)


def read_trajectory_csv(path: str | Path) -> SampledTrajectory:
    """Read a ``trajectory.csv`` (as written by ``skyquill fit``) into a trajectory.

    Parameters
    ----------
    path
        CSV file with a header naming at least ``t,x,y,z,vx,vy,vz,ax,ay,az``
        (any order, case and surrounding spaces ignored; other columns are
        ignored) and optionally all three of ``jx,jy,jz``. Units: s, m, m/s,
        m/s^2, m/s^3. Blank lines are skipped.

    Returns
    -------
    SampledTrajectory
        Time shifted so that the first row is at 0 (see :attr:`SampledTrajectory.t0`).

    Raises
    ------
    InputError
        Naming the file, and the column or line, when the file is missing or
        unreadable, a required column is missing, there are fewer than 2 rows,
        a cell is not a finite number of magnitude at most 1e6, or the times
        are not strictly increasing.
    """
    file = Path(path)
    if not file.is_file():
        raise InputError(f"trajectory file: got {str(file)!r}, expected an existing CSV file")
    name = file.name
    header, rows = _read_rows(file)
    _check_header(name, header)
    has_jerk = any(c in header for c in JERK_COLUMNS)
    if has_jerk and not all(c in header for c in JERK_COLUMNS):
        present = [c for c in JERK_COLUMNS if c in header]
        raise InputError(
            f"{name}: got jerk column(s) {','.join(present)}, expected all of jx,jy,jz or none"
        )
    columns = REQUIRED_COLUMNS + (JERK_COLUMNS if has_jerk else ())
    index = [header.index(c) for c in columns]
    data = np.empty((len(rows), len(columns)))
    for r, (line, row) in enumerate(rows):
        for c, (column, i) in enumerate(zip(columns, index, strict=True)):
            data[r, c] = _cell(name, line, column, row, i)
    if data.shape[0] < 2:
        raise InputError(f"{name}: got {data.shape[0]} data row(s), expected at least 2")
    t = data[:, 0]
    steps = np.diff(t)
    if np.any(steps < MIN_STEP_S):
        k = int(np.argmax(steps < MIN_STEP_S))
        raise InputError(
            f"{name} line {rows[k + 1][0]}, column t: got {t[k + 1]:.9g} after {t[k]:.9g}, "
            f"expected strictly increasing times (at least {MIN_STEP_S:g} s apart)"
        )
    return SampledTrajectory(
        t=t,
        p=data[:, 1:4],
        v=data[:, 4:7],
        a=data[:, 7:10],
        j=data[:, 10:13] if has_jerk else None,
    )


def _read_rows(file: Path) -> tuple[list[str], list[tuple[int, list[str]]]]:
    """Header (stripped, lower case) and the non-blank rows with their line numbers."""
    try:
        with file.open(newline="", encoding="utf-8") as handle:
            reader = csv.reader(handle)
            header = [h.strip().lower() for h in next(reader, [])]
            rows = [(reader.line_num, row) for row in reader if row and any(c.strip() for c in row)]
    except UnicodeDecodeError as exc:
        raise InputError(
            f"{file.name}: got bytes that are not UTF-8 (byte {exc.start}), expected a text CSV"
        ) from None
    except csv.Error as exc:
        raise InputError(f"{file.name}: got malformed CSV ({exc}), expected a text CSV") from None
    return header, rows


def _check_header(name: str, header: list[str]) -> None:
    missing = [c for c in REQUIRED_COLUMNS if c not in header]
    if missing:
        raise InputError(
            f"{name}: got columns {header}, expected at least {','.join(REQUIRED_COLUMNS)} "
            f"(optionally jx,jy,jz); missing {','.join(missing)}"
        )
    repeated = sorted(
        {c for c in header if c in REQUIRED_COLUMNS + JERK_COLUMNS and header.count(c) > 1}
    )
    if repeated:
        raise InputError(
            f"{name}: got column(s) {','.join(repeated)} more than once, expected each once"
        )


def _cell(name: str, line: int, column: str, row: list[str], i: int) -> float:
    value = parse_cell(name, line, column, row, i)
    text = row[i].strip()
    limit = 1e7 if column == "t" else MAX_VALUE
    if abs(value) > limit:
        raise InputError(
            f"{name} line {line}, column {column}: got {text!r}, expected a magnitude of at "
            f"most {limit:g} (SI units)"
        )
    return value


def flight_table(flight: Flight) -> FloatArray:
    """The ``flight.csv`` table, shape (N, 18), columns :data:`FLIGHT_COLUMNS`."""
    return np.column_stack(
        [
            flight.t,
            flight.p_ref,
            flight.p,
            flight.v_ref,
            flight.v,
            flight.a_cmd,
            flight.thrust,
            flight.tilt,
        ]
    )


def write_flight_csv(path: str | Path, flight: Flight) -> int:
    """Write ``flight.csv`` (columns :data:`FLIGHT_COLUMNS`, SI units); returns the row count.

    ``thrust`` is the commanded collective thrust in N, ``tilt`` the commanded
    tilt from vertical in rad, ``a*_cmd`` the outer loop's acceleration command
    (gravity excluded), m/s^2.
    """
    table = flight_table(flight)
    np.savetxt(path, table, delimiter=",", header=",".join(FLIGHT_COLUMNS), comments="", fmt="%.9g")
    return int(table.shape[0])
