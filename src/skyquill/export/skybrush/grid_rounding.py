"""Bézier points onto Skybrush's coordinate grid without crossing the plan's limits.

Skybrush stores every Bézier point in whole units of ``scale`` mm. Rounding each point to the
nearest unit is usually harmless, but where the curve sits on a limit (a time-optimal move
accelerating at ``amax``) a half-unit step of one point can push a short segment's
acceleration a few per cent over it: a 200 ms jerk phase whose second difference is 13.33
units plays at 2.0 m/s^2 with 13 and at 2.1 m/s^2 with 14.

So every segment is first rounded to the nearest units; each one whose hull (the Bézier
points of its velocity, acceleration and jerk, which contain the whole curve's) then crosses a
limit by more than :data:`TARGETS` is searched again. Its start is
the previous segment's end; per axis the options are its forward differences (the start
velocity ``D1``, acceleration ``D2`` and jerk ``D3`` on the grid) rounded down, up and one
more either way, which moves its end point by a few units where the curve must be held back
(a 200 ms segment at ``amax = 1`` needs a second difference of 6.67 units: 6, and the end
two units behind, which the next segment takes up). Every combination of the three axes is
tried at once (the norms couple them). Of those inside the limits the one nearest the curve
wins, with the velocity and acceleration steps at its joins counted like distances (so the
joins stay as close to C2 as the grid allows). A segment for which no combination is inside
is left at its least excess and reported (``unresolved``): the exporter then refits
(:mod:`.refit`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from skyquill.export.base import ALLOWED_EXCESS
from skyquill.export.skybrush.keyframe_fit import hull_excess, hull_points
from skyquill.limits import BoxLimit, CylinderLimit, DerivativeLimit, NormLimit
from skyquill.validation import FloatArray

#: What the rounding aims for on the hull, relative excess per order (speed, acceleration,
#: jerk): 80 % of :data:`~skyquill.export.base.ALLOWED_EXCESS` (the rest is for the player's
#: float32 arithmetic). Aiming inside the limits instead (tried: the 10-drone show) holds the
#: curve back where the plan cruises at its speed limit, 5 mm behind the plan instead of 1.5,
#: and cannot always be had.
TARGETS = (tuple(0.8 * ALLOWED_EXCESS[n] for n in (1, 2, 3)),)
#: Offsets tried for a segment's first difference (round(d1) + ...) and its second and third
#: (floor(d) + ...), units: rounding down, up, and one more either way.
#: Tried in this order: second and third differences down or up (12 options per axis), then
#: one more either way (48).
SEARCH_STEPS = (((-1.0, 0.0, 1.0), (0.0, 1.0)), ((-1.0, 0.0, 1.0), (-1.0, 0.0, 1.0, 2.0)))


@dataclass(frozen=True)
class Rounding:
    """The rounded points and what the rounding had to do.

    Attributes
    ----------
    units
        Bézier points in grid units, shape (S, 4, 3); a segment's end is the next one's start.
    adjusted
        Segments searched and put back inside the limits.
    unresolved
        Indices of segments left over a limit (no combination was inside).
    hull_excess
        The largest relative excess of the rounded hull per order (index 1..3), <= 0 inside.
    """

    units: NDArray[np.int64]
    adjusted: int
    unresolved: tuple[int, ...]
    hull_excess: tuple[float, float, float]


def round_to_grid(
    points_m: FloatArray,
    durations_s: FloatArray,
    limits: Sequence[DerivativeLimit],
    unit_m: float,
) -> Rounding:
    """Integer Bézier points of ``points_m`` (S, 4, 3), m, that keep ``limits`` (module docstring).

    ``durations_s`` (S,) are the segments' lengths; ``unit_m`` Skybrush's unit.
    """
    grid = _Grid(points_m, durations_s, limits, unit_m)
    pending = sorted(np.flatnonzero(grid.over(slice(None))).tolist()) if grid.limits else []
    adjusted, unresolved = 0, set()
    while pending:
        k = pending.pop(0)
        if grid.search(k):
            adjusted += 1
        else:
            unresolved.add(k)
        nxt = k + 1  # its start may have moved with this segment's end
        if nxt < grid.h.size and nxt not in pending and grid.over(slice(nxt, nxt + 1))[0]:
            pending.insert(0, nxt)
    return Rounding(grid.units.astype(np.int64), adjusted, tuple(sorted(unresolved)), grid.worst())


class _Grid:
    """The points in units (exact and rounded) and the limits they are checked against."""

    def __init__(
        self,
        points_m: FloatArray,
        durations_s: FloatArray,
        limits: Sequence[DerivativeLimit],
        unit_m: float,
    ) -> None:
        self.exact = np.asarray(points_m, dtype=float) / unit_m
        self.units = np.rint(self.exact)
        self.units[1:, 0] = self.units[:-1, 3]  # the same number twice: the same unit
        self.h = np.asarray(durations_s, dtype=float)
        self.limits = [lim for lim in limits if lim.order in ALLOWED_EXCESS]
        self.unit_m = unit_m
        self.targets = [np.array([np.inf, *target]) for target in TARGETS]

    def excess(self, units: FloatArray, h: FloatArray) -> FloatArray:
        """Relative hull excess per segment and order (..., 4) of ``units`` (..., 4, 3)."""
        return hull_excess(self.limits, hull_points(units * self.unit_m, h))

    def over(self, k: slice) -> NDArray[np.bool_]:
        """Whether each segment of ``k`` crosses a limit by more than the search aims for."""
        excess = self.excess(self.units[k], self.h[k])
        return np.asarray((excess > self.targets[0]).any(axis=-1))

    def worst(self) -> tuple[float, float, float]:
        """The largest hull excess per order (1..3) over all segments."""
        if not self.limits:
            return (-np.inf, -np.inf, -np.inf)
        final = self.excess(self.units, self.h).max(axis=0)
        return (float(final[1]), float(final[2]), float(final[3]))

    def search(self, k: int) -> bool:
        """Re-round segment ``k`` in place; whether a combination inside the limits was found.

        Each axis' options are its forward differences ``D1, D2, D3`` (the start velocity,
        acceleration and jerk on the grid) near the exact ones; what they cost (distance,
        join steps) adds over the axes, and the limits are evaluated on every combination of
        the three axes by broadcasting, so 48^3 combinations cost a few milliseconds.
        """
        tried: dict[int, tuple[list[_AxisOptions], FloatArray]] = {}
        for target in self.targets:
            for i, steps in enumerate(SEARCH_STEPS):  # a few options first, then all of them
                if i not in tried:
                    options = [self._axis_options(k, ax, *steps) for ax in range(3)]
                    tried[i] = (options, self._combined_excess(options, self.h[k]))
                options, excess = tried[i]
                worst = (excess - target).max(axis=-1)
                if (worst <= 0).any():
                    self._take(k, options, worst)
                    return True
        self._take(k, options, worst)
        return False

    def _take(self, k: int, options: list[_AxisOptions], worst: FloatArray) -> None:
        """Set segment ``k`` to the cheapest combination inside (``worst <= 0``), else to the
        one with the least excess."""
        cost = sum(
            o.cost.reshape([-1 if a == ax else 1 for a in range(3)]) for ax, o in enumerate(options)
        )
        inside = (worst <= 0).ravel()
        if inside.any():
            flat = int(np.flatnonzero(inside)[np.argmin(np.asarray(cost).ravel()[inside])])
        else:
            flat = int(np.argmin(worst.ravel()))
        pick = np.unravel_index(flat, worst.shape)
        for ax, o in enumerate(options):
            self.units[k, :, ax] = o.points[pick[ax]]
        if k + 1 < self.h.size:
            self.units[k + 1, 0] = self.units[k, 3]

    def _axis_options(
        self, k: int, ax: int, d1_steps: tuple[float, ...], d23_steps: tuple[float, ...]
    ) -> _AxisOptions:
        """Segment ``k``'s candidate points on axis ``ax`` and what each costs on its own."""
        start = float(self.units[k, 0, ax])
        exact = self.exact[k, :, ax]
        d1, d2, d3 = _differences(exact.tolist())
        # Where the previous segments left the start off the curve (``drift`` units), the
        # first difference takes a third of it back (3 D1 is the velocity's share of the end).
        drift = start - exact[0]
        # with the drift taken back, or left (where taking it back is too fast: the first
        # difference rounded towards zero, whichever its sign); sorted and unique
        back = float(np.rint(d1 - drift / 3.0))
        first = np.array(
            sorted({*(back + step for step in d1_steps), math.floor(d1), math.ceil(d1)})
        )
        second = math.floor(d2) + np.array(d23_steps)
        third = math.floor(d3) + np.array(d23_steps)
        combos = np.empty((first.size, second.size, third.size, 3))  # every one, "ij" order
        combos[..., 0] = first[:, None, None]
        combos[..., 1] = second[None, :, None]
        combos[..., 2] = third[None, None, :]
        grid = combos.reshape(-1, 3)
        p1 = start + grid[:, 0]
        p2 = start + 2 * grid[:, 0] + grid[:, 1]
        p3 = start + 3 * grid[:, 0] + 3 * grid[:, 1] + grid[:, 2]
        if k == self.h.size - 1:  # the trajectory's last point stays where it ends
            p3 = np.full_like(p3, self.units[k, 3, ax])
            grid = np.unique(np.column_stack([p1, p2, p3]), axis=0)
            p1, p2, p3 = grid.T
        points = np.column_stack([np.full(p1.size, start), p1, p2, p3])
        cost = ((points - exact) ** 2).sum(axis=1) + self._join_steps(k, points, ax)
        return _AxisOptions(points, cost)

    def _combined_excess(self, options: list[_AxisOptions], h: float) -> FloatArray:
        """The relative excess per order (column 1..3) of every combination (nx, ny, nz, 4)."""
        parts = [
            hull_points(o.points[:, :, None] * self.unit_m, np.full(len(o.points), h))
            for o in options
        ]
        shape = [len(o.points) for o in options]
        worst = np.full([*shape, 4], -np.inf)
        for lim in self.limits:
            comps = [
                parts[ax][lim.order][..., 0].reshape(
                    [-1 if a == ax else 1 for a in range(3)] + [parts[ax][lim.order].shape[1]]
                )
                for ax in range(3)
            ]
            order = worst[..., lim.order]
            worst[..., lim.order] = np.maximum(order, _limit_excess(lim, comps))
        return worst

    def _join_steps(self, k: int, points: FloatArray, ax: int) -> FloatArray:
        """Squared velocity and acceleration steps at segment ``k``'s joins on axis ``ax``, as
        point distances.

        A step of velocity ``dv`` is ``dv h / 3`` units of a Bézier point, one of acceleration
        ``da`` is ``da h^2 / 6``: the distance a point would have to move to close it.
        """
        cost = np.zeros(len(points))
        hk = self.h[k]
        if k > 0:
            cost += _steps(self.units[k - 1, :, ax], self.h[k - 1], points, hk, hk)
        if k + 1 < self.h.size:
            cost += _steps(points, hk, self.units[k + 1, :, ax], self.h[k + 1], hk)
        return cost


@dataclass(frozen=True)
class _AxisOptions:
    """One axis' candidate points (n, 4), in units, and their own cost (n,)."""

    points: FloatArray
    cost: FloatArray


def _limit_excess(lim: DerivativeLimit, comps: list[FloatArray]) -> FloatArray:
    """Relative excess of ``lim`` over broadcast per-axis hull components (..., points)."""
    if isinstance(lim, NormLimit):
        norm = np.sqrt(sum(c**2 for c in comps[: lim.dim]))
        return np.asarray(norm.max(axis=-1) / lim.radius - 1.0)
    if isinstance(lim, CylinderLimit):
        out = np.sqrt(comps[0] ** 2 + comps[1] ** 2).max(axis=-1) / lim.radius - 1.0
        if lim.z_lower is not None and lim.z_upper is not None:
            up = (comps[2].max(axis=-1) - lim.z_upper) / abs(lim.z_upper)
            down = (lim.z_lower - comps[2].min(axis=-1)) / abs(lim.z_lower)
            out = np.maximum(out, np.maximum(up, down))
        return np.asarray(out)
    assert isinstance(lim, BoxLimit)
    out = np.full(np.broadcast_shapes(*(c.shape for c in comps))[:-1], -np.inf)
    for ax in range(lim.dim):
        up = (comps[ax].max(axis=-1) - lim.upper[ax]) / abs(lim.upper[ax])
        down = (lim.lower[ax] - comps[ax].min(axis=-1)) / abs(lim.lower[ax])
        out = np.maximum(out, np.maximum(up, down))
    return np.asarray(out, dtype=float)


def _differences(x: list[float]) -> tuple[float, float, float]:
    """The first forward differences of orders 1, 2, 3 of four numbers (as ``np.diff``)."""
    a0, a1, a2 = x[1] - x[0], x[2] - x[1], x[3] - x[2]
    b0, b1 = a1 - a0, a2 - a1
    return a0, b0, b1 - b0


def _steps(left: FloatArray, hl: float, right: FloatArray, hr: float, h: float) -> FloatArray:
    """Squared steps (as distances over ``h``) where ``left`` (.., 4) meets ``right`` (.., 4)."""
    dv = 3 * (right[..., 1] - right[..., 0]) / hr - 3 * (left[..., 3] - left[..., 2]) / hl
    da = (
        6 * (right[..., 2] - 2 * right[..., 1] + right[..., 0]) / hr**2
        - 6 * (left[..., 3] - 2 * left[..., 2] + left[..., 1]) / hl**2
    )
    return np.asarray((dv * h / 3) ** 2 + (da * h**2 / 6) ** 2)
