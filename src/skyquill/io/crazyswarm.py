"""Crazyswarm2 / uav_trajectories polynomial CSV: export a spline, import it back.

The format (``uav_trajectories``' ``generate_trajectory`` output, read by
Crazyswarm2's ``uav_trajectory.Trajectory.loadcsv`` and uploaded with
``upload_trajectory``) is one row per polynomial piece::

    duration,x^0,...,x^7,y^0,...,y^7,z^0,...,z^7,yaw^0,...,yaw^7

``duration`` is the piece's length in seconds; the ``x^j`` column is the
coefficient of ``tau^j`` with ``tau`` the local time of the piece, from 0 to
``duration``; positions in metres, yaw in radians. Pieces are flown back to
back.

Frames: skyquill's world frame is z-up (ENU-like) and so is the Crazyswarm
world frame (x, y horizontal, z up), so nothing is converted -- the numbers in
the file are skyquill's numbers.

A clamped uniform B-spline of degree ``k <= 7`` is a polynomial of degree ``k``
on each knot span, so the export is exact: one piece per span, coefficients of
``tau^(k+1) .. tau^7`` zero. The Crazyflie keeps at most :data:`MAX_PIECES`
pieces in its 4 KB trajectory memory (132 B a piece); a longer trajectory is
split into several consecutive uploads, and :class:`CrazyswarmExport` says so.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np

from skyquill.errors import InputError
from skyquill.io.table import read_table
from skyquill.trajectory import PiecewisePolynomial, SplineTrajectory
from skyquill.validation import FloatArray, as_float, as_int

#: Pieces the Crazyflie can hold at once: 4096 B of trajectory memory / 132 B a piece.
MAX_PIECES = 31
#: Coefficients per axis in the file (degree 7).
N_COEFFS = 8
#: Axes in the file, in column order.
AXES = ("x", "y", "z", "yaw")
#: The header, column by column.
COLUMNS: tuple[str, ...] = ("duration", *(f"{a}^{j}" for a in AXES for j in range(N_COEFFS)))
#: The header line as written.
HEADER = ",".join(COLUMNS)


@dataclass(frozen=True)
class CrazyswarmExport:
    """What :func:`write_crazyswarm` wrote.

    Attributes
    ----------
    files
        The CSV files, one per upload, in flight order.
    pieces
        Total number of polynomial pieces over all files.
    strategy
        ``"single"`` (one file) or ``"split"`` (several uploads flown back to back).
    message
        One sentence on what was done, for the CLI to print and ``summary.json``.
    """

    files: tuple[Path, ...]
    pieces: int
    strategy: Literal["single", "split"]
    message: str


def crazyswarm_pieces(traj: SplineTrajectory, yaw: float = 0.0) -> FloatArray:
    """The rows of the Crazyswarm CSV for ``traj``: one per knot span, exact.

    Parameters
    ----------
    traj
        Spline of degree 1 to 7 with 2 or 3 axes, z-up world frame, metres.
        A 2-D trajectory gets ``z = 0``.
    yaw
        Constant yaw, rad (the ``yaw^0`` column; higher yaw coefficients are 0).

    Returns
    -------
    numpy.ndarray, shape (L, 33)
        Column 0 is the piece duration, s; then 8 coefficients (``tau^0`` to
        ``tau^7``, lowest first) for each of x, y, z (m) and yaw (rad).
    """
    if not isinstance(traj, SplineTrajectory):
        raise InputError(
            f"traj: got {type(traj).__name__}, expected a SplineTrajectory "
            "(the export is exact only for piecewise polynomials)"
        )
    if traj.dim not in (2, 3):
        raise InputError(f"traj: got a {traj.dim}-D trajectory, expected 2 or 3 axes")
    yaw = as_float("yaw", yaw)
    breaks, coeffs = traj.to_piecewise_polynomial()  # (L+1,), (L, k+1, d)
    n_pieces, n_coef, dim = coeffs.shape
    poly = np.zeros((n_pieces, N_COEFFS, 4))  # zero padding: degree < 7, z of 2-D, yaw
    poly[:, :n_coef, :dim] = coeffs
    poly[:, 0, 3] = yaw
    # Axis-major columns: x^0..x^7, y^0..y^7, ...
    return np.column_stack([np.diff(breaks), poly.transpose(0, 2, 1).reshape(n_pieces, -1)])


def _part_path(path: Path, i: int) -> Path:
    return path.with_name(f"{path.stem}_part{i}.csv")


def _write_table(path: Path, table: FloatArray) -> None:
    # '%.17g' is round-trip precision for float64.
    lines = [HEADER, *(",".join(f"{v:.17g}" for v in row) for row in table)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def write_crazyswarm(
    traj: SplineTrajectory,
    path: str | Path,
    max_pieces: int = MAX_PIECES,
    yaw: float = 0.0,
) -> CrazyswarmExport:
    """Write ``traj`` as Crazyswarm CSV, split into uploads the Crazyflie can hold.

    Parameters
    ----------
    traj
        Spline of degree 1 to 7, 2 or 3 axes, z-up world frame (no conversion:
        Crazyswarm's world frame is z-up too), metres.
    path
        Output file. With more than ``max_pieces`` pieces the trajectory is
        split into ``n`` consecutive uploads written to
        ``<stem>_part1.csv .. <stem>_part<n>.csv`` next to ``path`` (and
        ``path`` itself is not written); each part starts at its own local
        time 0, and the parts have (nearly) equal piece counts.
    max_pieces
        Most pieces per file, >= 1; default the Crazyflie's :data:`MAX_PIECES`.
        A larger value is honoured, but the message then says the vehicle
        cannot hold such a file in one upload.
    yaw
        Constant yaw, rad.

    Returns
    -------
    CrazyswarmExport
        The files, the piece count, ``"single"`` or ``"split"`` and a message.

    Notes
    -----
    Splitting keeps the trajectory exact: the pieces are the same, only grouped
    into uploads. At each join the end state of one upload equals the start of
    the next up to derivative ``k - 1`` (the spline is ``C^(k-1)``), so the
    uploads flown back to back fly the original trajectory. The alternative the
    issue mentions, refitting with fewer knots, changes the trajectory and would
    have to be re-verified against the limits; it is not done here.
    """
    table = crazyswarm_pieces(traj, yaw)
    max_pieces = as_int("max_pieces", max_pieces, low=1)
    path = Path(path)
    n_pieces = table.shape[0]
    notes = ""
    if traj.dim == 2:
        notes += (
            " The trajectory is 2-D and was written with z = 0 m: fly it relative to a "
            "hover point (Crazyswarm2 start_trajectory(relative=True)) or lift it first."
        )
    if max_pieces > MAX_PIECES and min(n_pieces, max_pieces) > MAX_PIECES:
        notes += (
            f" WARNING: a file holds more than {MAX_PIECES} pieces, more than the Crazyflie's "
            f"4 KB trajectory memory holds ({MAX_PIECES} pieces of 132 B); it cannot be "
            "uploaded to a Crazyflie in one go."
        )
    if n_pieces <= max_pieces:
        _write_table(path, table)
        return CrazyswarmExport(
            files=(path,),
            pieces=n_pieces,
            strategy="single",
            message=(
                f"wrote {n_pieces} piece(s) of degree {traj.degree} (exact) to {path}, "
                f"one upload of <= {max_pieces} pieces." + notes
            ),
        )
    n_files = math.ceil(n_pieces / max_pieces)
    files = []
    for i, part in enumerate(np.array_split(table, n_files), start=1):
        part_path = _part_path(path, i)
        _write_table(part_path, part)
        files.append(part_path)
    return CrazyswarmExport(
        files=tuple(files),
        pieces=n_pieces,
        strategy="split",
        message=(
            f"{n_pieces} pieces exceed {max_pieces} per upload: split into {n_files} uploads "
            f"of <= {max_pieces} pieces ({files[0].name} .. {files[-1].name}); fly them back "
            "to back; each piece's end state equals the next one's start "
            f"(C^{traj.degree - 1})." + notes
        ),
    )


def _read_table(path: Path) -> FloatArray:
    """The pieces of one file, shape (P, 33), columns :data:`COLUMNS`; durations > 0."""
    table = read_table(path, required=COLUMNS, unknown="refuse", min_rows=1, name="crazyswarm file")
    durations = table.column("duration")
    if np.any(durations <= 0.0):
        r = int(np.argmax(durations <= 0.0))
        raise InputError(
            f"{table.name} line {table.lines[r]}, column duration: got {durations[r]:g}, "
            "expected a duration > 0 s"
        )
    return table.data


def read_crazyswarm(path: str | Path | Sequence[str | Path]) -> PiecewisePolynomial:
    """Read one Crazyswarm CSV, or several uploads flown back to back.

    Parameters
    ----------
    path
        A file, or a sequence of files (e.g. the ``_part<i>.csv`` uploads of
        :func:`write_crazyswarm`) whose pieces are concatenated in time.

    Returns
    -------
    PiecewisePolynomial
        3 axes in the z-up world frame (Crazyswarm's frame; nothing converted),
        metres, time from 0; yaw via :meth:`PiecewisePolynomial.evaluate_yaw`.

    Raises
    ------
    InputError
        Whatever :func:`~skyquill.io.table.read_table` refuses (missing or
        unreadable file, a missing, repeated or unknown column -- the header
        must hold exactly :data:`COLUMNS`, in any order and case --, a line
        with the wrong number of columns, a non-numeric, NaN or infinite cell,
        no rows), a duration <= 0 (naming file and line), or piece durations
        that do not add up to increasing times.
    """
    paths = [Path(path)] if isinstance(path, str | Path) else [Path(p) for p in path]
    if not paths:
        raise InputError("path: got an empty sequence, expected at least one CSV file")
    table = np.concatenate([_read_table(p) for p in paths])
    n = table.shape[0]
    breaks = np.concatenate([[0.0], np.cumsum(table[:, 0])])
    if not np.all(np.isfinite(breaks)) or np.any(np.diff(breaks) <= 0.0):
        raise InputError(
            f"{', '.join(map(str, paths))}: piece durations do not add up to a finite, "
            "strictly increasing time (durations too large or too small relative to the total)"
        )
    poly = table[:, 1:].reshape(n, 4, N_COEFFS).transpose(0, 2, 1)  # (P, 8, 4)
    return PiecewisePolynomial(breaks, poly[:, :, :3].copy(), poly[:, :, 3].copy())
