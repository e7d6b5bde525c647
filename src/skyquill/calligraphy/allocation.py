"""The time allocation of a writing flight: the fastest timing that writes faithfully.

The route's first timing (:func:`~skyquill.calligraphy.timing.route_times`) is
the fastest the vehicle's limits allow along the polyline. Fitting the swung
brush tip, a timing that fast can stray beyond the tolerance: the tip swings
with the acceleration, and the lifts onto the board land where the swing puts
them. The writing is then slowed by capping the limits it is timed with at a
*pace* ``p`` -- speed, acceleration and jerk ``(p, 2 p^2, 10 p^3)``, one motion
played ``p`` times faster (:data:`~skyquill.calligraphy.timing.PACE_SHAPE`) --
while the legs from and to home keep the speed limit.

Which pace is decided by *probes*: the route timed with the limits of the pace
alone and solved within them, or within the pace shape's at pace
:data:`PROBE_SOLVE_PACE` where those are looser -- whatever the vehicle's
(:class:`_Ladder`). A probe's
verdict -- faithful or not -- is the same for every vehicle, so the search
below finds the same pace for every vehicle whose limits it does not reach:

1. the probe at the vehicle's *full pace* (where the pace reaches all its
   limits; at the CLI's limits, which are of the pace's shape, that probe is
   the plan at the limits themselves: most characters need one solve);
2. otherwise rungs of one ladder of paces, ``p = stretch_factor ** u`` for
   whole ``u`` below the full pace, downwards (skipping those the deviation
   predicts to fail, :func:`_stretches_needed`) until a probe is faithful,
   then the highest faithful rung by bisection on the rungs between;
3. between that rung and the next, :data:`BISECTIONS` halvings of ``u`` (the
   dyadic points of the rung) find the fastest faithful probe to
   ``stretch_factor ** 2**-BISECTIONS`` (0.7 % at 1.25).

The flight is then planned at that pace within the vehicle's limits (the
vehicle's limits capped at the pace: no faster than the probe anywhere, and
slower where the vehicle is slower); where that plan strays (a vehicle whose
limits are not of the pace's shape), at the highest faithful position below it
(:func:`_flown`).

Why looser limits never give a slower flight: the probes and the points they
are tried at are the same for every vehicle, so at looser limits the search
finds the same pace or a faster one (it may find faster probes above the
tighter vehicle's full pace, which the tighter search never needs), and every
step of the flown timing is non-increasing in every limit and in the pace. The
argument holds where slower probes are no less faithful and the flown plan is
as faithful as its probe; ``docs/calligraphy-timing.md`` has it in full and the
measurements.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.options import WritingOptions
from skyquill.calligraphy.planning import RoutePlan, logger, plan_at
from skyquill.calligraphy.route import RouteSamples
from skyquill.calligraphy.timing import PACE_SHAPE, TimingBounds, route_times
from skyquill.errors import InfeasibleError
from skyquill.limits import LIMIT_CEILINGS, VehicleLimits
from skyquill.validation import FloatArray

#: Halvings of the last rung (:func:`plan_route`): the pace found is within
#: ``stretch_factor ** (1 / 32)`` of the fastest faithful one (0.7 % at 1.25;
#: the flight's duration moves by at most that much).
BISECTIONS = 5
#: How fast the pen-down deviation falls as the writing slows, ``deviation ~ pace^-p``,
#: taken on the fast side of what is measured (p ~ 3.1) so that a predicted jump
#: down the ladder never passes the first faithful rung (:func:`_stretches_needed`).
DEVIATION_EXPONENT = 3.5


@dataclass
class _Ladder:
    """The timings and plans of one route at positions ``u`` of the pace ladder.

    Position ``u`` is the pace ``stretch_factor ** u``. Two plans per position:

    * the *probe* (:meth:`probe`): the route timed with the limits of the pace
      alone, :data:`~skyquill.calligraphy.timing.PACE_SHAPE` played at it, and
      solved within them or the pace shape's at :data:`PROBE_SOLVE_PACE`,
      whichever are looser -- the same problem for every vehicle, whose verdict
      (faithful or not) decides the search;
    * the *plan* (:meth:`plan`): the route timed with the vehicle's limits capped
      at the pace and solved within the vehicle's limits -- what is flown. At or
      above :attr:`top` (the full pace) it is timed with the limits themselves.
    """

    samples: RouteSamples
    board: Board
    opts: WritingOptions
    top: float
    timings: dict[tuple[float, bool], FloatArray] = field(default_factory=dict)
    probes: dict[float, RoutePlan | None] = field(default_factory=dict)
    plans: dict[float, RoutePlan | None] = field(default_factory=dict)
    #: Why a position has no plan (the solve's own error, naming the limits).
    errors: dict[float, InfeasibleError] = field(default_factory=dict)

    def pace_options(self, u: float, solve: bool = False) -> WritingOptions:
        """The options with the limits of the pace at ``u`` alone (the vehicle's own at the
        full pace when they are of the pace's shape: the CLI's defaults are).

        With ``solve``, the limits the probe is *solved* within: those of the pace,
        but never below :data:`PROBE_SOLVE_PACE`'s. A probe timed slower than that
        is solved within fixed limits, so slowing it gives the spline room to
        follow the route: solved within its own pace's limits, a slower probe is
        the faster one played slower where the limits bind, and strays as far
        (the path-fitting writing of 中 stayed at 8.1 mm from 1.56x to 5.96x).
        """
        u = min(u, self.top)
        pace = self.opts.stretch_factor**u
        if solve:
            pace = max(pace, PROBE_SOLVE_PACE)
        bounds = PACE_SHAPE_BOUNDS.at_pace(pace)
        # Never above the ceilings a vehicle's limits are held to: at limits near them the
        # full pace's (a hair faster, TimingBounds.full_pace) would be refused as a unit mistake.
        jmax = None if bounds.jmax is None else min(bounds.jmax, LIMIT_CEILINGS[3])
        limits = VehicleLimits(
            min(bounds.vmax, LIMIT_CEILINGS[1]), min(bounds.amax, LIMIT_CEILINGS[2]), jmax
        )
        if u >= self.top and _same_limits(limits, self.opts.limits):
            return self.opts
        return replace(self.opts, limits=limits)

    def times(self, u: float, probe: bool = False) -> FloatArray:
        """The route's times at position ``u`` (N,), s: the plan's, or the probe's."""
        u = min(u, self.top)
        key = (u, probe)
        if key not in self.timings:
            s = self.samples
            if probe:
                opts, pace = self.pace_options(u), None
            else:
                opts, pace = self.opts, None if u >= self.top else self.opts.stretch_factor**u
            self.timings[key] = route_times(
                s.points, s.roles, self.board, opts, pace, legs=s.legs, lead_in=s.lead_in
            )
        return self.timings[key]

    def scale(self, u: float, probe: bool = False) -> float:
        """How much slower the timing at ``u`` (the plan's, or the probe's) is than the
        first timing (the plan's at the full pace)."""
        return float(self.times(u, probe)[-1] / self.times(self.top)[-1])

    def probe(self, u: float) -> RoutePlan | None:
        """The probe at ``u`` (solved once), ``None`` where its limits cannot be met."""
        u = min(u, self.top)
        if u not in self.probes:
            if self.pace_options(u) is self.opts:  # the plan itself
                self.probes[u] = self.plan(u)
            else:
                self.probes[u] = self._solved(u, self.pace_options(u, solve=True), probe=True)
        return self.probes[u]

    def plan(self, u: float) -> RoutePlan | None:
        """The plan at ``u`` (solved once), ``None`` where the limits cannot be met."""
        u = min(u, self.top)
        if u not in self.plans:
            self.plans[u] = self._solved(u, self.opts, probe=False)
        return self.plans[u]

    def _solved(self, u: float, opts: WritingOptions, probe: bool) -> RoutePlan | None:
        scale = self.scale(u, probe)
        logger.debug("solving at %.3gx the first timing", scale)
        try:
            return plan_at(self.samples, self.times(u, probe), self.board, opts, scale)
        except InfeasibleError as exc:
            if not probe:
                self.errors[u] = exc
            return None

    def probe_faithful(self, u: float) -> bool:
        """Whether the probe at ``u`` meets its limits and writes within the tolerance."""
        plan = self.probe(u)
        return plan is not None and plan.faithful(self.opts)

    def faithful(self, u: float) -> bool:
        """Whether the plan at ``u`` meets the limits and writes within the tolerance."""
        plan = self.plan(u)
        return plan is not None and plan.faithful(self.opts)

    def slower(self, u: float) -> float:
        """The next rung below ``u`` worth probing: at least the deviation at ``u`` predicts
        (:func:`_stretches_needed`; one rung without a probe) slower than ``u``, and at most
        as slow as the slowest timing the options allow (``stretch_factor ** max_stretches``)."""
        plan, opts = self.probe(u), self.opts
        rungs = 1
        if plan is not None and plan.deviation.max_m > opts.tolerance:
            rungs = _stretches_needed(plan.deviation.max_m, opts)
        wanted = min(self.scale(u, True) * opts.stretch_factor**rungs, self.slowest_scale)
        rung = math.ceil(u) - 1.0
        while self.scale(rung, True) < wanted * (1.0 - 1e-9):
            rung -= 1.0  # timings only: a rung as fast as the one above is not solved
        return rung

    def slowest(self, u: float) -> bool:
        """Whether the probe at ``u`` is as slow as the options allow."""
        return self.scale(u, True) >= self.slowest_scale * (1.0 - 1e-9)

    @property
    def slowest_scale(self) -> float:
        """The slowest timing tried, against the full pace."""
        return float(self.opts.stretch_factor**self.opts.max_stretches)


#: The slowest pace whose limits a probe is solved within (:meth:`_Ladder.pace_options`):
#: :data:`~skyquill.calligraphy.timing.PACE_SHAPE` itself, the CLI's default limits. The
#: same for every vehicle, so a probe's verdict still is.
PROBE_SOLVE_PACE = 1.0
#: The pace shape as timing bounds (:meth:`TimingBounds.at_pace` of it is the shape played
#: at a pace, uncapped below any practical pace).
PACE_SHAPE_BOUNDS = TimingBounds(*(1e9 * c for c in PACE_SHAPE))


def _same_limits(a: VehicleLimits, b: VehicleLimits) -> bool:
    """Whether two limit sets agree to rounding (a cube root cubed)."""
    pairs = [(getattr(a, n), getattr(b, n)) for n in ("vmax", "amax", "jmax")]
    if any((x is None) != (y is None) for x, y in pairs):
        return False
    axes = [getattr(b, n) for n in ("vmax_axis", "amax_axis", "jmax_axis")]
    close = all(x is None or y is None or abs(x - y) <= 1e-9 * abs(y) for x, y in pairs)
    return close and all(x is None for x in axes)


def plan_route(samples: RouteSamples, board: Board, opts: WritingOptions) -> RoutePlan:
    """The fastest faithful rest-to-rest spline along ``samples`` over ``board`` (module docstring).

    The probes go down the ladder until one is faithful, at most until the
    writing takes ``opts.stretch_factor ** opts.max_stretches`` the time of
    the first timing; the plan is then flown at the fastest faithful probe's
    pace (or a little slower, where the vehicle's limits make it stray). If no
    pace down to there is faithful, the slowest plan is returned (the caller
    decides). No re-segmentation (:func:`~skyquill.calligraphy.planning.resegmented`).

    Raises
    ------
    InfeasibleError
        The limits cannot be met even at the slowest pace tried.
    """
    full = TimingBounds.of(opts.limits)
    top = math.log(full.full_pace) / math.log(opts.stretch_factor)
    ladder = _Ladder(samples, board, opts, top)
    if opts.max_stretches == 0 or ladder.probe_faithful(top):
        return _flown(ladder, top)
    above, rung = top, ladder.slower(top)
    while not ladder.probe_faithful(rung):
        if ladder.slowest(rung):
            return _kept(ladder, rung)
        above, rung = rung, ladder.slower(rung)
    # The jump down may have passed faithful rungs: the bracket is the highest
    # faithful rung and the unfaithful one above it, the same whatever the limits.
    rung = _highest_faithful_rung(ladder, rung, above)
    return _flown(ladder, _bisect(ladder, rung, rung + 1))


def _highest_faithful_rung(ladder: _Ladder, low: float, high: float) -> float:
    """The highest rung whose probe is faithful between ``low`` (faithful) and ``high``
    (not), by bisection on the whole rungs between them."""
    lo, hi = float(low), float(math.ceil(high))  # hi: not faithful (or at the full pace)
    while hi - lo > 1:
        middle = math.floor(0.5 * (lo + hi))
        if middle <= lo:
            break
        if middle < ladder.top and ladder.probe_faithful(middle):
            lo = middle
        else:
            hi = middle
    return float(lo)


def _bisect(ladder: _Ladder, low: float, high: float) -> float:
    """The highest faithful dyadic point of ``[low, high]`` found by :data:`BISECTIONS` halvings.

    ``low``'s probe is faithful, ``high``'s is not (or it is at or above the full
    pace, whose probe is not).
    """
    return _highest(lambda u: u < ladder.top and ladder.probe_faithful(u), low, high)


def _highest(faithful: Callable[[float], bool], low: float, high: float) -> float:
    """The highest position of ``[low, high]`` found ``faithful`` by halving the bracket
    (``low`` is, ``high`` is not) down to ``2**-BISECTIONS`` of a rung."""
    while high - low > 2.0**-BISECTIONS * (1.0 + 1e-9):
        middle = 0.5 * (low + high)
        if faithful(middle):
            low = middle
        else:
            high = middle
    return low


def _flown(ladder: _Ladder, u: float) -> RoutePlan:
    """The plan at the fastest faithful probe's position ``u``, or, where the vehicle's
    limits make that plan stray, the highest faithful one below it to ``2**-BISECTIONS``
    of a rung: down in steps that double from that (up to a rung) until a plan is
    faithful, then the bracket halved (the flown timing only ever slows from the probe's).

    Without the halving, the doubled steps passed faithful plans: 人 at (1, 4, 5) m/s,
    m/s², m/s³ strayed from its full pace down to 0.58 and was flown at -0.42 (16.1 s),
    below the 0 (the timing of (1, 2, 5): 15.2 s) where it writes faithfully.
    """
    step, strayed = 2.0**-BISECTIONS, None
    while not ladder.faithful(u):
        if ladder.slowest(u):
            return _kept(ladder, u)
        strayed = u = min(u, ladder.top)
        u -= step
        step = min(2.0 * step, 1.0)
    if strayed is not None:
        u = _highest(ladder.faithful, u, strayed)
    return _kept(ladder, u)


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
