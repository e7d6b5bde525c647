"""Setpoints as JSON: the ``trajectory.csv`` table at any rate, with its frame.

The file is one object::

    {"frame": "world ENU z-up, SI",
     "rate_hz": 50.0,
     "columns": ["t", "x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az", "jx", "jy", "jz"],
     "rows": [[0.0, ...], ...]}

Units: s, m, m/s, m/s^2, m/s^3; world frame x east, y north, z up. 2-D
trajectories are written with ``z = 0``. The CSV form of the same table is
:func:`skyquill.io.points.write_trajectory_csv`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from skyquill.errors import InputError
from skyquill.io.atomic import write_json
from skyquill.io.json_read import read_json_file
from skyquill.io.points import TRAJECTORY_COLUMNS, trajectory_table
from skyquill.trajectory import Trajectory
from skyquill.trajectory.sampled import MIN_STEP_S, SampledTrajectory
from skyquill.validation import as_float

#: The frame string every file carries.
FRAME = "world ENU z-up, SI"
#: Largest coordinate magnitude accepted on reading (larger is almost surely a unit error).
MAX_ABS = 1e6
#: Largest file read, bytes (checked before reading): 1,000,000 rows of 13 numbers.
MAX_BYTES = 256 * 2**20
#: Most rows read: 2.8 h at 100 Hz, as :data:`skyquill.io.table.MAX_ROWS`.
MAX_ROWS = 1_000_000


@dataclass(frozen=True)
class SetpointsJson:
    """A setpoints JSON file read back.

    Attributes
    ----------
    rate_hz
        The rate the rows were sampled at, Hz.
    trajectory
        The rows as a :class:`~skyquill.io.trajectory_csv.SampledTrajectory`
        (times (N,), s; position, velocity, acceleration, jerk (N, 3); world
        frame z-up, SI).
    """

    rate_hz: float
    trajectory: SampledTrajectory


def write_setpoints_json(traj: Trajectory, path: str | Path, rate: float) -> int:
    """Write ``traj`` sampled at ``rate`` Hz as setpoints JSON; returns the row count.

    Parameters
    ----------
    traj
        Any trajectory in the world frame (z up), m.
    path
        Output file; overwritten.
    rate
        Sample rate, Hz, > 0; samples run from 0 to the duration inclusive.

    Raises
    ------
    InputError
        When ``rate`` is not a positive finite number.
    """
    rate = as_float("rate", rate, positive=True)
    table = trajectory_table(traj, rate)
    write_json(
        path,
        {
            "frame": FRAME,
            "rate_hz": rate,
            "columns": list(TRAJECTORY_COLUMNS),
            "rows": table.tolist(),
        },
    )
    return int(table.shape[0])


def _number(value: Any) -> bool:
    return (
        isinstance(value, int | float)
        and not isinstance(value, bool)
        and math.isfinite(value)
        and abs(value) <= MAX_ABS
    )


def read_setpoints_json(path: str | Path) -> SetpointsJson:
    """Read and validate a file written by :func:`write_setpoints_json`.

    Raises
    ------
    InputError
        Naming the file and the field when the file is missing or not JSON,
        larger than :data:`MAX_BYTES`, not UTF-8 or nested too deep
        (:mod:`skyquill.io.json_read`), ``frame`` or ``columns`` differ from
        what is written, ``rate_hz`` is not > 0, there are fewer than 2 or more
        than :data:`MAX_ROWS` rows, a row has the wrong length or a cell is not
        a finite JSON number (magnitude <= 1e6; a string is refused), or times
        do not increase.
    """
    file = Path(path)
    if not file.is_file():
        raise InputError(f"setpoints file: got {str(file)!r}, expected an existing JSON file")
    name = file.name
    try:
        data = read_json_file(file, "setpoints JSON", max_bytes=MAX_BYTES)
    except InputError as exc:  # say the file's name, as every other message here does
        raise InputError(str(exc).replace(str(file), name, 1)) from None
    if not isinstance(data, dict):
        raise InputError(f"{name}: got {type(data).__name__}, expected a JSON object")
    if data.get("frame") != FRAME:
        raise InputError(f"{name}: frame: got {data.get('frame')!r}, expected {FRAME!r}")
    if data.get("columns") != list(TRAJECTORY_COLUMNS):
        raise InputError(
            f"{name}: columns: got {data.get('columns')!r:.80}, expected {list(TRAJECTORY_COLUMNS)}"
        )
    raw_rate: Any = data.get("rate_hz")
    if not _number(raw_rate) or float(raw_rate) <= 0:
        raise InputError(f"{name}: rate_hz: got {raw_rate!r}, expected a number > 0 (Hz)")
    rate = float(raw_rate)
    rows = data.get("rows")
    if not isinstance(rows, list) or not 2 <= len(rows) <= MAX_ROWS:
        got = f"{len(rows):,} row(s)" if isinstance(rows, list) else repr(rows)[:60]
        raise InputError(f"{name}: rows: got {got}, expected a list of 2 to {MAX_ROWS:,} rows")
    width = len(TRAJECTORY_COLUMNS)
    for r, row in enumerate(rows):
        if not isinstance(row, list) or len(row) != width:
            raise InputError(
                f"{name}: rows[{r}]: got {row!r:.60}, expected a list of {width} numbers"
            )
        for c, cell in enumerate(row):
            if not _number(cell):
                raise InputError(
                    f"{name}: rows[{r}] column {TRAJECTORY_COLUMNS[c]}: got {cell!r:.40}, "
                    f"expected a finite number of magnitude at most {MAX_ABS:g}"
                )
    table = np.asarray(rows, dtype=float)
    steps = np.diff(table[:, 0])
    if np.any(steps < MIN_STEP_S):
        r = int(np.argmax(steps < MIN_STEP_S)) + 1
        raise InputError(
            f"{name}: rows[{r}] column t: got {table[r, 0]:.9g} after {table[r - 1, 0]:.9g}, "
            f"expected strictly increasing times at least {MIN_STEP_S:g} s apart"
        )
    traj = SampledTrajectory(
        t=table[:, 0], p=table[:, 1:4], v=table[:, 4:7], a=table[:, 7:10], j=table[:, 10:13]
    )
    return SetpointsJson(rate_hz=rate, trajectory=traj)
