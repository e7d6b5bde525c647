"""What a vehicle can hold: the upload budget a plan is made to fit (``--target``).

A Crazyflie flies polynomial trajectories from its 4096-byte trajectory
memory (crazyflie-firmware ``src/modules/src/crtp_commander_high_level.c``,
``TRAJECTORY_MEMORY_SIZE 4096``). cflib's ``Poly4D`` packs a raw piece as
the duration and 8 coefficients for each of x, y, z and yaw, all float32:
33 x 4 B = 132 B (cflib ``cflib/crazyflie/mem/trajectory_memory.py``), so 31
pieces fit, in total. A longer flight is several uploads flown one after
another; the next upload can only be written while the vehicle holds still,
so uploads change where the plan is at rest -- between the pieces of a
:class:`~skyquill.trajectory.RestToRestSequence` -- and a planner that
targets the vehicle puts a hover of :attr:`UploadTarget.hover_s` there.

:func:`plan_uploads` is the one place that decides the uploads of a plan; the
planners check their result with it and the Crazyswarm exporter writes what
it returns.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from skyquill.errors import InputError
from skyquill.trajectory import (
    PiecewisePolynomial,
    RestToRestSequence,
    SplineTrajectory,
    Trajectory,
)
from skyquill.validation import FloatArray

#: Largest spread of a hover's control points, m (a hover is one point).
HOVER_TOLERANCE_M = 1e-9


@dataclass(frozen=True)
class UploadTarget:
    """A vehicle's trajectory memory and how a plan is cut into uploads for it.

    Attributes
    ----------
    name
        The ``--target`` name.
    memory_bytes
        Trajectory memory, B.
    bytes_per_piece
        One raw polynomial piece as uploaded, B.
    max_degree
        Highest polynomial degree the vehicle evaluates.
    hover_s
        Hover planned before every upload after the first, s: the vehicle
        holds its last setpoint while the next upload is written (cflib writes
        4 KB in well under a second over Crazyradio PA).
    """

    name: str
    memory_bytes: int
    bytes_per_piece: int
    max_degree: int
    hover_s: float

    @property
    def max_pieces(self) -> int:
        """Pieces one upload holds."""
        return self.memory_bytes // self.bytes_per_piece


CRAZYFLIE = UploadTarget("crazyflie", 4096, 132, 7, 1.0)
#: ``--target`` choices.
TARGETS: dict[str, UploadTarget] = {CRAZYFLIE.name: CRAZYFLIE}
#: How a plan was made to fit: one upload over the whole flight, or several
#: flown rest to rest with a hover between them.
Strategy = Literal["one-upload", "split"]


@dataclass(frozen=True)
class Upload:
    """One upload: consecutive motion pieces of a plan, flown from rest to rest.

    Attributes
    ----------
    start_s, end_s
        When it is flown on the plan's clock, s.
    parts
        The plan's pieces it holds (splines or polynomials of degree at most
        the target's), in order.
    pieces
        Polynomial pieces in the upload (knot spans of its parts).
    hover_before_s
        Planned hover before it (0 for the first), s.
    """

    start_s: float
    end_s: float
    parts: tuple[Trajectory, ...]
    pieces: int
    hover_before_s: float


def uploads_summary(
    target: UploadTarget, strategy: Strategy, uploads: tuple[Upload, ...]
) -> dict[str, Any]:
    """The ``"target"`` section of a planning command's ``summary.json`` (s, pieces, B)."""
    return {
        "name": target.name,
        "strategy": strategy,
        "max_pieces_per_upload": target.max_pieces,
        "hover_s": target.hover_s,
        "pieces": sum(u.pieces for u in uploads),
        "uploads": [
            {
                "pieces": u.pieces,
                "bytes": u.pieces * target.bytes_per_piece,
                "start_s": u.start_s,
                "end_s": u.end_s,
                "hover_before_s": u.hover_before_s,
            }
            for u in uploads
        ],
    }


def hover(position: FloatArray, duration: float) -> SplineTrajectory:
    """Holding ``position`` (d,) for ``duration`` s: a one-span constant cubic spline."""
    points = np.repeat(np.asarray(position, dtype=float)[None, :], 4, axis=0)
    return SplineTrajectory(points, 3, float(duration))


def is_hover(traj: Trajectory) -> bool:
    """Whether ``traj`` is a spline that holds one point (no upload needed)."""
    if not isinstance(traj, SplineTrajectory):
        return False
    return bool(np.ptp(traj.control_points, axis=0).max() <= HOVER_TOLERANCE_M)


def polynomial_pieces(traj: Trajectory, max_degree: int) -> int | None:
    """Polynomial pieces of ``traj`` as a vehicle would hold them; ``None`` if not polynomial.

    A spline counts its knot spans, a piecewise polynomial its pieces; both
    only when their degree is at most ``max_degree``.
    """
    if isinstance(traj, SplineTrajectory) and traj.degree <= max_degree:
        return len(traj.breakpoints) - 1
    if isinstance(traj, PiecewisePolynomial) and traj.degree <= max_degree:
        return traj.n_pieces
    return None


def plan_uploads(traj: Trajectory, target: UploadTarget) -> tuple[Upload, ...]:
    """Cut ``traj`` into the uploads ``target`` flies, in flight order.

    Hovers are not uploaded (the vehicle holds its last setpoint); consecutive
    motion pieces are packed greedily into uploads of at most
    :attr:`UploadTarget.max_pieces` pieces, changing upload only where the
    sequence is at rest.

    Raises
    ------
    InputError
        A part that is not a polynomial of degree at most the target's, or one
        with more pieces than an upload holds; the message says how to plan
        for the target.
    """
    uploads: list[Upload] = []
    current: list[tuple[float, Trajectory, int]] = []
    gap = before = 0.0  # hover since the last upload; hover before the one being packed
    for start, part in _parts(traj):
        if is_hover(part):
            if current:
                uploads.append(_upload(current, before))
                current = []
            gap += part.duration
            continue
        pieces = _pieces(part, target, start)
        if current and sum(c[2] for c in current) + pieces > target.max_pieces:
            uploads.append(_upload(current, before))
            current = []
        if not current:
            before, gap = (gap if uploads else 0.0), 0.0
        current.append((start, part, pieces))
    if current:
        uploads.append(_upload(current, before))
    return tuple(uploads)


def _parts(traj: Trajectory) -> Iterator[tuple[float, Trajectory]]:
    if isinstance(traj, RestToRestSequence):
        for start, part in zip(traj.starts, traj.pieces, strict=False):
            yield float(start), part
    else:
        yield 0.0, traj


def _pieces(part: Trajectory, target: UploadTarget, start: float) -> int:
    pieces = polynomial_pieces(part, target.max_degree)
    if pieces is None:
        raise InputError(
            f"trajectory: got a {type(part).__name__} at {start:.3f} s, expected polynomial "
            f"pieces of degree at most {target.max_degree} for a {target.name}; plan it "
            f"with target {target.name!r}"
        )
    if pieces > target.max_pieces:
        raise InputError(
            f"trajectory: got {pieces} pieces between rests at {start:.3f} s, expected at "
            f"most {target.max_pieces} per upload ({target.memory_bytes} B of trajectory "
            f"memory) for a {target.name}; plan it with target {target.name!r}"
        )
    return pieces


def _upload(current: list[tuple[float, Trajectory, int]], hover_before: float) -> Upload:
    start = current[0][0]
    end = current[-1][0] + current[-1][1].duration
    parts = tuple(c[1] for c in current)
    return Upload(start, end, parts, sum(c[2] for c in current), hover_before)
