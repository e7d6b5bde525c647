"""A Crazyflie's trajectory memory: cflib's packing and the firmware's float32 evaluation.

What a Crazyflie flies is not the CSV but the bytes cflib writes into its
4096-byte trajectory memory, evaluated by the firmware in float32. This
module is a faithful copy of both, so that an export can be checked as it
will be flown:

- **Packing** (:func:`pack_pieces`): cflib 0.1.34
  ``cflib/crazyflie/mem/trajectory_memory.py``, ``Poly4D.pack``: per piece
  the 8 coefficients of x, y, z and yaw (lowest power first), then the
  duration, each ``struct.pack('<f', ...)`` -- little-endian float32,
  rounded to nearest -- 33 x 4 = 132 B. ``TrajectoryMemory.write_data``
  concatenates the pieces from address 0.
- **Evaluation** (:class:`FirmwareTrajectory`): crazyflie-firmware
  ``src/modules/src/pptraj.c``: ``piecewise_eval`` finds the piece by
  subtracting each piece's float32 duration from the float32 local time
  until ``t <= duration`` (past the last piece it holds the end position with
  velocity, acceleration and jerk set to 0); ``poly4d_eval`` evaluates each
  axis with ``polyval`` (float32 Horner, ``x = x * t + p[i]``) and takes
  derivatives with ``polyder`` (``p[i-1] = i * p[i]`` in float32, in place,
  once per order).

Not modelled: the on-board clock (``usecTimestamp() / 1e6`` as float, so
the local time is rounded to float32 of the uptime, which shifts *when* a
point is flown by microseconds but not the curve), a compiler contracting
``x * t + p[i]`` into one fused multiply-add (a last-bit difference), and
``timescale`` (1 here: ``start_trajectory(time_scale=1.0)``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.trajectory.base import Samples, evaluation_times, sample
from skyquill.validation import FloatArray, as_array, as_int

#: Trajectory memory, B (``crtp_commander_high_level.c``: ``TRAJECTORY_MEMORY_SIZE``).
MEMORY_BYTES = 4096
#: Coefficients per axis (``pptraj.h``, ``PP_SIZE`` = ``PP_DEGREE + 1`` = 8).
PP_SIZE = 8
#: Axes of a ``poly4d``: x, y, z, yaw.
N_AXES = 4
#: One packed piece, B: 4 x 8 coefficients and the duration, float32.
PIECE_BYTES = 4 * (N_AXES * PP_SIZE + 1)
#: Little-endian float32, as ``struct.pack('<f')`` writes it.
FLOAT32_LE = np.dtype("<f4")

Float32Array = NDArray[np.float32]


def pack_pieces(table: FloatArray) -> bytes:
    """The bytes cflib writes for ``table``: ``Poly4D.pack`` of each row, concatenated.

    Parameters
    ----------
    table
        Shape (P, 33): the rows of a Crazyswarm CSV (duration, s; then 8
        coefficients each of x, y, z in m / s^j and yaw in rad / s^j).

    Returns
    -------
    bytes
        ``132 * P`` bytes: per piece x^0..x^7, y^0..y^7, z^0..z^7,
        yaw^0..yaw^7, duration as little-endian float32 (the duration last,
        unlike the CSV).

    Raises
    ------
    InputError
        A value that float32 cannot hold (``struct.pack`` would raise
        ``OverflowError``) or that is not finite.
    """
    table = as_array("table", table, shape=(None, 1 + N_AXES * PP_SIZE))
    with np.errstate(over="ignore"):
        # numpy's float64 -> float32 cast rounds to nearest even, like struct.pack('<f').
        rows = np.column_stack([table[:, 1:], table[:, :1]]).astype(FLOAT32_LE)
    if not np.all(np.isfinite(rows)):
        r, c = np.argwhere(~np.isfinite(rows))[0]
        raise InputError(
            f"table: got {table[r, (c + 1) % table.shape[1]]:g} in row {r}, expected a value "
            "float32 can hold (|x| < 3.4e38)"
        )
    return rows.tobytes()


def unpack_pieces(data: bytes) -> tuple[Float32Array, Float32Array]:
    """Durations and coefficients from trajectory-memory bytes, as the firmware reads them.

    Parameters
    ----------
    data
        ``132 * P`` bytes, ``P >= 1`` (``struct poly4d`` of ``pptraj.h``:
        ``float p[4][8]; float duration;``).

    Returns
    -------
    durations : numpy.ndarray of float32, shape (P,)
        Seconds.
    coeffs : numpy.ndarray of float32, shape (P, 4, 8)
        Per piece and axis (x, y, z, yaw), lowest power first.

    Raises
    ------
    InputError
        A length that is not a positive multiple of :data:`PIECE_BYTES`, or
        more than :data:`MEMORY_BYTES`.
    """
    size = len(data)
    if size == 0 or size % PIECE_BYTES:
        raise InputError(
            f"data: got {size} B, expected a positive multiple of {PIECE_BYTES} B (one "
            "packed Poly4D per piece)"
        )
    if size > MEMORY_BYTES:
        raise InputError(
            f"data: got {size} B ({size // PIECE_BYTES} pieces), expected at most "
            f"{MEMORY_BYTES} B, the Crazyflie's trajectory memory"
        )
    rows = np.frombuffer(data, dtype=FLOAT32_LE).reshape(-1, N_AXES * PP_SIZE + 1)
    durations = rows[:, -1].astype(np.float32)
    coeffs = rows[:, :-1].reshape(-1, N_AXES, PP_SIZE).astype(np.float32)
    return durations, coeffs


def polyval(coeffs: Float32Array, t: Float32Array) -> Float32Array:
    """``pptraj.c`` ``polyval``: float32 Horner, one polynomial (..., 8) per time (...)."""
    x = np.zeros(t.shape, dtype=np.float32)
    for i in range(PP_SIZE - 1, -1, -1):
        # Two roundings, multiply then add, as the C statement x = x * t + p[i] reads.
        x = (x * t).astype(np.float32) + coeffs[..., i]
    return x.astype(np.float32)


def polyder(coeffs: Float32Array) -> Float32Array:
    """``pptraj.c`` ``polyder``: ``p[i-1] = i * p[i]`` in float32, last coefficient 0."""
    out = np.zeros_like(coeffs)
    out[..., :-1] = coeffs[..., 1:] * np.arange(1, PP_SIZE, dtype=np.float32)
    return out


@dataclass(frozen=True)
class FirmwareTrajectory:
    """One upload as the firmware flies it (``pptraj.c`` ``piecewise_eval``), timescale 1.

    Parameters
    ----------
    durations
        Piece durations, shape (P,), float32 s, > 0.
    coeffs
        Shape (P, 4, 8), float32: x, y, z (m) and yaw (rad), lowest power first.

    Notes
    -----
    Satisfies :class:`~skyquill.trajectory.Trajectory` (3 axes, z-up world
    frame, time from 0) so that the dense limit check runs on it; yaw via
    :meth:`evaluate_yaw`.
    """

    durations: Float32Array
    coeffs: Float32Array

    def __post_init__(self) -> None:
        durations = np.asarray(self.durations, dtype=np.float32).reshape(-1)
        coeffs = np.asarray(self.coeffs, dtype=np.float32)
        if coeffs.shape != (durations.size, N_AXES, PP_SIZE) or durations.size == 0:
            raise InputError(
                f"coeffs: got shape {coeffs.shape} for {durations.size} durations, expected "
                f"({max(durations.size, 1)}, {N_AXES}, {PP_SIZE})"
            )
        bad = ~(np.isfinite(durations) & (durations > 0))
        if bad.any():
            i = int(np.argmax(bad))
            raise InputError(f"durations: got {durations[i]:g} at piece {i}, expected > 0 s")
        if not np.all(np.isfinite(coeffs)):
            raise InputError("coeffs: got a NaN or infinite coefficient, expected finite values")
        for name, value in (("durations", durations), ("coeffs", coeffs)):
            value.setflags(write=False)
            object.__setattr__(self, name, value)

    @classmethod
    def from_bytes(cls, data: bytes) -> FirmwareTrajectory:
        """The upload held in ``data`` (:func:`unpack_pieces`)."""
        return cls(*unpack_pieces(data))

    @property
    def duration(self) -> float:
        """Length, s (float64 sum of the float32 durations)."""
        return float(self.breakpoints[-1])

    @property
    def dim(self) -> int:
        """3: x, y, z."""
        return 3

    @property
    def n_pieces(self) -> int:
        """Pieces ``P``."""
        return int(self.durations.size)

    @property
    def breakpoints(self) -> FloatArray:
        """Piece boundaries, shape (P + 1,), s."""
        return np.concatenate([[0.0], np.cumsum(self.durations.astype(float))])

    def evaluate(self, t: FloatArray, order: int = 0) -> FloatArray:
        """Derivative ``order`` of x, y, z at local times ``t`` (N,); returns (N, 3), float64."""
        return self._evaluate(t, order)[:, :3]

    def evaluate_yaw(self, t: FloatArray, order: int = 0) -> FloatArray:
        """Derivative ``order`` of yaw at ``t`` (N,); returns (N,), rad / s^order."""
        return self._evaluate(t, order)[:, 3]

    def sample(self, rate: float) -> Samples:
        """Samples at ``rate`` Hz (position to jerk), including both ends."""
        return sample(self, rate)

    def _evaluate(self, t: FloatArray, order: int) -> FloatArray:
        order = as_int("order", order, low=0)
        remaining = evaluation_times(t, self.duration).astype(np.float32)
        piece = np.full(remaining.shape, -1)
        for k, d in enumerate(self.durations):
            # piecewise_eval: `if (t <= piece->duration) evaluate; else t -= duration`.
            here = (piece < 0) & (remaining <= d)
            piece[here] = k
            later = piece < 0
            remaining[later] = remaining[later] - d
        past = piece < 0
        # Past the end: the last piece at its own duration, derivatives set to 0.
        piece[past] = self.n_pieces - 1
        remaining[past] = self.durations[-1]
        coeffs = self.coeffs[piece]  # (N, 4, 8)
        for _ in range(order):
            coeffs = polyder(coeffs)
        out = polyval(coeffs, remaining[:, None]).astype(float)
        if order > 0:
            out[past] = 0.0
        return out


def end_states(upload: FirmwareTrajectory) -> tuple[FloatArray, FloatArray]:
    """Position, velocity, acceleration at the start and at the end of ``upload``.

    Evaluated with ``poly4d_eval`` on the first piece at 0 and on the last
    piece at its own duration (where the firmware takes the held end position
    from), i.e. what the vehicle is commanded on either side of the upload
    before the firmware's hold sets the derivatives to 0.

    Returns
    -------
    start, end : numpy.ndarray, shape (3, 3)
        Rows position (m), velocity (m/s), acceleration (m/s^2); columns x, y, z.
    """
    out = []
    for k, tau in ((0, np.float32(0.0)), (upload.n_pieces - 1, upload.durations[-1])):
        coeffs = upload.coeffs[k][None]
        rows = []
        for _ in range(3):
            rows.append(polyval(coeffs, np.array([[tau]], dtype=np.float32))[0, :3])
            coeffs = polyder(coeffs)
        out.append(np.array(rows, dtype=float))
    return out[0], out[1]


@dataclass(frozen=True)
class FlownUploads:
    """Several uploads flown on one clock: each from its start time, holding in between.

    Parameters
    ----------
    starts_s
        When each upload is started on the plan's clock, shape (U,), s,
        increasing, each at or after the previous upload's end.
    uploads
        What the firmware flies for each (:class:`FirmwareTrajectory`).
    duration_s
        The plan's length, s, at or after the last upload's end.
    axes
        Axes evaluated: 3 (x, y, z), or 2 (x, y) for a 2-D plan written
        with z = 0.

    Notes
    -----
    Before the first upload the vehicle holds its start, between uploads the
    previous end (the firmware's hold past the end of a trajectory, then the
    script's ``go_to`` to the same point while the next upload is written),
    after the last one its end. Each upload's local time is the plan time
    minus its start, rounded to float32 as the firmware's clock is.
    """

    starts_s: FloatArray
    uploads: tuple[FirmwareTrajectory, ...]
    duration_s: float
    axes: int = 3

    def __post_init__(self) -> None:
        as_int("axes", self.axes, low=2, high=3)
        uploads = tuple(self.uploads)
        starts = as_array("starts_s", self.starts_s, shape=(len(uploads),))
        if not uploads:
            raise InputError("uploads: got none, expected at least one upload")
        ends = starts + np.array([u.duration for u in uploads])
        tol = 1e-6
        overlap = np.any(starts[1:] < ends[:-1] - tol)
        if starts[0] < 0 or overlap or self.duration_s < ends[-1] - tol:
            raise InputError(
                f"starts_s: got {starts.tolist()} for uploads ending at {ends.tolist()} in a "
                f"{self.duration_s:g} s plan, expected each to start after the previous one "
                "ends, all within the plan"
            )
        starts.setflags(write=False)
        object.__setattr__(self, "starts_s", starts)
        object.__setattr__(self, "uploads", uploads)

    @property
    def duration(self) -> float:
        """Length, s."""
        return float(self.duration_s)

    @property
    def dim(self) -> int:
        """Number of axes (:attr:`axes`)."""
        return self.axes

    @property
    def breakpoints(self) -> FloatArray:
        """Every piece boundary on the plan's clock, with 0 and the end, shape (L + 1,), s."""
        inner = [s + u.breakpoints for s, u in zip(self.starts_s, self.uploads, strict=True)]
        points = np.unique(np.concatenate([[0.0, self.duration], *inner]))
        return points[(points >= 0.0) & (points <= self.duration)]

    def evaluate(self, t: FloatArray, order: int = 0) -> FloatArray:
        """Derivative ``order`` at plan times ``t`` (N,); returns (N, axes), float64."""
        times = evaluation_times(t, self.duration)
        which = np.clip(np.searchsorted(self.starts_s, times, side="right") - 1, 0, None)
        out = np.empty((times.size, 3))
        for k in np.unique(which):
            mask = which == k
            upload = self.uploads[k]
            local = np.clip(times[mask] - self.starts_s[k], 0.0, upload.duration)
            # float32 local time, as the firmware subtracts t_begin in float.
            local = np.minimum(local.astype(np.float32).astype(float), upload.duration)
            out[mask] = upload.evaluate(local, order)
            if order > 0:
                holding = (times[mask] < self.starts_s[k]) | (
                    times[mask] > self.starts_s[k] + upload.duration
                )
                out[np.flatnonzero(mask)[holding]] = 0.0
        return out[:, : self.axes]

    def sample(self, rate: float) -> Samples:
        """Samples at ``rate`` Hz (position to jerk), including both ends."""
        return sample(self, rate)


def flown_uploads(
    starts_s: Sequence[float], data: Sequence[bytes], duration_s: float, axes: int = 3
) -> FlownUploads:
    """:class:`FlownUploads` of the packed uploads ``data`` started at ``starts_s``."""
    return FlownUploads(
        np.asarray(starts_s, dtype=float),
        tuple(FirmwareTrajectory.from_bytes(d) for d in data),
        duration_s,
        axes,
    )
