"""The reachability passes (skyquill.coverage.speed.reach) against the grid LP they replace.

The LP (HiGHS) is the independent reference: the passes' ``b`` must satisfy
every row of the LP's own matrix, its objective may not exceed the LP's
optimum, and the plans' durations must agree; looser limits must never give
a longer flight.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.interpolate import BSpline
from speed_curves import square_spiral, wiggle

from skyquill.coverage.speed import plan_speed
from skyquill.coverage.speed.curve import _derivs3
from skyquill.coverage.speed.norms import component_limits, components
from skyquill.coverage.speed.reach import ReachPass, acceleration_rows
from skyquill.coverage.speed.rows import _acc_matrix, _speed_bounds
from skyquill.errors import InputError

#: Largest relative gap between the passes' and the LP's durations on a 2,000-point grid
#: (measured 1.1e-4 per axis, 7.6e-5 with the 16-gon: the boxes of the rows that are not
#: monotone; the gap shrinks with the grid, 1e-5 at 8,000 points).
DURATION_RTOL = 3e-4


@pytest.mark.parametrize("norm_sides", [None, 16])
@pytest.mark.parametrize("vmax", [3.0, 100.0])
def test_durations_equal_the_lps(norm_sides: int | None, vmax: float) -> None:
    curve = square_spiral()
    kw = {"n": 2000, "norm_sides": norm_sides, "max_excess": None}
    reach = plan_speed(curve, vmax, 5.0, None, method="reach", **kw)
    lp = plan_speed(curve, vmax, 5.0, None, method="lp", **kw)
    assert reach.method == "reach" and lp.method == "lp"
    assert reach.duration == pytest.approx(lp.duration, rel=DURATION_RTOL)
    # Feasible for the LP, so never above its optimum.
    assert reach.b.sum() <= lp.b.sum() * (1.0 + 1e-9)


def _rows_hold(curve: BSpline, n: int, vmax: float, amax: float, sides: int | None) -> None:
    """The passes' ``b`` inside the LP's own rows and column bounds."""
    sig = np.linspace(0.0, 1.0, n)
    c1, c2, _ = _derivs3(curve, sig)
    ub, _ = _speed_bounds(c1, c2, vmax, chord_error=None, period=0.02)
    p1, p2 = components(c1, sides), components(c2, sides)
    limits = component_limits(np.full(2, amax), sides)
    b = ReachPass(acceleration_rows(p1, p2, sig[1], limits)).solve(np.ones(n - 1), ub)
    assert b is not None
    assert np.all(b >= 0.0) and np.all(b <= ub * (1 + 1e-12))
    rows = _acc_matrix(sig, (p1, p2), limits) @ b
    assert np.max(np.abs(rows)) <= 1.0 + 1e-9


def test_the_passes_hold_every_row_of_the_lp() -> None:
    for sides in (None, 8, 16):
        _rows_hold(square_spiral(), 3000, 3.0, 5.0, sides)


steps = st.tuples(st.floats(-3.0, 3.0), st.floats(-3.0, 3.0)).filter(
    lambda p: abs(p[0]) + abs(p[1]) > 0.2
)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    points=st.lists(steps, min_size=6, max_size=12),
    vmax=st.floats(0.2, 20.0),
    amax=st.floats(0.2, 20.0),
    sides=st.sampled_from([None, 4, 16]),
)
def test_random_paths_feasible_and_as_fast_as_the_lp(
    points: list[tuple[float, float]], vmax: float, amax: float, sides: int | None
) -> None:
    curve = wiggle([(0.0, 0.0), *points])
    try:
        fast = plan_speed(curve, vmax, amax, None, n=400, norm_sides=sides, max_excess=None)
    except InputError:  # a path with a cusp: refused by both
        with pytest.raises(InputError):
            plan_speed(curve, vmax, amax, None, n=400, norm_sides=sides, method="lp")
        return
    _rows_hold(curve, 400, vmax, amax, sides)
    ref = plan_speed(curve, vmax, amax, None, n=400, norm_sides=sides, max_excess=None, method="lp")
    assert fast.method == "reach"
    assert fast.b.sum() <= ref.b.sum() * (1 + 1e-9)
    # Coarse grids of sharp random paths: the boxes of the non-monotone rows cost more.
    assert fast.duration == pytest.approx(ref.duration, rel=0.02)


@settings(max_examples=20, deadline=None)
@given(
    looser_v=st.floats(1.0, 4.0),
    looser_a=st.floats(1.0, 4.0),
    vmax=st.floats(0.5, 5.0),
    amax=st.floats(0.5, 10.0),
    sides=st.sampled_from([None, 16]),
)
def test_looser_limits_never_give_a_longer_flight(
    looser_v: float, looser_a: float, vmax: float, amax: float, sides: int | None
) -> None:
    curve = square_spiral()
    kw = {"n": 600, "norm_sides": sides, "max_excess": None}
    tight = plan_speed(curve, vmax, amax, None, **kw)
    loose = plan_speed(curve, vmax * looser_v, amax * looser_a, None, **kw)
    assert loose.duration <= tight.duration * (1 + 1e-9)
    assert np.all(loose.b >= tight.b * (1 - 1e-9))  # the greatest element grows


def test_a_jerk_free_plan_verifies_within_two_percent() -> None:
    plan = plan_speed(square_spiral(), 3.0, 5.0, None, n=2000, norm_sides=16)
    assert plan.method == "reach"
    assert plan.verify(2.0).max_excess <= 0.02


def test_reach_with_a_jerk_limit_is_refused() -> None:
    with pytest.raises(InputError, match="method: got 'reach' with a jerk limit"):
        plan_speed(square_spiral(), 3.0, 5.0, 3.0, method="reach")
    with pytest.raises(InputError, match="method: got 'fast'"):
        plan_speed(square_spiral(), 3.0, 5.0, None, method="fast")
