"""The banded interior-point method (skyquill.coverage.speed.banded) against HiGHS.

The HiGHS grid LP is the independent reference: on the pseudo-jerk LPs the
interior point's ``b`` must hold every row of the LP's own sparse matrix and
every column bound, and its objective must equal HiGHS's optimum; the plans
of ``method="banded"``, ``method="warm"`` and ``method="lp"`` must agree; looser limits must not
give a longer jerk-limited flight.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy import sparse
from scipy.interpolate import BSpline
from speed_curves import square_spiral, wiggle

from skyquill.coverage.speed import plan_speed
from skyquill.coverage.speed.active_rows import nearest_rows, row_ratios, solve_active_rows
from skyquill.coverage.speed.banded import BandedRows, solve_banded_lp
from skyquill.coverage.speed.banded_grid import HELD, banded_rows, lp_rows, row_bounds
from skyquill.coverage.speed.curve import _derivs3
from skyquill.coverage.speed.norms import component_limits, components
from skyquill.coverage.speed.reach import acceleration_rows
from skyquill.coverage.speed.rows import (
    _acc_matrix,
    _Bounds,
    _end_caps,
    _GridLP,
    _jerk_matrix,
    _ones,
    _speed_bounds,
)
from skyquill.coverage.speed.validate import BANDED_FROM_POINTS, _validate_method
from skyquill.errors import InputError
from skyquill.validation import FloatArray

#: Relative gap of the interior point's objective to HiGHS's optimum (solved to 1e-9).
OBJECTIVE_RTOL = 1e-7


#: One pseudo-jerk LP: the LP's sparse matrix, its row bounds, the column bounds, and the
#: same rows per node.
PseudoJerkLP = tuple[sparse.csr_array, FloatArray, FloatArray, BandedRows]


def _pseudo_jerk_lp(
    curve: BSpline, n: int, limits: tuple[float, float, float], sides: int | None, shrink: float
) -> PseudoJerkLP:
    """The LP linearised at ``shrink`` times the jerk-free optimum."""
    vmax, amax, jmax = limits
    sig = np.linspace(0.0, 1.0, n)
    c1, c2, c3 = _derivs3(curve, sig)
    ub, vb = _speed_bounds(c1, c2, vmax, chord_error=None, period=0.02)
    p1, p2, p3 = (components(c, sides) for c in (c1, c2, c3))
    alim = component_limits(np.full(2, amax), sides)
    jlim = component_limits(np.full(2, jmax), sides)
    a = sparse.vstack(
        [_acc_matrix(sig, (p1, p2), alim), _jerk_matrix((p1, p2, p3), jlim, vb)], format="csr"
    )
    bounds = _Bounds(ub, vb, p1.shape[1], *_ones(n))
    _end_caps(bounds.ub, p1, jlim)
    free = plan_speed(curve, vmax, amax, None, n=n, norm_sides=sides, max_excess=None).b
    r = bounds.rows(np.maximum(shrink * free, 1e-12))
    rows = banded_rows(acceleration_rows(p1, p2, sig[1], alim), (p1, p2, p3), jlim, vb)
    return a, r, bounds.cols(), rows


def _holds_and_equals_highs(lp: PseudoJerkLP, b: FloatArray) -> None:
    """``b`` inside every row and column bound of the LP, and at HiGHS's optimum."""
    a, r, ub, _ = lp
    ref = _GridLP(a, backend="highspy").solve(r, ub)
    finite = np.isfinite(r)
    assert np.all(b >= 0.0) and np.all(b <= ub)
    assert np.max(np.abs(a @ b)[finite] / r[finite]) <= 1.0 + 1e-9
    assert b.sum() == pytest.approx(ref.sum(), rel=OBJECTIVE_RTOL)


def _check_against_highs(lp: PseudoJerkLP) -> None:
    _, r, ub, rows = lp
    n = ub.size
    got = solve_banded_lp(rows, row_bounds(r, n, rows.centre.shape[0] // 3), ub, np.ones(n))
    assert got.status == "optimal"
    _holds_and_equals_highs(lp, got.b)


@pytest.mark.parametrize("sides", [None, 16])
@pytest.mark.parametrize("shrink", [1.0, 0.6])
def test_the_interior_point_equals_highs_on_the_spirals_pseudo_jerk_lp(
    sides: int | None, shrink: float
) -> None:
    _check_against_highs(_pseudo_jerk_lp(square_spiral(), 500, (3.0, 5.0, 3.0), sides, shrink))


@pytest.mark.parametrize("guess", ["free", "zero"])
def test_the_rows_that_bind_give_the_whole_lps_optimum(guess: str) -> None:
    # A guess far from the answer (the jerk-free optimum breaks most jerk rows; zero picks
    # rows at random): broken rows are added until none is, or the whole LP is solved.
    lp = _pseudo_jerk_lp(square_spiral(), 500, (3.0, 5.0, 3.0), 16, 0.8)
    _, r, ub, rows = lp
    start = ub if guess == "free" else np.zeros_like(ub)
    got, solves = solve_active_rows(rows, row_bounds(r, ub.size, 8), ub, guess=start, blocks=3,
                                    tolerance=1e-9)  # fmt: skip
    assert got.status == "optimal" and solves >= 1
    _holds_and_equals_highs(lp, got.b)


@pytest.mark.parametrize("guess", ["free", "zero"])
def test_highs_on_the_rows_that_bind_gives_the_whole_lps_optimum(guess: str) -> None:
    # HiGHS given the rows nearest their bound at a guess (or, at zero, rows at random):
    # every answer is checked against all rows and the broken ones added, so the optimum is
    # the whole LP's, and HiGHS holds fewer rows than it.
    lp = _pseudo_jerk_lp(square_spiral(), 500, (3.0, 5.0, 3.0), 16, 0.8)
    a, r, ub, rows = lp
    start = ub if guess == "free" else np.zeros_like(ub)
    mask = nearest_rows(row_ratios(rows, row_bounds(r, ub.size, 8), start), 3, HELD)
    held = lp_rows(mask, 8)
    grid = _GridLP(a, backend="highspy", rows=held)
    _holds_and_equals_highs(lp, grid.solve(r, ub))
    assert held.size < grid.lp.a.shape[0] < a.shape[0]
    assert grid.solves > 1  # rows were added and the problem solved again


def test_lp_rows_are_the_lps_own() -> None:
    # The per-node layout's rows map back onto the LP's row bounds (row_bounds' inverse).
    n, q = 7, 2
    r = np.arange(2 * q * (n - 1) + q * (n - 2), dtype=float)
    per_node = row_bounds(r, n, q)
    mask = np.isfinite(per_node) & (np.arange(n) % 2 == 0)
    assert np.array_equal(r[lp_rows(mask, q)], np.sort(per_node[mask]))


steps = st.tuples(st.floats(-3.0, 3.0), st.floats(-3.0, 3.0)).filter(
    lambda p: abs(p[0]) + abs(p[1]) > 0.2
)


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    points=st.lists(steps, min_size=6, max_size=10),
    limits=st.tuples(st.floats(0.5, 10.0), st.floats(0.5, 10.0), st.floats(0.5, 20.0)),
    sides=st.sampled_from([None, 4, 16]),
    shrink=st.floats(0.3, 1.0),
)
def test_random_pseudo_jerk_lps_equal_highs(
    points: list[tuple[float, float]],
    limits: tuple[float, float, float],
    sides: int | None,
    shrink: float,
) -> None:
    curve = wiggle([(0.0, 0.0), *points])
    try:
        lp = _pseudo_jerk_lp(curve, 300, limits, sides, shrink)
    except InputError:  # a path with a cusp
        return
    _check_against_highs(lp)


#: A hook, an S and a zigzag with rounded corners: paths other than the spiral.
PATHS = {
    "hook": [(0, 0), (3, 0), (5, 1), (5, 3), (3, 4), (2, 3)],
    "s": [(0, 0), (2, 1), (2, 3), (0, 4), (0, 6), (2, 7)],
    "zigzag": [(0, 0), (6, 0), (6, 1), (0, 1), (0, 2), (6, 2)],
}


@pytest.mark.parametrize("method", ["banded", "warm"])
@pytest.mark.parametrize("sides", [None, 16])
@pytest.mark.parametrize("path", ["spiral", *PATHS])
def test_banded_and_warm_plans_equal_the_lps(path: str, sides: int | None, method: str) -> None:
    curve = square_spiral() if path == "spiral" else wiggle(PATHS[path])
    kw = {"n": 500, "norm_sides": sides}
    got = plan_speed(curve, 3.0, 5.0, 3.0, method=method, **kw)
    lp = plan_speed(curve, 3.0, 5.0, 3.0, method="lp", **kw)
    assert got.method == method and lp.method == "lp"
    assert got.duration == pytest.approx(lp.duration, rel=1e-4)
    # The dense check: within the 2 % the refinement aims at (SpeedPlan.verify).
    assert got.verify(2.0).max_excess <= 0.02


@pytest.mark.parametrize("sides", [None, 16])
def test_the_warm_start_takes_the_lps_own_answers_in_fewer_pivots(sides: int | None) -> None:
    """Every LP after the first jerk-limited one is HiGHS's, so the plan is the LP's (to
    round-off: a degenerate LP may answer another optimal vertex); on a 2,000-point grid
    HiGHS pivots less than half as often as from the jerk-free basis."""
    pivots = {}
    plans = {}
    for method in ("warm", "lp"):
        counted = _count_pivots()
        plans[method] = plan_speed(square_spiral(), 3.0, 5.0, 3.0, n=2000, norm_sides=sides,
                                   method=method)  # fmt: skip
        pivots[method] = counted()
    assert plans["warm"].duration == pytest.approx(plans["lp"].duration, rel=1e-6)
    assert np.max(np.abs(plans["warm"].b - plans["lp"].b)) <= 1e-6 * np.max(plans["lp"].b)
    assert pivots["warm"] < 0.5 * pivots["lp"]


def test_a_stalled_warm_start_starts_again_from_the_interior_point(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """Every hot re-solve told stalled at once: each starts again from the interior point's
    vertex, HiGHS keeps answering (not linprog), and the plan is still the LP's."""
    from skyquill.solvers import lp as lp_module

    lp = plan_speed(square_spiral(), 3.0, 5.0, 3.0, n=500, norm_sides=16, method="lp")
    monkeypatch.setattr(lp_module, "RESTART_ITERATIONS_PER_COLUMN", 0)
    with caplog.at_level("INFO", logger="skyquill.solvers.lp"):
        warm = plan_speed(square_spiral(), 3.0, 5.0, 3.0, n=500, norm_sides=16, method="warm")
    messages = [r.getMessage() for r in caplog.records]
    assert any("from the vertex of the restart point" in m for m in messages)
    assert not any("linprog" in m for m in messages)
    assert warm.duration == pytest.approx(lp.duration, rel=1e-6)


def _count_pivots() -> Callable[[], int]:
    """A counter of the simplex pivots of every HiGHS solve from now on."""
    from skyquill.solvers import lp as lp_module

    total = [0]
    run = lp_module._HighsModel._run

    def counting(
        self: lp_module._HighsModel, limit_s: float, per_column: float | None = None
    ) -> object:
        status = run(self, limit_s, per_column)
        total[0] += max(int(self.highs.getInfo().simplex_iteration_count), 0)
        return status

    patch = pytest.MonkeyPatch()
    patch.setattr(lp_module._HighsModel, "_run", counting)

    def read() -> int:
        patch.undo()
        return total[0]

    return read


def test_auto_takes_the_warm_start_and_the_banded_method_on_fine_grids() -> None:
    assert plan_speed(square_spiral(), 3.0, 5.0, 3.0, n=300).method == "warm"
    assert _validate_method("auto", jerk=True, n=BANDED_FROM_POINTS - 1) == "warm"
    assert _validate_method("auto", jerk=True, n=BANDED_FROM_POINTS) == "banded"
    for method in ("banded", "warm"):
        plan = plan_speed(square_spiral(), 3.0, 5.0, None, n=300, method=method)
        assert plan.method == "reach"


#: How much longer a looser jerk-limited plan may be: the pseudo-jerk iteration stops at
#: a relative change of 1e-3 of sqrt(b), so two fixed points agree to about that.
LOOSER_RTOL = 2e-3


@settings(max_examples=10, deadline=None)
@given(
    looser=st.tuples(st.floats(1.0, 3.0), st.floats(1.0, 3.0), st.floats(1.0, 3.0)),
    limits=st.tuples(st.floats(0.5, 5.0), st.floats(0.5, 10.0), st.floats(0.5, 10.0)),
    sides=st.sampled_from([None, 16]),
)
def test_looser_limits_never_give_a_longer_jerk_limited_flight(
    looser: tuple[float, float, float], limits: tuple[float, float, float], sides: int | None
) -> None:
    # The banded method only: the simplex's answers ("lp", and "warm", which is HiGHS from
    # its second solve on) can stop the vehicle between two nodes of this coarse grid, at
    # the tighter limits (1, 1.25, 1) or only at the looser ones ((2, 3, 5) -> (2, 6, 10)):
    # a refusal of that grid, which coverage answers with a finer one (GRID_LADDER). The
    # interior point's answers stay inside and plan both.
    kw = {"n": 300, "norm_sides": sides, "max_excess": None, "method": "banded"}
    tight = plan_speed(square_spiral(), *limits, **kw)
    loose = plan_speed(square_spiral(), *(x * k for x, k in zip(limits, looser, strict=True)), **kw)
    assert loose.duration <= tight.duration * (1.0 + LOOSER_RTOL)
