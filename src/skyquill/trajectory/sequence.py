"""Trajectories flown one after another, at rest where they meet.

Stop-and-go legs, a coverage flown part by part, a mission split into
uploads with a hover between them: each piece starts and ends at rest, so the
sequence is as smooth as its pieces (velocity and acceleration are 0 at
every join, checked at construction).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.trajectory.base import (
    Kinked,
    Samples,
    Trajectory,
    derivatives,
    evaluation_times,
    sample,
)
from skyquill.validation import FloatArray, as_int

#: Largest position gap between consecutive pieces (m), and speed (m/s) and acceleration
#: (m/s^2) at a join that still count as rest.
JOIN_TOLERANCE_M = 1e-6


@dataclass(frozen=True)
class RestToRestSequence:
    """``pieces`` flown back to back.

    Parameters
    ----------
    pieces
        At least one trajectory, all with the same number of axes; each next
        one starts where the previous one ends, and both are at rest there.
    tolerance
        Largest gap (m), speed (m/s) and acceleration (m/s^2) at a join that still
        counts as meeting at rest; float32 pieces (a Crazyflie's own polynomials) end
        within a float32 rounding of their targets and need more than the default.
    """

    pieces: tuple[Trajectory, ...]
    tolerance: float = JOIN_TOLERANCE_M

    def __post_init__(self) -> None:
        pieces = tuple(self.pieces)
        if not pieces:
            raise InputError("pieces: got none, expected at least one trajectory")
        dims = {p.dim for p in pieces}
        if len(dims) > 1:
            raise InputError(f"pieces: got axes {sorted(dims)}, expected one number of axes")
        for i in range(1, len(pieces)):
            _check_join(i, pieces[i - 1], pieces[i], self.tolerance)
        object.__setattr__(self, "pieces", pieces)

    @property
    def starts(self) -> FloatArray:
        """Start time of each piece and the end, shape (n + 1,), s."""
        return np.concatenate([[0.0], np.cumsum([p.duration for p in self.pieces])])

    @property
    def duration(self) -> float:
        """Total length, s."""
        return float(self.starts[-1])

    @property
    def dim(self) -> int:
        """Number of axes."""
        return self.pieces[0].dim

    @property
    def breakpoints(self) -> FloatArray:
        """Every piece's breakpoints on the sequence's clock, shape (L + 1,), s."""
        starts = self.starts
        shifted = [s + p.breakpoints[:-1] for s, p in zip(starts, self.pieces, strict=False)]
        return np.concatenate([*shifted, [starts[-1]]])

    def piece_at(self, t: FloatArray) -> NDArray[np.intp]:
        """Index of the piece flown at each time ``t`` (N,); a join belongs to the later piece."""
        return self._locate(evaluation_times(t, self.duration))

    def _locate(self, times: FloatArray) -> NDArray[np.intp]:
        last = len(self.pieces) - 1
        return np.clip(np.searchsorted(self.starts, times, side="right") - 1, 0, last)

    def kink_times(self) -> FloatArray:
        """Its pieces' kinks on the sequence's clock (see :class:`~.base.Kinked`), (K,), s."""
        kinks = [
            start + piece.kink_times()
            for start, piece in zip(self.starts, self.pieces, strict=False)
            if isinstance(piece, Kinked)
        ]
        return np.concatenate(kinks) if kinks else np.zeros(0)

    def evaluate(self, t: FloatArray, order: int = 0) -> FloatArray:
        """The ``order``-th time derivative at times ``t`` (N,); returns (N, d)."""
        return self.evaluate_orders(t, [order])[order]

    def evaluate_orders(self, t: FloatArray, orders: Sequence[int]) -> dict[int, FloatArray]:
        """``{n: self.evaluate(t, n)}`` for each of ``orders``, each piece's times found
        once and its derivatives taken together (:func:`~.base.derivatives`); (N, d) each."""
        checked = [as_int("order", n, low=0) for n in orders]
        times = evaluation_times(t, self.duration)
        which = self._locate(times)
        out = {n: np.empty((times.size, self.dim)) for n in checked}
        starts = self.starts
        # Each piece's times by one stable sort (index runs), not one mask per piece.
        order = np.argsort(which, kind="stable")
        bounds = np.searchsorted(which[order], np.arange(len(self.pieces) + 1))
        for k in np.flatnonzero(np.diff(bounds)):
            rows = order[bounds[k] : bounds[k + 1]]
            piece = self.pieces[k]
            local = np.clip(times[rows] - starts[k], 0.0, piece.duration)
            for n, values in derivatives(piece, local, checked).items():
                out[n][rows] = values
        return out

    def sample(self, rate: float) -> Samples:
        """Samples at ``rate`` Hz (position to jerk), including both ends."""
        return sample(self, rate)


def concatenate(pieces: Sequence[Trajectory]) -> Trajectory:
    """One trajectory for ``pieces`` flown back to back (the piece itself when there is one)."""
    return pieces[0] if len(pieces) == 1 else RestToRestSequence(tuple(pieces))


def _check_join(i: int, before: Trajectory, after: Trajectory, tolerance: float) -> None:
    end = np.array([before.duration])
    start = np.array([0.0])
    gap = float(np.linalg.norm(before.evaluate(end)[0] - after.evaluate(start)[0]))
    if gap > tolerance:
        raise InputError(
            f"pieces[{i}]: got a start {gap:.3g} m from where pieces[{i - 1}] ends, "
            f"expected at most {tolerance:g} m"
        )
    for order, name in ((1, "speed"), (2, "acceleration")):
        for which, traj, at in ((i - 1, before, end), (i, after, start)):
            value = float(np.linalg.norm(traj.evaluate(at, order)[0]))
            if value > tolerance:
                raise InputError(
                    f"pieces[{which}]: got {name} {value:.3g} at the join with the "
                    f"{'next' if which == i - 1 else 'previous'} piece, expected rest "
                    f"(at most {tolerance:g})"
                )
