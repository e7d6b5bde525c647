"""The time allocation of a writing flight: the fastest timing that writes faithfully.

The route's first timing (:func:`~skyquill.calligraphy.timing.route_times`) is
the fastest the vehicle's limits allow along the polyline. Fitting the swung
brush tip, a timing that fast can stray beyond the tolerance: the tip swings
with the acceleration, and the lifts onto the board land where the swing puts
them. The writing is then slowed by capping the limits it is timed with at a
*pace* (:meth:`~skyquill.calligraphy.timing.TimingBounds.at_pace`); the legs
from and to home keep the limits. :func:`plan_route` finds the fastest pace
whose plan meets the limits and is faithful:

1. the limits themselves (the *full pace*): most characters at the CLI's
   limits are faithful there, one evaluation;
2. otherwise rungs of one ladder of paces, ``pace = stretch_factor ** u`` for
   integer ``u`` below the full pace, are tried downwards (skipping those the
   deviation predicts to fail, :func:`_stretches_needed`) until one is
   faithful, then upwards until the next fails;
3. between that rung and the next, :data:`BISECTIONS` halvings of ``u`` (the
   dyadic points of the rung, never the full pace's own position) find the
   fastest faithful pace to ``stretch_factor ** 2**-BISECTIONS`` (0.35 % at
   1.25).

Why looser limits are never slower: every step of the timing is
non-increasing in every limit and in the pace, and below a vehicle's limits
the timing at a pace is the same for every vehicle (one :data:`PACE_SHAPE
<skyquill.calligraphy.timing.PACE_SHAPE>`). The ladder and its dyadic points
are the same for every vehicle too, so a search at looser limits that meets a
pace below both vehicles' limits solves the same problem there as the search at
tighter limits, gets the same verdict, and ends at the same pace or a faster
one. ``docs/calligraphy-timing.md`` has the argument, where it is only
approximate, and the measurements.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.options import WritingOptions
from skyquill.calligraphy.planning import RoutePlan, logger, plan_at
from skyquill.calligraphy.route import RouteSamples
from skyquill.calligraphy.timing import TimingBounds, route_times
from skyquill.errors import InfeasibleError
from skyquill.validation import FloatArray

#: Halvings of the last rung (:func:`plan_route`): the pace found is within
#: ``stretch_factor ** (1 / 64)`` of the fastest faithful one (0.35 % at 1.25;
#: the flight's duration moves by at most that much).
BISECTIONS = 6
#: How fast the pen-down deviation falls as the writing slows, ``deviation ~ pace^-p``,
#: taken on the fast side of what is measured (p ~ 3.1) so that a predicted jump
#: down the ladder never passes the first faithful rung (:func:`_stretches_needed`).
DEVIATION_EXPONENT = 3.5


@dataclass
class _Ladder:
    """The timings and plans of one route at positions ``u`` of the pace ladder.

    Position ``u`` is the pace ``stretch_factor ** u``; at or above :attr:`top`
    (the full pace) the writing is timed with the limits themselves.
    """

    samples: RouteSamples
    board: Board
    opts: WritingOptions
    top: float
    timings: dict[float, FloatArray] = field(default_factory=dict)
    tried: dict[float, RoutePlan | None] = field(default_factory=dict)
    #: Why a position has no plan (the solve's own error, naming the limits).
    errors: dict[float, InfeasibleError] = field(default_factory=dict)

    def times(self, u: float) -> FloatArray:
        """The route's times at position ``u`` (N,), s."""
        u = min(u, self.top)
        if u not in self.timings:
            pace = None if u >= self.top else self.opts.stretch_factor**u
            s = self.samples
            self.timings[u] = route_times(
                s.points, s.roles, self.board, self.opts, pace, legs=s.legs, lead_in=s.lead_in
            )
        return self.timings[u]

    def scale(self, u: float) -> float:
        """How much slower the timing at ``u`` is than at the full pace."""
        return float(self.times(u)[-1] / self.times(self.top)[-1])

    def plan(self, u: float) -> RoutePlan | None:
        """The plan at position ``u`` (solved once), ``None`` where the limits cannot be met."""
        u = min(u, self.top)
        if u not in self.tried:
            scale = self.scale(u)
            logger.debug("solving at %.3gx the first timing", scale)
            try:
                self.tried[u] = plan_at(self.samples, self.times(u), self.board, self.opts, scale)
            except InfeasibleError as exc:
                self.tried[u], self.errors[u] = None, exc
        return self.tried[u]

    def faithful(self, u: float) -> bool:
        """Whether the plan at ``u`` meets the limits and writes within the tolerance."""
        plan = self.plan(u)
        return plan is not None and plan.faithful(self.opts)

    def slower(self, u: float) -> float:
        """The next rung below ``u`` worth solving: at least the deviation at ``u`` predicts
        (:func:`_stretches_needed`; one rung without a plan) slower than ``u``, and at most
        as slow as the slowest timing the options allow (``stretch_factor ** max_stretches``)."""
        plan, opts = self.plan(u), self.opts
        rungs = 1
        if plan is not None and plan.deviation.max_m > opts.tolerance:
            rungs = _stretches_needed(plan.deviation.max_m, opts)
        wanted = min(self.scale(u) * opts.stretch_factor**rungs, self.slowest_scale)
        rung = math.ceil(u) - 1.0
        while self.scale(rung) < wanted * (1.0 - 1e-9):
            rung -= 1.0  # timings only: a rung the limits leave as fast is not solved
        return rung

    @property
    def slowest_scale(self) -> float:
        """The slowest timing tried, against the full pace."""
        return float(self.opts.stretch_factor**self.opts.max_stretches)


def plan_route(samples: RouteSamples, board: Board, opts: WritingOptions) -> RoutePlan:
    """The fastest faithful rest-to-rest spline along ``samples`` over ``board`` (module docstring).

    The writing is slowed down the ladder until a plan is faithful, at most
    until it takes ``opts.stretch_factor ** opts.max_stretches`` the time of
    the first timing; if none down to there is faithful, the slowest plan is
    returned (the caller decides). No re-segmentation
    (:func:`~skyquill.calligraphy.planning.resegmented`).

    Raises
    ------
    InfeasibleError
        The limits cannot be met even at the slowest pace tried.
    """
    full = TimingBounds.of(opts.limits)
    top = math.log(full.full_pace) / math.log(opts.stretch_factor)
    ladder = _Ladder(samples, board, opts, top)
    if ladder.faithful(top) or opts.max_stretches == 0:
        return _kept(ladder, top)
    rung = ladder.slower(top)
    while not ladder.faithful(rung):
        if ladder.scale(rung) >= ladder.slowest_scale * (1.0 - 1e-9):
            return _kept(ladder, rung)
        rung = ladder.slower(rung)
    # The jump down may have passed faithful rungs: the bracket is a faithful
    # rung and the unfaithful one above it, the same whatever the limits.
    while rung + 1 < top and ladder.faithful(rung + 1):
        rung += 1
    return _kept(ladder, _bisect(ladder, rung, rung + 1))


def _bisect(ladder: _Ladder, low: float, high: float) -> float:
    """The highest faithful dyadic point of ``[low, high]`` found by :data:`BISECTIONS` halvings.

    ``low`` is faithful, ``high`` is not (or at or above the full pace, which is not).
    """
    for _ in range(BISECTIONS):
        middle = 0.5 * (low + high)
        if middle < ladder.top and ladder.faithful(middle):
            low = middle
        else:
            high = middle
    return low


def _kept(ladder: _Ladder, u: float) -> RoutePlan:
    """The plan at ``u``; the solve's own error where the limits cannot be met there."""
    plan = ladder.plan(u)
    if plan is None:
        raise ladder.errors[min(u, ladder.top)]
    return plan


def _stretches_needed(deviation_m: float, opts: WritingOptions) -> int:
    """Rungs predicted to bring ``deviation_m`` within the tolerance (at least 1).

    The pen-down deviation falls about as ``pace^-p`` with ``p ~ 3.1`` (it
    halves per x1.25 on the bundled characters: 永 12.3 -> 6.1 -> 4.2 mm). The
    prediction uses :data:`DEVIATION_EXPONENT` = 3.5, a faster fall than seen,
    so it predicts too few rungs rather than too many: the search lands on
    the same rung as one step at a time, with the attempts between skipped.
    """
    per_stretch = DEVIATION_EXPONENT * math.log(opts.stretch_factor)
    return max(1, math.ceil(math.log(deviation_m / opts.tolerance) / per_stretch))
