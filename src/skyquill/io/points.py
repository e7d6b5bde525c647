"""Read point CSVs (``x,y[,z][,t]``) and write the ``trajectory.csv`` table.

``trajectory.csv`` is the format every command shares (written through
:mod:`skyquill.io.plan_dir`): columns
``t,x,y,z,vx,vy,vz,ax,ay,az,jx,jy,jz``, SI units, z-up world frame; 2-D
trajectories are written with ``z = 0``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np

from skyquill.errors import InputError
from skyquill.io.table import MAX_ROWS, read_table
from skyquill.trajectory import Samples, Trajectory, sample
from skyquill.validation import FloatArray

TRAJECTORY_COLUMNS = ("t", "x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az", "jx", "jy", "jz")


def read_points_csv(path: str | Path) -> tuple[FloatArray, FloatArray | None]:
    """Read ``x,y`` or ``x,y,z`` with an optional ``t`` column.

    Parameters
    ----------
    path
        CSV file read by :func:`~skyquill.io.table.read_table` (UTF-8, header names in
        any order and case, other columns ignored), at least 2 rows.

    Returns
    -------
    points : numpy.ndarray, shape (N, 2) or (N, 3), m
    times : numpy.ndarray, shape (N,), s, or None when there is no ``t`` column
    """
    table = read_table(
        path, required=("x", "y"), optional=("z", "t"), min_rows=2, name="points file"
    )
    axes = ["x", "y"] + (["z"] if table.has("z") else [])
    times = table.column("t") if table.has("t") else None
    return table.select(axes), times


def trajectory_table(traj: Trajectory, rate: float) -> FloatArray:
    """Samples as the ``trajectory.csv`` table, shape (N, 13); 2-D gets ``z = 0``.

    Raises
    ------
    InputError
        More rows than a trajectory file is read back with (:data:`MAX_ROWS`): the
        file would be written, then refused by its own read-back (a 10,000-dot
        painting at 100 Hz wrote 813 MB of it).
    """
    check_rows_written(traj.duration, rate)
    s: Samples = sample(traj, rate)

    def as3(x: FloatArray) -> FloatArray:
        return x if x.shape[1] == 3 else np.column_stack([x, np.zeros(x.shape[0])])

    return np.column_stack([s.t, as3(s.p), as3(s.v), as3(s.a), as3(s.j)])


def check_rows_written(
    duration: float, rate: float, argument: str = "rate", *, at_least: bool = False
) -> None:
    """Refuse a ``trajectory.csv`` of more rows than its readers take, before sampling.

    Parameters
    ----------
    duration
        The flight's duration, s.
    rate
        Sample rate, Hz.
    argument
        What the refusal names: where the rate came from.
    at_least
        ``duration`` is a lower bound of a flight still being planned (said so).
    """
    rows = math.floor(duration * rate + 1e-9) + 2  # the samples, and the end when off the grid
    if rows > MAX_ROWS:
        more = "at least " if at_least else ""
        flight = f"a flight of {more}{duration:.6g} s" if at_least else f"a {duration:.6g} s flight"
        raise InputError(
            f"{argument}: got {rate:g} Hz over {flight} ({more}{rows:,} rows), "
            f"expected at most {MAX_ROWS:,} rows in trajectory.csv, the most it is read back "
            "with (a lower rate)"
        )


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
    Path(path).write_bytes(table_text(table, ",".join(columns)).encode("latin-1"))
    return int(table.shape[0])


#: A cell of ``trajectory.csv``: nine significant digits.
CELL_FORMAT = "%.9g"


def table_text(table: FloatArray, header: str) -> str:
    """``header`` and the rows of ``table`` (N, k) as ``numpy.savetxt(..., fmt="%.9g")`` writes
    them (delimiter ``,``, no comment sign), character for character.

    All rows in one ``%`` of Python floats: ``savetxt`` formats row by row from numpy
    scalars, 3-4x the time on a show's thousands of rows (the same conversion: ``%g`` takes
    a float64 scalar as the float it is).
    """
    rows, cells = table.shape
    row = ",".join([CELL_FORMAT] * cells) + "\n"
    head = header + "\n" if header else ""  # savetxt writes no line for an empty header
    body: str = (row * rows) % tuple(np.asarray(table, dtype=float).ravel().tolist())
    return head + body
