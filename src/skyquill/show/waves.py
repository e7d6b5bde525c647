"""Which drones may move together, which must wait: delayed starts from straight paths.

For straight moves ``a_i -> b_i`` on one shared profile, the distance of two
drones of the same wave is ``|D0 + s (D1 - D0)|`` with ``s`` in [0, 1]: its
minimum has a closed form (:func:`closest_on_segments`). With the
minimum-squared-distance assignment, such synchronised moves keep drones
apart by at least ``1/sqrt(2)`` of their formations' spacing (Turpin, Michael
& Kumar, "CAPT", IJRR 2014), so most transitions need one wave.

Where straight paths come too close, a pair is resolved by order: waves are
flown one after another, so a drone only meets drones that are still (at their
start or their goal) or that move with it. ``i`` may go before ``j`` when
``i``'s path keeps clear of where ``j`` waits and ``j``'s path of where ``i``
ended (:func:`allowed`); :func:`order_waves` gives every pair an allowed
relation or names a pair that has none.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from skyquill.validation import FloatArray

IntArray = NDArray[np.intp]
BoolArray = NDArray[np.bool_]


def closest_on_segments(d0: FloatArray, d1: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Smallest ``|d0 + s (d1 - d0)|`` over ``s`` in [0, 1] and where, for (..., 3) arrays."""
    e = d1 - d0
    ee = np.einsum("...k,...k->...", e, e)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(ee > 0.0, -np.einsum("...k,...k->...", d0, e) / ee, 0.0)
    s = np.clip(s, 0.0, 1.0)
    return np.linalg.norm(d0 + s[..., None] * e, axis=-1), s


@dataclass(frozen=True)
class Allowed:
    """Which order each pair may fly in, each (N, N) boolean.

    Attributes
    ----------
    first
        ``[i, j]``: ``i``'s wave may come before ``j``'s.
    together
        ``[i, j]``: the same wave (their synchronised straight paths keep
        apart; for a drone that stays, its point and the other's path).
    held
        ``[i, j]``: ``i`` moves and its path comes too close to ``j``, which
        does not move (no order helps).
    """

    first: BoolArray
    together: BoolArray
    held: BoolArray


def allowed(a: FloatArray, b: FloatArray, moving: BoolArray, d: float) -> Allowed:
    """The relations of straight moves ``a`` -> ``b`` (N, 3) that keep distance ``d``, m."""
    # [i, j]: the smallest distance from i's path to where j starts / ends
    near_start = closest_on_segments(a[:, None] - a[None], b[:, None] - a[None])[0] < d
    near_goal = closest_on_segments(a[:, None] - b[None], b[:, None] - b[None])[0] < d
    sync = closest_on_segments(a[:, None] - a[None], b[:, None] - b[None])[0]
    other = ~np.eye(len(a), dtype=bool)
    held = moving[:, None] & ~moving[None, :] & (near_start | near_goal) & other
    return Allowed(~near_start & ~near_goal.T, (sync >= d) | ~other, held)


def _longest_paths(before: IntArray, after: IntArray, n: int) -> IntArray | None:
    """Waves from the orders ``before[k]`` ahead of ``after[k]``; ``None`` for a cycle."""
    wave = np.zeros(n, dtype=np.intp)
    for _ in range(n + 1):
        old = wave.copy()
        np.maximum.at(wave, after, wave[before] + 1)
        if np.array_equal(wave, old):
            return wave
    return None


def order_waves(ok: Allowed, moving: BoolArray) -> tuple[IntArray | None, tuple[int, int]]:
    """Each drone's wave (-1: stays), or ``None`` and a pair no order satisfies.

    All movers start in one wave; each pair whose relation is not allowed is
    given an allowed order (the lower index first when both are), and the
    waves are the longest paths of the orders, until every pair is satisfied.
    """
    n = moving.size
    i, j = np.nonzero(np.triu(moving[:, None] & moving[None, :], 1))
    before = np.zeros(0, dtype=np.intp)
    after = np.zeros(0, dtype=np.intp)
    wave: IntArray | None = np.zeros(n, dtype=np.intp)
    for _ in range(n + 1):
        assert wave is not None
        wi, wj = wave[i], wave[j]
        fine = np.where(
            wi == wj, ok.together[i, j], np.where(wi < wj, ok.first[i, j], ok.first[j, i])
        )
        if fine.all():
            return np.where(moving, wave, -1), (-1, -1)
        bi, bj = i[~fine], j[~fine]
        forward = ok.first[bi, bj]
        backward = ok.first[bj, bi]
        if not (forward | backward).all():
            k = int(np.flatnonzero(~(forward | backward))[0])
            return None, (int(bi[k]), int(bj[k]))
        before = np.concatenate([before, np.where(forward, bi, bj)])
        after = np.concatenate([after, np.where(forward, bj, bi)])
        wave = _longest_paths(before, after, n)
        if wave is None:
            return None, (int(bi[0]), int(bj[0]))
    return None, (int(i[0]), int(j[0]))  # pragma: no cover - orders are added at most once


def colours(conflict: BoolArray) -> IntArray:
    """A greedy colouring of the symmetric ``conflict`` graph (N, N): most conflicts first."""
    n = conflict.shape[0]
    colour = np.full(n, -1, dtype=np.intp)
    for k in np.argsort(-conflict.sum(axis=1), kind="stable"):
        taken = set(colour[conflict[k] & (colour >= 0)].tolist())
        colour[k] = next(c for c in range(n + 1) if c not in taken)
    return colour
