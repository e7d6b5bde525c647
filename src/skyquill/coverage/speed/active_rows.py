"""The banded interior point on the rows that can bind, checked against all of them.

With a norm limit held by a polygon (``norm_sides=16``: eight directions, so
24 rows per node) only the one or two directions nearest the acceleration's
and the jerk's own bind at a node; the others are implied. The interior point
costs ``O(R n)`` per Newton step, so it is solved on the ``keep`` rows of each
block (left-end acceleration, right-end acceleration, jerk) that come nearest
their bound at a guess (the previous solution), and the result is checked
against every row. A row it breaks is added and the problem solved again; an
optimum of the smaller problem that holds every row is the optimum of the
whole one (the rows left out were not binding). What is returned is exactly
feasible for every row (:func:`~.banded._feasible` on all of them).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from skyquill.coverage.speed.banded import BandedRows, BandedSolution, feasible, solve_banded_lp
from skyquill.validation import FloatArray

#: A mask of rows, shape (R, n).
Mask = npt.NDArray[np.bool_]

#: Rows kept per node in each block of the polygon's directions (the nearest to binding).
KEEP = 3
#: Solves with added rows before the whole problem is solved instead.
MAX_ROUNDS = 4


def row_ratios(rows: BandedRows, bound: FloatArray, b: FloatArray) -> FloatArray:
    """``|row(b)| / bound`` of every row, shape (R, n) (0 for free rows)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(np.isfinite(bound), np.abs(rows.values(b)) / bound, 0.0)


def nearest_rows(ratio: FloatArray, blocks: int, keep: int) -> Mask:
    """Mask (R, n) of the ``keep`` rows of each of ``blocks`` equal blocks nearest their bound."""
    mask = np.zeros(ratio.shape, dtype=bool)
    size = ratio.shape[0] // blocks
    for k in range(blocks):
        part = slice(k * size, (k + 1) * size)
        if size <= keep:
            mask[part] = True
            continue
        top = np.argpartition(-ratio[part], keep - 1, axis=0)[:keep]
        np.put_along_axis(mask[part], top, True, axis=0)
    return mask


def _gather(rows: BandedRows, bound: FloatArray, mask: Mask) -> tuple[BandedRows, FloatArray]:
    """The masked rows of every node stacked (the same count per node, free rows as padding)."""
    count = mask.sum(axis=0)
    # Stable sort of "not kept": each node's kept rows first, in their order.
    idx = np.argsort(~mask, axis=0, kind="stable")[: int(count.max())]
    pad = np.arange(idx.shape[0])[:, None] >= count[None, :]

    def take(a: FloatArray) -> FloatArray:
        return np.take_along_axis(a, idx, axis=0)

    sub_bound = np.where(pad, np.inf, take(bound))
    return BandedRows(take(rows.lower), take(rows.centre), take(rows.upper)), sub_bound


def solve_active_rows(
    rows: BandedRows,
    bound: FloatArray,
    ub: FloatArray,
    *,
    guess: FloatArray,
    blocks: int,
    tolerance: float,
) -> tuple[BandedSolution, int]:
    """``max sum(b)`` s.t. ``|rows(b)| <= bound``, ``0 <= b <= ub``, on the rows that bind.

    Parameters
    ----------
    rows : BandedRows
        ``R`` rows per node, in ``blocks`` blocks of ``R / blocks`` directions.
    bound : ndarray, shape (R, n)
        Row bounds (``inf``: free).
    ub : ndarray, shape (n,)
        Column upper bounds.
    guess : ndarray, shape (n,)
        A ``b`` near the answer (the rows nearest their bound there are kept first).
    blocks : int
        Blocks of rows per node.
    tolerance : float
        The interior point's relative tolerance; a row broken by no more than it is
        not added (the result is scaled into it instead, costing at most that much
        of the objective).

    Returns
    -------
    tuple
        The solution (exactly feasible for every row) and the interior-point solves made.
    """
    weights = np.ones(ub.size)
    mask = nearest_rows(row_ratios(rows, bound, guess), blocks, KEEP)
    solves = 0
    while solves < MAX_ROUNDS and not mask.all():
        solves += 1
        sol = solve_banded_lp(*_gather(rows, bound, mask), ub, weights, tolerance=tolerance)
        if sol.status != "optimal":
            return sol, solves
        ratio = row_ratios(rows, bound, sol.b)
        broken = ratio > 1.0 + tolerance
        if not broken.any():
            b = feasible(rows, bound, sol.b)
            return BandedSolution(b, sol.status, sol.iterations, sol.gap), solves
        mask |= broken
    return solve_banded_lp(rows, bound, ub, weights, tolerance=tolerance), solves + 1
