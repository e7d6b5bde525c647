"""Read ``trajectory.csv`` back into a trajectory that can be flown; write ``flight.csv``.

``trajectory.csv`` is what every planning command writes
(:data:`skyquill.io.points.TRAJECTORY_COLUMNS`): ``t,x,y,z,vx,vy,vz,ax,ay,az``
and optionally ``jx,jy,jz``, SI units, z-up world frame, one row per sample.
:func:`read_trajectory_csv` turns those samples into a
:class:`SampledTrajectory` that a simulator can fly; :func:`write_flight_csv`
writes the time series of a :class:`~skyquill.sim.Flight`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from skyquill.errors import InputError
from skyquill.io.table import Table, read_table
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
        Naming the file, and the column or line, for everything
        :func:`~skyquill.io.table.read_table` refuses (missing or unreadable
        file, missing or repeated column, ragged row, a cell that is not a
        finite number, fewer than 2 rows), a magnitude above 1e6 (1e7 for
        ``t``), only some of ``jx,jy,jz``, or times not strictly increasing.
    """
    table = read_table(
        path,
        required=REQUIRED_COLUMNS,
        optional=JERK_COLUMNS,
        min_rows=2,
        name="trajectory file",
    )
    present = [c for c in JERK_COLUMNS if table.has(c)]
    if present and len(present) < len(JERK_COLUMNS):
        raise InputError(
            f"{table.name}: got jerk column(s) {','.join(present)}, expected all of jx,jy,jz "
            "or none"
        )
    _check_magnitudes(table)
    t = table.column("t")
    steps = np.diff(t)
    if np.any(steps < MIN_STEP_S):
        k = int(np.argmax(steps < MIN_STEP_S))
        raise InputError(
            f"{table.name} line {table.lines[k + 1]}, column t: got {t[k + 1]:.9g} after "
            f"{t[k]:.9g}, expected strictly increasing times (at least {MIN_STEP_S:g} s apart)"
        )
    return SampledTrajectory(
        t=t,
        p=table.select(REQUIRED_COLUMNS[1:4]),
        v=table.select(REQUIRED_COLUMNS[4:7]),
        a=table.select(REQUIRED_COLUMNS[7:10]),
        j=table.select(JERK_COLUMNS) if present else None,
    )


def _check_magnitudes(table: Table) -> None:
    """Times within 1e7 s, other values within :data:`MAX_VALUE`: SI units, no overflow."""
    limits = np.array([1e7 if c == "t" else MAX_VALUE for c in table.columns])
    over = np.abs(table.data) > limits
    if np.any(over):
        r, c = np.argwhere(over)[0]
        raise InputError(
            f"{table.name} line {table.lines[r]}, column {table.columns[c]}: got "
            f"{table.data[r, c]:.9g}, expected a magnitude of at most {limits[c]:g} (SI units)"
        )


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
