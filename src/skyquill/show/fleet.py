"""Every drone's polynomial pieces in one table: positions and motion bounds for any drones at once.

The separation check asks, over and over, where drone ``who[k]`` is at time
``t[k]`` and how fast it can move on ``[a[k], b[k]]``, for hundreds of
thousands of ``k`` spread over all the drones. Asking each drone's
:class:`~skyquill.show.motion.Motion` in turn costs a Python call per drone
per question (a thousand drones: a thousand calls, each over a mask of every
question); here the pieces of all drones sit in one table, padded to one
degree, and one vectorised lookup answers every question at once.

The bounds are exactly :class:`~skyquill.show.motion.Motion`'s (the Taylor
bound at the midpoint inside one piece, the largest over the parts across piece
boundaries, the jumps where pieces meet).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from skyquill.show.motion import LocalMotion, Motion, taylor_bound
from skyquill.trajectory.horner import horner_columns, power_columns
from skyquill.validation import FloatArray

IntArray = NDArray[np.intp]


class Fleet:
    """The pieces of every motion (all on one clock), looked up by drone and time.

    Parameters
    ----------
    motions
        One per drone, all with the same horizon.
    """

    def __init__(self, motions: Sequence[Motion]) -> None:
        self.order = max(m.order for m in motions)
        counts = np.array([m.breaks.size - 1 for m in motions], dtype=np.intp)
        #: First piece of each drone in the table, and one past the last drone's, (N + 1,).
        self.offset = np.concatenate([[0], np.cumsum(counts)]).astype(np.intp)
        self.start = np.concatenate([m.breaks[:-1] for m in motions])
        self.end = np.concatenate([m.breaks[1:] for m in motions])
        self.coeffs = np.concatenate([_padded(m.coeffs, self.order) for m in motions])
        # Each derivative's coefficients, one block per power, made once for the many lookups.
        self._columns = [power_columns(self.coeffs, q) for q in range(self.order)]
        self.jump = np.array([m.jump_m for m in motions])
        self.horizon = max(m.horizon for m in motions)
        # Each drone's pieces shifted to their own stretch of one sorted axis; the
        # shift is a power of two, so drone d's time t lands within round-off of its key.
        self._span = 2.0 ** math.ceil(math.log2(self.horizon + 2.0))
        self._owner = np.repeat(np.arange(len(motions)), counts)
        self._keys = self.start + self._owner * self._span
        self._whole = self._within(self.start, self.end, np.arange(self.start.size))
        # with a 0 past the last row, for reduceat (made once: a played show has millions)
        self._whole_padded = np.append(self._whole, 0.0)

    def __len__(self) -> int:
        return int(self.jump.size)

    def piece(self, who: IntArray, t: FloatArray, side: str = "right") -> IntArray:
        """The piece of drone ``who`` (K,) at time ``t`` (K,): its row in the table (K,).

        ``side="right"``: the last piece starting at or before ``t``; ``"left"``: the
        last starting before ``t`` (the piece an interval ending at ``t`` ends in).
        Clipped to the drone's first and last pieces.
        """
        found = np.searchsorted(self._keys, t + who * self._span, side="right") - 1
        low, high = self.offset[who], self.offset[who + 1] - 1
        idx = np.clip(found, low, high)
        # The shifted times are off by round-off (1e-10 s): settle the few at a boundary
        # (each pass moves them one piece towards the right one).
        while True:
            if side == "right":
                back = (idx > low) & (self.start[idx] > t)
                ahead = (idx < high) & (self.start[np.minimum(idx + 1, high)] <= t)
            else:
                back = (idx > low) & (self.start[idx] >= t)
                ahead = (idx < high) & (self.start[np.minimum(idx + 1, high)] < t)
            if not (back.any() or ahead.any()):
                break
            idx = idx - back + (ahead & ~back)
        return np.asarray(idx, dtype=np.intp)

    def position(self, who: IntArray, t: FloatArray) -> FloatArray:
        """Positions of drones ``who`` (K,) at times ``t`` (K,), shape (K, 3), m."""
        idx = self.piece(who, t)
        return horner_columns(self._columns[0], idx, t - self.start[idx]).reshape(t.size, 3)

    def _derivatives(self, t: FloatArray, idx: IntArray) -> FloatArray:
        """Orders 1 to ``K - 1`` of pieces ``idx`` at ``t``, shape (M, K - 1, 3)."""
        tau = t - self.start[idx]
        if self.order < 2:
            return np.zeros((t.size, 0, 3))
        return np.stack(
            [
                horner_columns(self._columns[q], idx, tau).reshape(t.size, 3)
                for q in range(1, self.order)
            ],
            axis=1,
        )

    def _within(self, a: FloatArray, b: FloatArray, idx: IntArray) -> FloatArray:
        """Speed bound of pieces ``idx`` on ``[a, b]`` (inside each piece), m/s."""
        return taylor_bound(self._derivatives(0.5 * (a + b), idx), 0.5 * (b - a))

    def local(self, who: IntArray, a: FloatArray, b: FloatArray) -> LocalMotion:
        """Derivatives at the midpoints and speed bounds of drones ``who`` on ``[a, b]`` (K,)."""
        first = self.piece(who, a, "right")
        last = np.maximum(self.piece(who, b, "left"), first)
        inside = first == last
        derivatives = self._derivatives(0.5 * (a + b), first)
        speed = taylor_bound(derivatives, 0.5 * (b - a))
        out = ~inside
        if out.any():
            speed[out] = self._straddling(a[out], b[out], first[out], last[out])
            derivatives[out] = 0.0
        jump = (last - first).astype(float) * self.jump[who]
        return LocalMotion(derivatives, inside, speed, jump)

    def _straddling(
        self, a: FloatArray, b: FloatArray, first: IntArray, last: IntArray
    ) -> FloatArray:
        """Speed bounds on intervals across piece boundaries: the max over the parts."""
        head = self._within(a, self.end[first], first)
        tail = self._within(self.start[last], b, last)
        bound = np.maximum(head, tail)
        between = last - first >= 2
        if between.any():
            bound[between] = np.maximum(
                bound[between], self.largest_whole(first[between] + 1, last[between])
            )
        return bound

    def largest_whole(self, begin: IntArray, stop: IntArray) -> FloatArray:
        """The largest whole-piece speed bound over table rows ``[begin, stop)`` (K,), m/s.

        Empty ranges give 0.
        """
        out = np.zeros(begin.size)
        nonempty = stop > begin
        if nonempty.any():
            edges = np.column_stack([begin[nonempty], stop[nonempty]]).ravel()
            out[nonempty] = np.maximum.reduceat(self._whole_padded, edges)[::2]
        return out


def _padded(coeffs: FloatArray, order: int) -> FloatArray:
    """Coefficients (P, K, 3) padded with zeros to (P, order, 3)."""
    return np.pad(coeffs, ((0, 0), (0, order - coeffs.shape[1]), (0, 0)))
