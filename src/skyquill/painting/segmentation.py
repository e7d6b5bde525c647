"""Piecewise-linear fits of points ordered along a wall: where the pieces break, and how many.

Contacts on a piecewise-planar wall, seen from above and sorted along it, lie on ``K`` lines in
``K`` contiguous runs. For each ``K`` the least-squares best runs are found *exactly* by dynamic
programming over the sorted points (Bellman's segmented least squares, 1961): ``O(K M^2)`` for
``M`` candidate boundaries, each run's residual from prefix sums in ``O(1)``. ``K`` is then
chosen by the Bayesian information criterion ``n ln(RSS / n) + p ln n`` with ``p = 3K - 1``
(two per line, one per break).

Why dynamic programming rather than RANSAC over segment hypotheses: the runs are contiguous
along the wall, which the DP uses and for which it returns the optimum; RANSAC draws lines
without contiguity, gives no optimality and needs contiguity repaired afterwards; and the DP is
cheap enough (about a millisecond for 128 boundaries and 8 pieces) to re-run after every
contact. RANSAC's one strength, indifference to outliers, is supplied by :func:`screen`, a
local test that runs before the DP, and by the robust loss of the final fit
(:mod:`skyquill.painting.joint`).

Two guards make the criterion behave on real contacts:

* a noise floor: ``RSS / n`` never counts below ``noise_floor_m ** 2`` (2 mm by default, the
  bumper's squeeze and a wall's roughness), or a flat wall touched with sub-millimetre
  contacts would be cut into pieces that only fit that noise;
* each piece of a split wall has at least ``min_points`` contacts spread over ``min_width_m``,
  so that no piece is a line through two points that fits anything.

Pieces are independent lines (paper 002's eq. 13 is a set of lines, not a continuous
polyline): a corner and a step (a recess) are both two pieces. Where two neighbouring lines
cross between their last and first contacts the break is that corner; otherwise (a step) it is
half-way between the contacts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TypedDict, Unpack

import numpy as np

from skyquill.errors import InputError
from skyquill.validation import FloatArray

#: Steepest piece, |dy/dx| (75 deg): a wall at up to 60 deg seen by a drone turned by up to
#: 15 deg more than it believes.
MAX_SLOPE = math.tan(math.radians(75.0))
#: Points closer together along ``x`` than this are at the same ``x``, m.
MIN_SPREAD_M = 1e-6
#: Most candidate boundaries the DP considers; above it points are grouped in runs of equal
#: count (a mural of thousands of dots is still cut anywhere within ~1 % of its contacts).
MAX_ATOMS = 128


@dataclass(frozen=True)
class Pieces:
    """A piecewise-linear fit ``y = a_k x + b_k`` of points, ``K`` pieces left to right.

    Attributes
    ----------
    slopes, intercepts
        The line of each piece, shape (K,) (m / m and m).
    breaks
        ``x`` where each piece ends and the next begins, shape (K - 1,), m.
    labels
        Piece of each input point, shape (n,), ints in ``[0, K)``.
    x_lo, x_hi
        Extent of each piece's own points, shape (K,), m.
    rss
        Residual sum of squares of the chosen fit, m^2.
    bic
        The criterion for ``K = 1 .. max_pieces`` (``inf`` where no split exists), shape (Kmax,).
    """

    slopes: FloatArray
    intercepts: FloatArray
    breaks: FloatArray
    labels: np.ndarray
    x_lo: FloatArray
    x_hi: FloatArray
    rss: float
    bic: FloatArray

    @property
    def n_pieces(self) -> int:
        """``K``."""
        return int(self.slopes.size)

    def piece_of(self, x: FloatArray) -> np.ndarray:
        """Piece under each ``x`` (the end pieces extend to infinity), shape like ``x``."""
        return np.searchsorted(self.breaks, np.asarray(x, dtype=float), side="right")

    def predict(self, x: FloatArray) -> FloatArray:
        """``y`` of the fit at each ``x``, m."""
        k = self.piece_of(x)
        out: FloatArray = self.slopes[k] * np.asarray(x, dtype=float) + self.intercepts[k]
        return out


class SplitOptions(TypedDict, total=False):
    """How :class:`Splits` cuts the points (each as :class:`Splits` documents it)."""

    max_pieces: int
    min_points: int
    min_width_m: float
    noise_floor_m: float
    max_slope: float


def fit_pieces(x: FloatArray, y: FloatArray, **options: Unpack[SplitOptions]) -> Pieces:
    """The BIC-best piecewise-linear fit of the points ``(x, y)`` (n,) along ``x``.

    ``options`` as :class:`Splits` takes them.
    """
    splits = Splits(x, y, **options)
    return splits.pieces(splits.best)


class Splits:
    """The least-squares best cut of the points into ``K = 1 .. max_pieces`` pieces.

    Built once by the dynamic programme; :meth:`pieces` reads any ``K`` off it.

    Parameters
    ----------
    x, y
        Points, shape (n,) each, n >= 2, with ``x`` not all equal, m.
    max_pieces
        Largest ``K`` tried.
    min_points, min_width_m
        Each piece of a split fit has at least this many points spread over this width.
    noise_floor_m
        ``RSS / n`` counts as at least its square in the criterion.
    max_slope
        Steepest piece of a split fit (``|a|``): a steeper run is a few points that happen
        to line up across a corner or a step, not a wall the drone could face.

    Attributes
    ----------
    bic
        The criterion of each ``K`` (``inf`` where no cut exists), shape (max_pieces,).
    best
        The ``K`` with the smallest criterion.
    """

    def __init__(
        self,
        x: FloatArray,
        y: FloatArray,
        *,
        max_pieces: int = 8,
        min_points: int = 3,
        min_width_m: float = 0.1,
        noise_floor_m: float = 0.002,
        max_slope: float = MAX_SLOPE,
    ) -> None:
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        n = x.size
        if n < 2 or y.shape != x.shape or float(np.ptp(x)) <= MIN_SPREAD_M:
            raise InputError(f"x, y: got {n} point(s), expected at least 2 at distinct x")
        self._order = np.argsort(x, kind="stable")
        self._xs, self._ys = x[self._order], y[self._order]
        self._bounds = _atoms(n)
        max_pieces = max(1, min(max_pieces, n // max(min_points, 1)))
        sse = _run_costs(
            self._xs,
            self._ys,
            self._bounds,
            min_points=min_points,
            min_width=min_width_m,
            max_slope=max_slope,
        )
        costs, self._back = _dp(sse, max_pieces)
        line_rss = _one_line_rss(self._xs, self._ys)
        rss = np.concatenate([[line_rss], costs[2:, -1]])
        params = 3.0 * np.arange(1, rss.size + 1) - 1.0
        floor = max(noise_floor_m, 1e-9) ** 2
        bic = n * np.log(np.maximum(rss / n, floor)) + params * math.log(n)
        bic[~np.isfinite(rss)] = np.inf
        self._rss, self.bic = rss, bic
        self.best = int(np.argmin(bic)) + 1

    @property
    def most(self) -> int:
        """The largest ``K`` for which a cut exists."""
        return int(np.flatnonzero(np.isfinite(self._rss))[-1]) + 1

    def pieces(self, k: int) -> Pieces:
        """The best cut into ``k`` pieces (1 <= k <= :attr:`most`)."""
        starts = [0] if k == 1 else _backtrack(self._back, self._bounds, k)
        return _pieces(
            self._xs, self._ys, self._order, starts, rss=float(self._rss[k - 1]), bic=self.bic
        )


def _atoms(n: int) -> np.ndarray:
    """Candidate run boundaries (indices into the sorted points), shape (M + 1,)."""
    if n <= MAX_ATOMS:
        return np.arange(n + 1)
    return np.unique(np.round(np.linspace(0, n, MAX_ATOMS + 1)).astype(int))


def _prefix(xs: FloatArray, ys: FloatArray) -> tuple[FloatArray, ...]:
    """Prefix sums of 1, x, y, x^2, x y, y^2 of the centred points, each (n + 1,)."""
    xc, yc = xs - xs.mean(), ys - ys.mean()
    cols = (np.ones_like(xc), xc, yc, xc * xc, xc * yc, yc * yc)
    return tuple(np.concatenate([[0.0], np.cumsum(c)]) for c in cols)


def _run_costs(
    xs: FloatArray,
    ys: FloatArray,
    bounds: np.ndarray,
    *,
    min_points: int,
    min_width: float,
    max_slope: float,
) -> FloatArray:
    """Least-squares residual of one line through atoms ``i .. j - 1``, shape (M + 1, M + 1).

    ``inf`` where ``j <= i`` or the run has fewer than ``min_points`` points, is narrower
    than ``min_width`` or steeper than ``max_slope``.
    """
    s0, sx, sy, sxx, sxy, syy = (p[bounds] for p in _prefix(xs, ys))

    def diff(p: FloatArray) -> FloatArray:
        out: FloatArray = p[None, :] - p[:, None]
        return out

    n, mx, my = diff(s0), diff(sx), diff(sy)
    with np.errstate(divide="ignore", invalid="ignore"):
        cxx = diff(sxx) - mx * mx / n
        cxy = diff(sxy) - mx * my / n
        cyy = diff(syy) - my * my / n
        sse = np.maximum(cyy - cxy * cxy / cxx, 0.0)
    first = xs[np.minimum(bounds, xs.size - 1)]
    last = xs[np.maximum(bounds - 1, 0)]
    width = last[None, :] - first[:, None]
    ok = (n >= min_points) & (width >= min_width) & (cxx > 1e-12)
    with np.errstate(divide="ignore", invalid="ignore"):
        ok &= np.abs(cxy / cxx) <= max_slope
    out: FloatArray = np.where(ok, sse, np.inf)
    return out


def _dp(sse: FloatArray, max_pieces: int) -> tuple[FloatArray, np.ndarray]:
    """Best cost of ``k`` runs over atoms ``0 .. j - 1``, ``costs[k, j]``, and back-pointers."""
    m = sse.shape[0]
    costs = np.full((max_pieces + 1, m), np.inf)
    back = np.zeros((max_pieces + 1, m), dtype=int)
    costs[0, 0] = 0.0
    for k in range(1, max_pieces + 1):
        cand = costs[k - 1][:, None] + sse
        back[k] = np.argmin(cand, axis=0)
        costs[k] = cand[back[k], np.arange(m)]
    return costs, back


def _backtrack(back: np.ndarray, bounds: np.ndarray, k: int) -> list[int]:
    """First sorted-point index of each of the ``k`` runs."""
    j = bounds.size - 1
    cuts = []
    for level in range(k, 0, -1):
        j = int(back[level, j])
        cuts.append(int(bounds[j]))
    return cuts[::-1]


def _one_line_rss(xs: FloatArray, ys: FloatArray) -> float:
    """Residual of the least-squares line through all points (any count >= 2)."""
    xc, yc = xs - xs.mean(), ys - ys.mean()
    cxx = float(xc @ xc)
    if cxx <= 1e-12:
        return float(yc @ yc)
    return max(float(yc @ yc) - float(xc @ yc) ** 2 / cxx, 0.0)


def _line(xs: FloatArray, ys: FloatArray) -> tuple[float, float]:
    """Least-squares ``(slope, intercept)`` of ``y`` on ``x``."""
    mx, my = float(xs.mean()), float(ys.mean())
    xc = xs - mx
    cxx = float(xc @ xc)
    a = float(xc @ (ys - my)) / cxx if cxx > 1e-12 else 0.0
    return a, my - a * mx


def _pieces(
    xs: FloatArray,
    ys: FloatArray,
    order: np.ndarray,
    starts: list[int],
    *,
    rss: float,
    bic: FloatArray,
) -> Pieces:
    """Lines, extents and breaks of the runs beginning at ``starts`` (sorted indices)."""
    ends = [*starts[1:], xs.size]
    lines = np.array([_line(xs[a:b], ys[a:b]) for a, b in zip(starts, ends, strict=True)])
    slopes, intercepts = lines[:, 0], lines[:, 1]
    x_lo = np.array([xs[a] for a in starts])
    x_hi = np.array([xs[b - 1] for b in ends])
    breaks = np.array(
        [
            corner_or_step(x_hi[k], x_lo[k + 1], lines[k], lines[k + 1])
            for k in range(len(starts) - 1)
        ]
    )
    labels_sorted = np.repeat(np.arange(len(starts)), np.diff([*starts, xs.size]))
    labels = np.empty_like(labels_sorted)
    labels[order] = labels_sorted
    return Pieces(slopes, intercepts, breaks, labels, x_lo, x_hi, rss, bic)


def corner_or_step(x_left: float, x_right: float, left: FloatArray, right: FloatArray) -> float:
    """Where two neighbouring pieces meet: their lines' crossing if it lies between the left
    piece's last point ``x_left`` and the right one's first ``x_right`` (a corner), else
    half-way between them (a step). ``left``, ``right``: ``(slope, intercept)``."""
    da = float(left[0] - right[0])
    if abs(da) > 1e-9:
        x = float(right[1] - left[1]) / da
        if x_left <= x <= x_right:
            return x
    return 0.5 * (x_left + x_right)


def screen(
    x: FloatArray,
    y: FloatArray,
    *,
    neighbours: int = 4,
    reach_m: float = 1.0,
    min_baseline_m: float = 0.1,
    max_slope: float = MAX_SLOPE,
    floor_m: float = 0.03,
    scales: float = 3.5,
) -> np.ndarray:
    """Mask of the points not short of every line through two of their neighbours (True: keep).

    ``y`` grows away from the drone (into the wall). A false contact -- the IMU firing before
    the wall -- is measured short of the wall, never beyond it. A point on a piecewise-planar
    wall lies on the line through two other points of its own piece (on a piece of three
    contacts, its two neighbours); a false contact lies short of every line through two wall
    points nearby, by more than a corner's sag. So each point is tested against the lines
    through every pair among its ``neighbours`` nearest points on each side (within
    ``reach_m``, pairs at least ``min_baseline_m`` apart and no steeper than ``max_slope``),
    and dropped when it is short of all of them by more than ``max(scales * s, floor_m)``,
    ``s`` the robust scale (1.4826 x median) of the points' smallest misses. A point beyond
    a line is never dropped (it says the wall is farther), nor one with no usable pair. A line
    with a neighbour beyond it by as much, between its two points, is not a wall line (it goes
    through a false contact: the wall is behind it there) and explains nothing.

    Why this test and not the residuals of one fit: the piecewise fit that follows would
    otherwise spend a piece on a false contact and two neighbours (a line through three
    points nearly fits anything), and the false contact would then look like wall.
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    n = x.size
    keep = np.ones(n, dtype=bool)
    if n < 3:
        return keep
    order = np.argsort(x, kind="stable")
    xs, ys = x[order], y[order]
    steps = np.concatenate([-np.arange(1, neighbours + 1), np.arange(1, neighbours + 1)])
    idx = np.arange(n)[:, None] + steps[None, :]
    inside = (idx >= 0) & (idx < n)
    idx = np.clip(idx, 0, n - 1)
    nx, ny = xs[idx], ys[idx]
    inside &= np.abs(nx - xs[:, None]) <= reach_m
    pairs = np.triu_indices(steps.size, k=1)
    dropped = np.zeros(n, dtype=bool)
    for _ in range(3):  # a dropped point explains nothing: test again without it
        now = _short(
            (xs, ys),
            (nx, ny, inside & ~dropped[idx]),
            pairs,
            min_baseline_m=min_baseline_m,
            max_slope=max_slope,
            floor_m=floor_m,
            scales=scales,
        )
        if np.array_equal(now, dropped):
            break
        dropped = now
    keep[order[dropped]] = False
    return keep


def _short(
    points: tuple[FloatArray, FloatArray],
    near: tuple[FloatArray, FloatArray, np.ndarray],
    pairs: tuple[np.ndarray, np.ndarray],
    *,
    min_baseline_m: float,
    max_slope: float,
    floor_m: float,
    scales: float,
) -> np.ndarray:
    """One pass of :func:`screen` over the sorted ``points`` (xs, ys) and their neighbours
    ``near`` (x, y, usable), shape (n, m) each: which points are short of every line."""
    xs, ys = points
    nx, ny, inside = near
    p, q = pairs
    dx = nx[:, q] - nx[:, p]
    usable = inside[:, p] & inside[:, q] & (np.abs(dx) >= min_baseline_m)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        slope = (ny[:, q] - ny[:, p]) / dx
        usable &= np.abs(slope) <= max_slope
        slope = np.where(usable, slope, 0.0)
        signed = ys[:, None] - (ny[:, p] + slope * (xs[:, None] - nx[:, p]))
    seen = usable.any(axis=1)
    if not seen.any():
        return np.zeros(xs.size, dtype=bool)
    smallest = np.where(usable, np.abs(signed), np.inf).min(axis=1)
    s = 1.4826 * float(np.median(smallest[seen]))
    tau = max(scales * s, floor_m)
    usable &= ~_beyond(nx, ny, inside, (p, q), slope=slope, tau=tau)
    deepest = np.where(usable, signed, -np.inf).max(axis=1)  # the least short of any line
    out: np.ndarray = seen & (deepest < -tau)
    return out


def _beyond(
    nx: FloatArray,
    ny: FloatArray,
    inside: np.ndarray,
    pairs: tuple[np.ndarray, np.ndarray],
    *,
    slope: FloatArray,
    tau: float,
) -> np.ndarray:
    """Per point and pair: a neighbour strictly between the pair's two points lies beyond the
    pair's line by more than ``tau``, shape (n, pairs)."""
    p, q = pairs
    lo = np.minimum(nx[:, p], nx[:, q])[:, :, None]
    hi = np.maximum(nx[:, p], nx[:, q])[:, :, None]
    rx, ry = nx[:, None, :], ny[:, None, :]
    between = inside[:, None, :] & (rx > lo) & (rx < hi)
    line = ny[:, p][:, :, None] + slope[:, :, None] * (rx - nx[:, p][:, :, None])
    with np.errstate(invalid="ignore"):
        out = np.asarray((between & (ry - line > tau)).any(axis=2), dtype=bool)
    return out
