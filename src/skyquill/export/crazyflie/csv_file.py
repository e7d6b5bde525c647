"""Crazyswarm2 / uav_trajectories polynomial CSV: one upload per file, exact, and read back.

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
``tau^(k+1) .. tau^7`` zero; a :class:`PiecewisePolynomial` of degree ``<= 7``
is written piece by piece. One file is one upload: deciding the uploads
(at most 31 pieces each, changing only where the vehicle is at rest) is
:func:`skyquill.targets.plan_uploads`' job, and what the Crazyflie does with
the numbers is :mod:`skyquill.export.crazyflie.memory`'s.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from skyquill.errors import InputError
from skyquill.io.table import read_table
from skyquill.trajectory import PiecewisePolynomial, SplineTrajectory, Trajectory
from skyquill.validation import FloatArray, as_float

#: Coefficients per axis in the file (degree 7).
N_COEFFS = 8
#: Axes in the file, in column order.
AXES = ("x", "y", "z", "yaw")
#: The header, column by column.
COLUMNS: tuple[str, ...] = ("duration", *(f"{a}^{j}" for a in AXES for j in range(N_COEFFS)))
#: The header line as written.
HEADER = ",".join(COLUMNS)


def crazyswarm_pieces(traj: SplineTrajectory | PiecewisePolynomial, yaw: float = 0.0) -> FloatArray:
    """The rows of the Crazyswarm CSV for ``traj``: one per knot span or piece, exact.

    Parameters
    ----------
    traj
        Spline or piecewise polynomial of degree at most 7 with 2 or 3 axes,
        z-up world frame, metres. A 2-D trajectory gets ``z = 0``.
    yaw
        Constant yaw, rad (the ``yaw^0`` column), used when ``traj`` carries
        no yaw polynomial of its own.

    Returns
    -------
    numpy.ndarray, shape (L, 33)
        Column 0 is the piece duration, s; then 8 coefficients (``tau^0`` to
        ``tau^7``, lowest first) for each of x, y, z (m) and yaw (rad).
    """
    yaw = as_float("yaw", yaw)
    breaks, coeffs, yaw_coeffs = _power_basis(traj)
    n_pieces, n_coef, dim = coeffs.shape
    if n_coef > N_COEFFS:
        raise InputError(
            f"traj: got degree {n_coef - 1}, expected at most {N_COEFFS - 1} (the Crazyflie "
            "evaluates degree-7 polynomials)"
        )
    poly = np.zeros((n_pieces, N_COEFFS, 4))  # zero padding: degree < 7, z of 2-D, yaw
    poly[:, :n_coef, :dim] = coeffs
    poly[:, 0, 3] = yaw
    if yaw_coeffs is not None:
        poly[:, :, 3] = 0.0
        poly[:, : yaw_coeffs.shape[1], 3] = yaw_coeffs[:, :N_COEFFS]
    # Axis-major columns: x^0..x^7, y^0..y^7, ...
    return np.column_stack([np.diff(breaks), poly.transpose(0, 2, 1).reshape(n_pieces, -1)])


def _power_basis(
    traj: SplineTrajectory | PiecewisePolynomial,
) -> tuple[FloatArray, FloatArray, FloatArray | None]:
    """Breaks (L + 1,), coefficients (L, K, d) and yaw coefficients (L, K_yaw) or None."""
    if isinstance(traj, SplineTrajectory):
        breaks, coeffs = traj.to_piecewise_polynomial()
        yaw = None
    elif isinstance(traj, PiecewisePolynomial):
        breaks, coeffs, yaw = traj.breaks, traj.coeffs, traj.yaw_coeffs
        if yaw is not None and yaw.shape[1] > N_COEFFS and np.any(yaw[:, N_COEFFS:]):
            raise InputError(
                f"traj: got a yaw polynomial of degree {yaw.shape[1] - 1}, expected at most "
                f"{N_COEFFS - 1}"
            )
    else:
        raise InputError(
            f"traj: got {type(traj).__name__}, expected a SplineTrajectory or a "
            "PiecewisePolynomial (the export is exact only for piecewise polynomials)"
        )
    if traj.dim not in (2, 3):
        raise InputError(f"traj: got a {traj.dim}-D trajectory, expected 2 or 3 axes")
    return breaks, coeffs, yaw


def upload_pieces(parts: Sequence[Trajectory], yaw: float = 0.0) -> FloatArray:
    """The rows of one upload: the pieces of ``parts`` (flown back to back), shape (P, 33).

    ``parts`` are the :attr:`~skyquill.targets.Upload.parts` of an upload,
    each a :class:`SplineTrajectory` or :class:`PiecewisePolynomial`
    (:func:`crazyswarm_pieces`); an empty sequence is refused.
    """
    if not parts:
        raise InputError("parts: got none, expected at least one trajectory")
    tables = []
    for part in parts:
        if not isinstance(part, SplineTrajectory | PiecewisePolynomial):
            raise InputError(
                f"parts: got a {type(part).__name__}, expected a SplineTrajectory or a "
                "PiecewisePolynomial"
            )
        tables.append(crazyswarm_pieces(part, yaw))
    return np.concatenate(tables)


def write_crazyswarm(table: FloatArray, path: str | Path) -> Path:
    """Write the rows ``table`` (P, 33) (:func:`upload_pieces`) as one Crazyswarm CSV.

    Values are printed with ``%.17g`` (float64 round trip), so the file holds
    exactly the polynomials it was given; ``path`` is returned.
    """
    table = np.asarray(table, dtype=float)
    if table.ndim != 2 or table.shape[1] != len(COLUMNS) or table.shape[0] < 1:
        raise InputError(
            f"table: got shape {table.shape}, expected (P, {len(COLUMNS)}) with P >= 1"
        )
    path = Path(path)
    lines = [HEADER, *(",".join(f"{v:.17g}" for v in row) for row in table)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def read_crazyswarm_table(path: str | Path) -> FloatArray:
    """The pieces of one Crazyswarm CSV, shape (P, 33), columns :data:`COLUMNS`.

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
    table = read_table(path, required=COLUMNS, unknown="refuse", min_rows=1, name="crazyswarm file")
    durations = table.column("duration")
    if np.any(durations <= 0.0):
        r = int(np.argmax(durations <= 0.0))
        raise InputError(
            f"{table.name} line {table.lines[r]}, column duration: got {durations[r]:g}, "
            "expected a duration > 0 s"
        )
    breaks = np.concatenate([[0.0], np.cumsum(durations)])
    if not np.all(np.isfinite(breaks)) or np.any(np.diff(breaks) <= 0.0):
        raise InputError(
            f"{table.name}: piece durations do not add up to a finite, strictly increasing "
            "time (durations too large or too small relative to the total)"
        )
    return np.array(table.select(COLUMNS))


def read_crazyswarm(path: str | Path) -> PiecewisePolynomial:
    """Read one Crazyswarm CSV (one upload) in float64, as Crazyswarm2's ``loadcsv`` does.

    Parameters
    ----------
    path
        The file.

    Returns
    -------
    PiecewisePolynomial
        3 axes in the z-up world frame (Crazyswarm's frame; nothing converted),
        metres, time from 0; yaw via :meth:`PiecewisePolynomial.evaluate_yaw`.

    Raises
    ------
    InputError
        As :func:`read_crazyswarm_table`.
    """
    table = read_crazyswarm_table(path)
    n = table.shape[0]
    breaks = np.concatenate([[0.0], np.cumsum(table[:, 0])])
    poly = table[:, 1:].reshape(n, 4, N_COEFFS).transpose(0, 2, 1)  # (P, 8, 4)
    return PiecewisePolynomial(breaks, poly[:, :, :3].copy(), poly[:, :, 3].copy())
