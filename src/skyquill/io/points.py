"""Read point CSVs (``x,y[,z][,t]``) and write ``trajectory.csv`` / ``summary.json``.

``trajectory.csv`` is the format every command shares: columns
``t,x,y,z,vx,vy,vz,ax,ay,az,jx,jy,jz``, SI units, z-up world frame; 2-D
trajectories are written with ``z = 0``.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np

from skyquill.errors import InputError
from skyquill.trajectory import Samples, Trajectory, sample
from skyquill.validation import FloatArray

TRAJECTORY_COLUMNS = ("t", "x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az", "jx", "jy", "jz")


def read_points_csv(path: str | Path) -> tuple[FloatArray, FloatArray | None]:
    """Read ``x,y`` or ``x,y,z`` with an optional ``t`` column.

    Returns
    -------
    points : numpy.ndarray, shape (N, 2) or (N, 3), m
    times : numpy.ndarray, shape (N,), s, or None when there is no ``t`` column
    """
    file = Path(path)
    if not file.is_file():
        raise InputError(f"points file: got {str(file)!r}, expected an existing CSV file")
    with file.open(newline="", encoding="utf-8") as handle:
        reader = csv.reader(handle)
        header = [h.strip().lower() for h in next(reader, [])]
        rows = [row for row in reader if row and any(cell.strip() for cell in row)]
    missing = [c for c in ("x", "y") if c not in header]
    if missing:
        raise InputError(
            f"{file.name}: got columns {header}, expected columns x,y (optionally z and t); "
            f"missing {','.join(missing)}"
        )
    columns = [c for c in ("x", "y", "z", "t") if c in header]
    index = [header.index(c) for c in columns]
    data = np.empty((len(rows), len(columns)))
    for r, row in enumerate(rows):
        for c, (name, i) in enumerate(zip(columns, index, strict=True)):
            data[r, c] = parse_cell(file.name, r + 2, name, row, i)
    if data.shape[0] < 2:
        raise InputError(f"{file.name}: got {data.shape[0]} data row(s), expected at least 2")
    has_t = columns[-1] == "t"
    points = data[:, : len(columns) - has_t]
    return points, (data[:, -1] if has_t else None)


def parse_cell(name: str, line: int, column: str, row: list[str], i: int) -> float:
    """Cell ``i`` of a CSV ``row`` as a finite float; InputError naming file, line, column."""
    text = row[i].strip() if i < len(row) else ""
    try:
        value = float(text)
    except ValueError:
        raise InputError(
            f"{name} line {line}, column {column}: got {text!r}, expected a number"
        ) from None
    if not math.isfinite(value):
        raise InputError(
            f"{name} line {line}, column {column}: got {text!r}, expected a finite number"
        )
    return value


def trajectory_table(traj: Trajectory, rate: float) -> FloatArray:
    """Samples as the ``trajectory.csv`` table, shape (N, 13); 2-D gets ``z = 0``."""
    s: Samples = sample(traj, rate)

    def as3(x: FloatArray) -> FloatArray:
        return x if x.shape[1] == 3 else np.column_stack([x, np.zeros(x.shape[0])])

    return np.column_stack([s.t, as3(s.p), as3(s.v), as3(s.a), as3(s.j)])


def write_trajectory_csv(
    path: str | Path,
    traj: Trajectory,
    rate: float,
    pen: Callable[[FloatArray], FloatArray] | None = None,
) -> int:
    """Write ``trajectory.csv`` sampled at ``rate`` Hz; returns the number of rows.

    With ``pen`` (times (N,) -> 1.0 where the brush is down, else 0.0) two
    columns follow the engine's: ``yaw`` (rad, constant 0: paper 000 writes
    with a fixed heading) and ``pen``.
    """
    table = trajectory_table(traj, rate)
    return write_table_csv(path, table, None if pen is None else pen(table[:, 0]))


def write_table_csv(path: str | Path, table: FloatArray, pen: FloatArray | None = None) -> int:
    """Write the ``trajectory.csv`` table (N, 13), with ``yaw`` (0) and ``pen`` (N,) if given."""
    columns = list(TRAJECTORY_COLUMNS)
    if pen is not None:
        table = np.column_stack([table, np.zeros(table.shape[0]), pen])
        columns += ["yaw", "pen"]
    np.savetxt(path, table, delimiter=",", header=",".join(columns), comments="", fmt="%.9g")
    return int(table.shape[0])
