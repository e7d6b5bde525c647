"""The pseudo-jerk iteration stops when it stalls, and only then (coverage/speed/iteration.py)."""

from __future__ import annotations

import itertools
from collections.abc import Callable

import numpy as np

from skyquill.coverage.speed.iteration import _pseudo_jerk
from skyquill.coverage.speed.rows import _Bounds, _ones
from skyquill.validation import FloatArray

N = 8


class _Scripted:
    """A grid solver whose iterates follow ``answer(k)``; records which solves were rough."""

    def __init__(self, answer: Callable[[int], FloatArray]) -> None:
        self.answer = answer
        self.rough: list[bool] = []

    @property
    def time(self) -> float:
        return 0.0

    @property
    def solves(self) -> int:
        return len(self.rough)

    def solve(self, r: FloatArray, ub: FloatArray, *, rough: bool = False) -> FloatArray:
        self.rough.append(rough)
        return self.answer(len(self.rough))


def _bounds() -> _Bounds:
    return _Bounds(np.full(N, np.inf), np.ones(N), 2, *_ones(N))


def _run(answer: Callable[[int], FloatArray]) -> tuple[_Scripted, int, list[float]]:
    solver = _Scripted(answer)
    log: tuple[list[float], list[float]] = ([], [])
    _, iterations = _pseudo_jerk(solver, _bounds(), np.full(N, 4.0), stop=(20, 1e-3), log=log)
    return solver, iterations, log[1]


def test_a_cycling_iteration_stops_and_is_certified() -> None:
    # Two iterates 10 % apart in turn: the change never falls below the tolerance.
    solver, iterations, changes = _run(lambda k: np.full(N, 1.0 if k % 2 else 1.21))
    assert iterations < 20
    assert iterations <= 10  # the damped reference settles between the two, then it stalls
    assert solver.rough == [True] * iterations + [False]  # the certification LP last
    assert min(changes) > 1e-3


def test_a_converging_iteration_is_not_stopped_early() -> None:
    # The change shrinks by a third each time, slowly: it runs to the tolerance.
    solver, iterations, changes = _run(lambda k: np.full(N, 1.0 + 0.6 ** (k + 2)))
    assert changes[-1] < 1e-3 <= changes[-2]
    assert iterations == len(changes) > 3
    assert all(later < earlier for earlier, later in itertools.pairwise(changes))
    assert solver.rough[-1] is False


def test_the_flight_is_within_its_limits_at_the_curve_knots() -> None:
    # The 30 x 100 m piece of holes_1_3ha: its speed plan checked on even samples only flew
    # 2.1 % over the jerk limit where the path crosses its curve's knots (between the
    # samples), while its dense check said 0.25 %. The refinement and the check now take
    # the kinks too.
    from pathlib import Path

    from shapely.geometry import Point

    from skyquill.coverage.holes import hole_free_pieces
    from skyquill.coverage.partition import convex_parts
    from skyquill.coverage.plan import CoverageOptions, coverage_limits, plan_tuned
    from skyquill.coverage.regions import load_region
    from skyquill.trajectory import RetimedPath
    from skyquill.trajectory.base import derivatives

    field = Path(__file__).parents[2] / "examples" / "coverage" / "holes_1_3ha.geojson"
    parts = [q for p in hole_free_pieces(load_region(field), 5.0) for q in convex_parts(p, 5.0)]
    piece = next(p for p in parts if p.contains(Point(3.0, 3.0)))
    plan = plan_tuned(piece, CoverageOptions(width=5.0), 0.995)
    flight = plan.trajectory
    assert isinstance(flight, RetimedPath)
    kinks = flight.kink_times()
    at_kinks = derivatives(flight, kinks, [1, 2, 3])
    limits = coverage_limits(plan.options)
    worst = max(lim.relative_excess(at_kinks[lim.order])[1] for lim in limits)
    assert kinks.size > 10
    assert worst <= 0.02
    assert plan.limits["max_excess"] >= worst  # the check saw them


def test_the_refinement_samples_every_interval_end_from_the_left() -> None:
    """Where the dense check looks: the side before every node, the path's end included (a
    2.2 ha part of holes_10ha flew 2.3 % over its jerk limit at its rest end, unsampled)."""
    from speed_curves import square_spiral

    from skyquill.coverage.speed import iteration, plan_speed

    plan = plan_speed(square_spiral(), 3.0, 5.0, 3.0, n=200, max_excess=None)
    samples = iteration._Samples.of(plan)
    sampled = samples.even
    ends = np.nextafter(plan._sigma[1:], -np.inf)
    assert np.isin(ends, sampled).all() and ends[-1] < 1.0 == plan._sigma[-1]
    assert np.isin(plan._sigma[:-1], sampled).all()
    # The path's derivatives there are evaluated once, for every refinement round.
    np.testing.assert_array_equal(samples.path_even[2], plan._path(sampled, nu=3))


def test_the_refinement_reads_the_profile_as_the_spline_evaluates_it() -> None:
    """The timing's rates at the even samples, from each interval's coefficients times one
    matrix, are the profile spline's own (with a jerk limit a cubic in ``b**(3/4)``, without
    one linear in ``b``), the interval ends from the left included."""
    from speed_curves import square_spiral

    from skyquill.coverage.speed import iteration, plan_speed

    for jmax in (3.0, None):
        plan = plan_speed(square_spiral(), 3.0, 5.0, jmax, n=300, max_excess=None)
        samples = iteration._Samples.of(plan)
        for blended, evaluated in zip(samples.rates(plan), plan._derivs(samples.even), strict=True):
            # To round-off, but at the rest ends, where w = 0 and the cube root of w's
            # round-off is read: the blend gives the end itself from the left and the
            # spline the point an ulp before it (w ~ 1e-12); at the start the blend's
            # w = (-w_1 + w_1) / 6 is 4e-14 (rates of ~1e-7 against limits of 1-5).
            scale = max(1.0, float(np.abs(evaluated).max()))
            inner = slice(1, -1)
            np.testing.assert_allclose(blended[inner], evaluated[inner], rtol=0, atol=1e-9 * scale)
            ends = [0, -1]
            np.testing.assert_allclose(blended[ends], evaluated[ends], rtol=0, atol=1e-6 * scale)
