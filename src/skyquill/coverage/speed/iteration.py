"""The pseudo-jerk iteration, its certification LP and the local refinement."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from skyquill.coverage.speed.curve import _derivs3
from skyquill.coverage.speed.norms import limit_ratio
from skyquill.coverage.speed.profile import (
    SpeedPlan,
    _interval_times,
    _profile_spline,
    rates_of_b,
    rates_of_w,
)
from skyquill.coverage.speed.rows import GridSolver, _Bounds, _end_caps
from skyquill.trajectory.retimed import increasing_preimage, interior_knots
from skyquill.validation import FloatArray

#: Even points per grid interval at which the refinement checks the plan (the dense check
#: samples >= 20 per interval), besides its end from the left and the path's kinks.
_SAMPLES = 24
#: Grid size up to which every interval gets _SAMPLES, and the fewest on finer grids.
_SAMPLE_GRID = 2000
_MIN_SAMPLES = 3
#: Weight of the last solution in the next pseudo-jerk reference (geometric mean).
DAMPING = 0.65
#: The iteration has stalled when its change has not fallen below STALL_FACTOR times the
#: smallest so far for STALL_ITERATIONS iterations in a row: on some grids it cycles (the
#: 2.2 ha part of examples/coverage/holes_10ha.geojson: the change stays at 1 %, and at 31 %
#: in the refinement rounds, for all 20 iterations of every round: 128 LPs, 49 s). The
#: certification LP that follows makes any reference feasible, so it is taken from there.
STALL_FACTOR = 0.9
STALL_ITERATIONS = 3


def _initial_solve(
    lp: GridSolver,
    bounds: _Bounds,
    *,
    c1: FloatArray,
    jmax: FloatArray | None,
    stop: tuple[int, float],
    log: tuple[list[float], list[float]],
) -> tuple[FloatArray, int]:
    """Jerk-free LP; with a jerk limit its rest ends capped first, then the pseudo-jerk
    iteration from its answer.

    The caps depend on the path alone, so the jerk-free problem is solved once, with
    them: its answer without them (solved first until session 43) only went to the
    log, and cost a tenth of a 2,000-point plan (a pass pair, 14 ms of 0.14 s).
    """
    if jmax is not None:
        _end_caps(bounds.ub, c1, jmax)
    b = lp.solve(bounds.rows(None), bounds.cols())
    log[0].append(float(b.sum()))
    if jmax is None:
        return b, 0
    return _pseudo_jerk(lp, bounds, b, stop=stop, log=log)


def _pseudo_jerk(
    lp: GridSolver,
    bounds: _Bounds,
    start: FloatArray,
    *,
    stop: tuple[int, float],
    log: tuple[list[float], list[float]],
) -> tuple[FloatArray, int]:
    """Damped pseudo-jerk fixed-point iteration from ``start``, then the certification LP.

    Each LP linearises ``sqrt(b)`` at a reference ``ref`` (the jerk rows read
    ``sqrt(ref) |X(b)| <= jmax``). The undamped iteration (``ref`` = the last
    solution, paper 001's) alternates around the fixed point and shrinks its
    error by about 0.55 a step: a reference too high gives rows too tight and
    a solution too low, and back. The next reference is therefore the
    geometric mean of the last reference and the last solution
    (:data:`DAMPING`), which removes most of that swing: on the 10 m square's
    spiral 4-6 LPs instead of 13-23, to the same fixed point.

    The final LP linearises at ``B = max(ref, b)`` and imposes ``b <= B``,
    which makes the true grid jerk ``sqrt(b) |X| <= sqrt(B) |X| <= jmax``.

    Parameters
    ----------
    lp
        The grid problem's solver.
    bounds
        Row/column bounds with the refinement factors.
    start
        First reference (an over-estimate: the jerk-free optimum, or the
        previous plan before a refinement).
    stop
        ``(max_iterations, tolerance)`` on the relative change of ``sqrt(b)``
        between a reference and its solution; the iteration also stops when it
        stalls (:data:`STALL_FACTOR`, :data:`STALL_ITERATIONS`).
    log
        Lists that receive the objectives and the relative changes.

    Returns
    -------
    tuple
        Final ``b`` and the number of iterations.
    """
    max_iter, tol = stop
    objectives, changes = log
    ub = bounds.cols()
    ref = b = start
    iterations = stalled = 0
    best = math.inf
    for _ in range(max_iter):
        b = lp.solve(bounds.rows(ref), ub, rough=True)
        iterations += 1
        objectives.append(float(b.sum()))
        sq = np.sqrt(b)
        change = float(np.max(np.abs(sq - np.sqrt(ref))) / max(np.max(sq), 1e-300))
        changes.append(change)
        stalled = stalled + 1 if change >= STALL_FACTOR * best else 0
        best = min(best, change)
        if change < tol or stalled >= STALL_ITERATIONS:
            break
        ref = ref ** (1.0 - DAMPING) * b**DAMPING
    big = np.maximum(ref, b)
    b = lp.solve(bounds.rows(big), np.minimum(ub, big))
    objectives.append(float(b.sum()))
    return b, iterations


def _refine(
    plan: SpeedPlan,
    lp: GridSolver,
    bounds: _Bounds,
    *,
    target: float | None,
    rounds: int,
    stop: tuple[int, float],
    log: tuple[list[float], list[float]],
) -> tuple[SpeedPlan, int, float, int]:
    """Tighten the limits locally and re-solve until the estimated excess meets ``target``.

    Returns
    -------
    tuple
        Final plan, refinement rounds done, its estimated max excess, extra
        pseudo-jerk iterations.
    """
    done = extra = 0
    samples = _Samples.of(plan)
    while True:
        excess = _interval_excess(plan, samples)
        est = float(max(np.max(x) for x in excess))
        if target is None or est <= target or done >= rounds:
            return plan, done, est, extra
        _tighten(bounds, excess, power=1.0 + done)
        if plan.jmax is None:
            b = lp.solve(bounds.rows(None), bounds.cols())
            log[0].append(float(b.sum()))
        else:
            b, its = _pseudo_jerk(lp, bounds, plan._bsig, stop=stop, log=log)
            extra += its
        spline = _profile_spline(plan._sigma, b, jerk=plan.jmax is not None)
        plan = replace(plan, _bsig=b, _bspline=spline)
        done += 1


class _Samples(NamedTuple):
    """Where the refinement checks a plan on its grid, and the path's derivatives there.

    Attributes
    ----------
    m
        Even samples per grid interval (besides its end from the left).
    even
        ``m`` even points of every interval, then its end from the left, shape
        ((n - 1) (m + 1),), on the grid's parameter.
    kinks
        The path's kinks, shape (K,) (:func:`_kinks`).
    at
        The interval each kink lies in, shape (K,).
    path_even, path_kinks
        The path's first three derivatives at ``even`` and at ``kinks``: the same in
        every refinement round (only the timing changes), evaluated once.
    blend
        The profile's spline and its derivatives at ``even`` as weights of its
        coefficients: ``(k + 1, m + 1)`` each, for a spline of degree ``k`` on the
        uniform grid (:func:`_blend`).
    """

    m: int
    even: FloatArray
    kinks: FloatArray
    at: NDArray[np.intp]
    path_even: tuple[FloatArray, FloatArray, FloatArray]
    path_kinks: tuple[FloatArray, FloatArray, FloatArray]
    blend: tuple[FloatArray, ...]

    @classmethod
    def of(cls, plan: SpeedPlan) -> _Samples:
        """The samples of ``plan``'s grid (see :func:`_interval_excess`)."""
        sig = plan._sigma
        # _SAMPLES per interval, fewer on a grid finer than _SAMPLE_GRID (the samples stay
        # as dense along the path), then the interval's end from the left.
        m = max(_MIN_SAMPLES, min(_SAMPLES, math.ceil(_SAMPLES * _SAMPLE_GRID / sig.size)))
        even = sig[:-1, None] + (sig[1] - sig[0]) * (np.arange(m) / m)[None, :]
        us = np.column_stack([even, np.nextafter(sig[1:], -np.inf)]).ravel()
        kinks = _kinks(plan)
        at = np.clip(np.searchsorted(sig, kinks, side="right") - 1, 0, sig.size - 2)
        path = plan._path
        blend = _blend(m, sig[1] - sig[0], jerk=plan.jmax is not None)
        return cls(m, us, kinks, at, _derivs3(path, us), _derivs3(path, kinks), blend)

    def rates(self, plan: SpeedPlan) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``plan``'s ``u_dot``, ``u_ddot``, ``u_dddot`` at :attr:`even`, each
        ((n - 1) (m + 1),).

        The profile is a spline on the uniform grid whose intervals are all sampled at
        the same local points, so its values there are each interval's coefficients
        times one matrix (:attr:`blend`): a small product where the B-spline's own
        evaluation searched the knots of 50,000 points three times a refinement round
        (a fifth of a 2,000-point jerk-limited plan). The same polynomials: they agree
        with it to round-off (``tests/coverage/test_speed_iteration.py``).
        """
        coef = plan._bspline.c
        windows = np.lib.stride_tricks.sliding_window_view(coef, len(self.blend[0]))
        values = [np.dot(windows[: plan._sigma.size - 1], w).ravel() for w in self.blend]
        if plan.jmax is None:
            return rates_of_b(values[0], values[1])
        return rates_of_w(values[0], values[1], values[2])


def _blend(m: int, h: float, *, jerk: bool) -> tuple[FloatArray, ...]:
    """Weights of a uniform spline's coefficients at ``t = 0, 1/m, ..., (m - 1)/m`` and
    ``t = 1`` (the end from the left) of each interval of width ``h``: the value and its
    first two derivatives in ``u`` of a cubic (``jerk``; shapes (4, m + 1), the uniform
    cubic B-spline's blending functions), else the value and the slope of a linear spline
    ((2, m + 1))."""
    t = np.append(np.arange(m) / m, 1.0)
    if not jerk:
        return np.stack([1.0 - t, t]), np.stack([-np.ones_like(t), np.ones_like(t)]) / h
    s = 1.0 - t
    value = np.stack([s**3, 3 * t**3 - 6 * t**2 + 4, -3 * t**3 + 3 * t**2 + 3 * t + 1, t**3])
    slope = np.stack([-3 * s**2, 9 * t**2 - 12 * t, -9 * t**2 + 6 * t + 3, 3 * t**2])
    curvature = np.stack([6 * s, 18 * t - 12, -18 * t + 6, 6 * t])
    return value / 6.0, slope / (6.0 * h), curvature / (6.0 * h * h)


def _interval_excess(
    plan: SpeedPlan, samples: _Samples
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Relative speed, acceleration and jerk excess of each grid interval.

    The chain-rule derivatives of the interpolated plan (what
    :meth:`SpeedPlan.setpoints` outputs and :meth:`SpeedPlan.verify`
    differences) are evaluated where the dense check of the flight
    (:func:`skyquill.trajectory.base.check_times`) looks (``samples``): at
    ``_SAMPLES`` even points of each interval, at its end from the left, and at
    the path's kinks (its curve's knots, :func:`_kinks`).  The interval's end:
    the profile's jerk jumps at every grid node (``w = b**(3/4)`` is a cubic
    spline), and the path's last point, the rest end, was never sampled before
    session 38. The 2.2 ha part of ``examples/coverage/holes_10ha.geojson``
    flew 2.3 % over its jerk limit there while the refinement saw none, was
    refused by the dense check and went on to finer grids (9.1 s of planning,
    then a +0.5 % flight); its first grid now passes. The samples every
    ``control_period / 10`` of an interval's traversal time (up to 256 an
    interval, 860,000 on a 1,700 s flight: 0.6 s a round) that came near it
    are gone: the dense check of the flight samples 20 a span. The kinks: the
    jerk peaks there, narrowly, between samples (a 1.3 ha field's flight:
    0.9 % over the limit on the samples, 2.3 % at the kinks).  Acceleration
    and jerk are measured against the limits the caller asked for (per axis,
    or the norm), not the LP's polygon.

    Returns
    -------
    tuple of ndarray, shape (n - 1,)
        ``max(ratio - 1, 0)`` per interval for speed, acceleration, jerk.
    """
    sig = plan._sigma
    # A plan that stops the vehicle between the rest ends is refused here (InfeasibleError).
    _interval_times(plan._bsig, sig[1] - sig[0], jerk=plan.jmax is not None)
    per_interval = (sig.size - 1, samples.m + 1)
    even = _ratios(plan, samples.rates(plan), samples.path_even)
    ex = [np.maximum(x.reshape(per_interval).max(axis=1) - 1.0, 0.0) for x in even]
    if samples.kinks.size:
        ratios = _ratios(plan, plan._derivs(samples.kinks), samples.path_kinks)
        for x, per in zip(ratios, ex, strict=True):
            np.maximum.at(per, samples.at, x - 1.0)
    return ex[0], ex[1], ex[2]


def _ratios(
    plan: SpeedPlan,
    rates: tuple[FloatArray, FloatArray, FloatArray],
    path: tuple[FloatArray, FloatArray, FloatArray],
) -> list[FloatArray]:
    """Speed, acceleration and jerk over their limits at M points where the timing's
    ``rates`` are ``u_dot``, ``u_ddot``, ``u_dddot`` (each (M,)) and the path's first
    three derivatives ``path`` (each (M, d))."""
    ud, udd, uddd = rates
    c1, c2, c3 = path
    speed = np.linalg.norm(c1, axis=1) * ud / plan.vmax
    acc = limit_ratio(c2 * (ud**2)[:, None] + c1 * udd[:, None], plan.amax, plan.norm_sides)
    if plan.jmax is None:
        return [speed, acc, np.zeros_like(speed)]
    jerk = c3 * (ud**3)[:, None] + 3.0 * c2 * (ud * udd)[:, None] + c1 * uddd[:, None]
    return [speed, acc, limit_ratio(jerk, plan.jmax, plan.norm_sides)]


def _kinks(plan: SpeedPlan) -> FloatArray:
    """The grid parameters (K,) of the path's kinks: its curve's interior knots (a B-spline
    curve's), and on an adaptive grid its map's, where the map takes the curve's there."""
    knots = interior_knots(plan.curve)
    if plan._umap is None:
        return knots
    sigma = increasing_preimage(plan._umap, knots, np.zeros(knots.size), np.ones(knots.size))
    return np.sort(np.concatenate([sigma, interior_knots(plan._umap)]))


def _spread(x: FloatArray, lo: int, hi: int, size: int) -> FloatArray:
    """``out[i] = max(x[i - hi .. i - lo])`` (clipped), for mapping intervals to nodes."""
    out = np.zeros(size)
    for s in range(lo, hi + 1):
        dst = slice(max(s, 0), min(size, x.size + s))
        src = slice(max(-s, 0), max(-s, 0) + dst.stop - dst.start)
        out[dst] = np.maximum(out[dst], x[src])
    return out


def _tighten(
    bounds: _Bounds, excess: tuple[FloatArray, FloatArray, FloatArray], *, power: float
) -> None:
    """Lower the limits near every interval with an excess by ``(1 + excess)**power``.

    Interval ``k`` of the cubic ``w`` interpolant depends on nodes ``k - 1 .. k + 2``;
    all of them are tightened (speed, jerk), and the acceleration rows of the
    interval and its neighbours.  The caller raises ``power`` round by round:
    where the interpolant's jerk is not proportional to the grid's (short
    features, rest ends) a plain ``1 / (1 + excess)`` converges only
    geometrically.  The rest-end caps on ``b_1``, ``b_{n-2}`` are jerk limits
    too (``b_1**1.5`` scales like the jerk) and follow the worst of the three
    intervals each shapes (``0 .. 2``, ``n - 4 .. n - 2``): following the end
    interval alone, the 2,000-point spiral of the 10 m square kept 4-6 % of
    jerk excess in interval ``n - 3`` through three rounds (its cap, which that
    interval's cubic reads, never moved) and took four rounds (0.17 s); now one
    (0.12 s, a 0.14 % shorter flight; elsewhere the flights moved by at most
    0.06 %, the rounds not at all).
    """
    ev, ea, ej = excess
    n = bounds.ub.size
    bounds.speed = bounds.speed / (1.0 + _spread(ev, -1, 2, n)) ** power
    bounds.jerk = bounds.jerk / (1.0 + _spread(ej, -1, 2, n)) ** power
    bounds.acc = bounds.acc / (1.0 + _spread(ea, -1, 1, n - 1)) ** power
    # speed**2 multiplies the column bound, so b scales like (1 + e)**(-2/3).
    ends = np.array([ej[:3].max(), ej[-3:].max()])
    bounds.speed[[1, n - 2]] /= (1.0 + ends) ** (power / 3.0)
