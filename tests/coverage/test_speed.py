"""Tests for skyquill.coverage.speed (LP speed planning, §2.1-2.2)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import BSpline, CubicSpline, make_interp_spline
from speed_curves import square_spiral

from skyquill.coverage.speed import SpeedPlan, plan_speed
from skyquill.errors import InputError


def _line(length: float) -> BSpline:
    x = np.linspace(0.0, 1.0, 8)
    return make_interp_spline(x, np.column_stack([length * x, 0.0 * x]), k=3)


def _circle(radius: float = 1.0) -> BSpline:
    th = np.linspace(0.0, 1.0, 60)
    pts = np.column_stack([np.cos(2 * np.pi * th), np.sin(2 * np.pi * th)]) * radius
    return make_interp_spline(th, pts, k=5)


def _bang_bang_time(length: float, vmax: float, amax: float) -> float:
    d_acc = vmax**2 / amax
    if d_acc >= length:
        return float(2.0 * np.sqrt(length / amax))
    return 2.0 * vmax / amax + (length - d_acc) / vmax


def _walk_check(plan: SpeedPlan, period: float) -> float:
    """Largest relative excess of the §2.2 walk's setpoints at ``period``, by finite differences.

    The walk is the paper's interpolation (the delivered trajectory is the
    retimed path, :meth:`SpeedPlan.verify`); its positions are differenced here,
    padded with rest before and after so that a start with acceleration shows
    up as jerk.
    """
    sp = plan.setpoints(period)
    p = np.concatenate([np.repeat(sp.p[:1], 3, axis=0), sp.p, np.repeat(sp.p[-1:], 3, axis=0)])
    speed = np.linalg.norm(np.diff(p, axis=0), axis=1).max() / period / plan.vmax
    ratios = [speed, (np.abs(np.diff(p, n=2, axis=0)) / period**2 / plan.amax).max()]
    if plan.jmax is not None:
        ratios.append((np.abs(np.diff(p, n=3, axis=0)) / period**3 / plan.jmax).max())
    return max(0.0, float(max(ratios)) - 1.0)


def _s_curve_time(length: float, vmax: float, amax: float, jmax: float) -> float:
    # Only the case used below: vmax = amax**2 / jmax (triangular acc profile).
    assert np.isclose(vmax, amax**2 / jmax)
    t_acc = 2.0 * amax / jmax
    d_acc = vmax * t_acc / 2.0
    assert 2 * d_acc <= length
    return 2.0 * t_acc + (length - 2 * d_acc) / vmax


@pytest.mark.parametrize(("n", "tol"), [(100, 1e-3), (1000, 1e-5)])
def test_line_matches_bang_bang(n: int, tol: float) -> None:
    plan = plan_speed(_line(2.0), 1.0, 1.0, None, n=n)
    exact = _bang_bang_time(2.0, 1.0, 1.0)
    assert abs(plan.duration - exact) / exact < tol
    short = plan_speed(_line(0.5), 1.0, 1.0, None, n=n)
    assert abs(short.duration - _bang_bang_time(0.5, 1.0, 1.0)) / short.duration < 10 * tol
    ver = plan.verify()
    assert ver.max_excess <= 0.02
    sp = plan.setpoints()
    assert abs(sp.t[-1] - exact) <= 0.021


def test_endpoints_at_rest() -> None:
    for jmax in (None, 3.0):
        plan = plan_speed(_circle(), 1.0, 2.0, jmax, n=300)
        assert plan.b[0] == 0.0 and plan.b[-1] == 0.0
        sp = plan.setpoints()
        assert np.allclose(sp.v[0], 0.0) and np.allclose(sp.v[-1], 0.0)
        assert np.allclose(sp.p[0], _circle()(0.0)) and np.allclose(sp.p[-1], _circle()(1.0))


def test_circle_speed_capped_by_centripetal_limit() -> None:
    radius, amax = 1.0, 1.0
    plan = plan_speed(_circle(radius), 10.0, amax, None, n=1000)
    speed = np.sqrt(plan.b) * np.linalg.norm(_circle(radius)(plan.u, 1), axis=1)
    mid = slice(300, 700)
    # Per-axis limit: v**2/R * max(|cos|, |sin|) <= amax, so the speed lies
    # between sqrt(amax R) (on the axes) and sqrt(sqrt(2) amax R) (diagonals).
    cap = np.sqrt(amax * radius)
    assert np.min(speed[mid]) == pytest.approx(cap, rel=0.02)
    assert np.max(speed) <= np.sqrt(np.sqrt(2.0) * amax * radius) * 1.02
    assert plan.verify().max_excess <= 0.02


def test_chord_error_caps_speed() -> None:
    eps, period = 1e-4, 0.02
    plan = plan_speed(_circle(), 10.0, 100.0, None, n=400, chord_error=eps, control_period=period)
    speed = np.sqrt(plan.b) * np.linalg.norm(_circle()(plan.u, 1), axis=1)
    assert np.max(speed) <= np.sqrt(8 * 1.0 * eps / period**2) * 1.01


def test_jerk_line_matches_s_curve_and_verifies() -> None:
    plan = plan_speed(_line(3.0), 1.0, 1.0, 1.0, n=1000)
    exact = _s_curve_time(3.0, 1.0, 1.0, 1.0)
    # Conservative (end caps + grid): ~1.3 % slower than the analytic S-curve.
    assert exact <= plan.duration <= exact * 1.02
    ver = plan.verify()
    assert ver.excess(3) <= 0.02
    assert ver.max_excess <= 0.02


def test_jerk_circle_excess_within_two_percent() -> None:
    plan = plan_speed(_circle(), 1.0, 2.0, 3.0, n=1000)
    fine = plan.verify()
    ctrl = _walk_check(plan, plan.control_period)
    assert fine.max_excess <= 0.02, fine
    assert ctrl <= 0.02, ctrl
    # The jerk limit binds: measured jerk reaches the limit.
    assert np.max(np.asarray(fine.max_jerk) / 3.0) > 0.95


def test_pseudo_jerk_iteration_converges_monotonically() -> None:
    # The base iteration alone: refinement rounds restart it from a tightened
    # problem (their changes/objectives are appended and need not be monotone).
    plan = plan_speed(
        _circle(), 1.0, 2.0, 3.0, n=500, jerk_iterations=30, jerk_tol=1e-4, max_excess=None
    )
    assert plan.refinements == 0
    changes = np.asarray(plan.jerk_changes)
    assert plan.iterations == changes.size >= 2
    assert np.all(np.diff(changes) < 0.0)  # contraction
    assert changes[-1] < 1e-4
    # Iterates alternate around the fixed point; the brackets shrink.
    obj = np.asarray(plan.objectives[1:-1])
    gaps = np.abs(np.diff(obj))
    assert np.all(np.diff(gaps) < 0.0)
    # The jerk-free optimum (rest ends capped) bounds everything from above.
    assert plan.objectives[0] >= max(plan.objectives[1:])


def test_cubic_spline_curve_accepted() -> None:
    ss = np.linspace(0.0, 1.0, 6)
    pts = np.column_stack([ss, np.sin(3 * ss), 0.2 * ss**2])
    plan = plan_speed(CubicSpline(ss, pts), 0.8, [1.0, 1.5, 2.0], [4.0, 4.0, 4.0], n=300)
    assert plan.duration > 0.0 and plan.amax.shape == (3,)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"max_excess": -0.1}, "max_excess"),
        ({"refine_rounds": -1}, "refine_rounds"),
        ({"lp_backend": "glpk"}, "lp_backend"),
        ({"grid": "auto"}, "grid"),
        ({"vmax": 0.0}, "vmax"),
        ({"vmax": -1.0}, "vmax"),
        ({"n": 2}, "^n: got"),
        ({"amax": [1.0, 2.0, 3.0]}, "amax"),
        ({"jmax": -1.0}, "jmax"),
        ({"chord_error": 0.0}, "chord_error"),
        ({"control_period": 0.0}, "control_period"),
    ],
)
def test_bad_input(kwargs: dict[str, object], match: str) -> None:
    args: dict[str, object] = {"vmax": 1.0, "amax": 1.0, "jmax": None, "n": 50}
    args.update(kwargs)
    with pytest.raises(InputError, match=match):
        plan_speed(_line(1.0), **args)  # type: ignore[arg-type]


def test_non_callable_curve() -> None:
    with pytest.raises(InputError, match="callable"):
        plan_speed(np.zeros((3, 2)), 1.0, 1.0)  # type: ignore[arg-type]


def test_matches_toppra_without_jerk() -> None:
    ta = pytest.importorskip("toppra")
    import toppra.algorithm as algo
    from toppra import constraint

    ta.setup_logging("WARNING")
    ss = np.linspace(0.0, 1.0, 7)
    pts = np.column_stack([2.0 * ss, 0.5 * np.sin(2.0 * np.pi * ss)])
    curve = CubicSpline(ss, pts)
    amax = np.array([1.0, 1.5])
    vlim = np.array([[-100.0, 100.0]] * 2)
    alim = np.column_stack([-amax, amax])
    path = ta.SplineInterpolator(ss, pts)
    inst = algo.TOPPRA(
        [constraint.JointVelocityConstraint(vlim), constraint.JointAccelerationConstraint(alim)],
        path,
        gridpoints=np.linspace(0.0, 1.0, 2001),
        parametrizer="ParametrizeConstAccel",
    )
    traj = inst.compute_trajectory(0, 0)
    assert traj is not None
    plan = plan_speed(curve, 100.0, amax, None, n=2001)
    assert plan.duration == pytest.approx(float(traj.duration), rel=1e-3)  # measured ~4e-6


def test_square_spiral_within_two_percent() -> None:
    # The case (paper limits). Before the local refinement: jerk excess
    # 0.82 (n=500), 0.34 (n=1000); now 0.012 at n=1000 (uniform grid).
    plan = plan_speed(square_spiral(1.0), 3.0, 5.0, 3.0, n=1000)
    ver = plan.verify()
    assert ver.max_excess <= 0.02, ver
    assert plan.excess_estimate <= 0.02
    assert plan.grid == "uniform"
    assert 30.0 < plan.duration < 31.0  # 30.69 s; converged value ~30.4-30.5 s
    ctrl = _walk_check(plan, plan.control_period)  # the Taylor walk at the control period
    assert ctrl <= 0.02, ctrl


def test_adaptive_grid_onsquare_spiral() -> None:
    # Opt-in grid: 30.51 s at excess 0.004 (uniform: 30.69 s at 0.012).
    plan = plan_speed(square_spiral(1.0), 3.0, 5.0, 3.0, n=1000, grid="adaptive")
    ver = plan.verify()
    assert ver.max_excess <= 0.02, ver
    assert plan.grid == "adaptive"
    assert 30.0 < plan.duration < 30.9
    # Reported in the caller's parameter: u increasing on [0, 1], v = sqrt(b) |C'(u)|.
    assert plan.u[0] == 0.0 and plan.u[-1] == 1.0 and np.all(np.diff(plan.u) > 0.0)
    speed = np.sqrt(plan.b) * np.linalg.norm(square_spiral(1.0)(plan.u, 1), axis=1)
    assert np.max(speed) <= 3.0 * (1.0 + 1e-6)
    sp = plan.setpoints()
    assert np.allclose(sp.p, square_spiral(1.0)(sp.u), atol=1e-9)


def test_refinement_lowers_excess_locally() -> None:
    curve = square_spiral(1.0)
    base = plan_speed(curve, 3.0, 5.0, 3.0, n=500, grid="uniform", max_excess=None)
    refined = plan_speed(curve, 3.0, 5.0, 3.0, n=500, grid="uniform", max_excess=0.02)
    assert base.refinements == 0 and refined.refinements >= 1
    # The estimate is what verify() measures (up to sampling).
    before, after = base.verify().max_excess, refined.verify().max_excess
    assert base.excess_estimate == pytest.approx(before, abs=0.02)
    assert refined.excess_estimate == pytest.approx(after, abs=0.02)
    assert after < 0.5 * before
    # Local, not global: the duration grows by far less than the excess fell.
    assert refined.duration < 1.05 * base.duration
    assert refined.lp_solves > base.lp_solves


def test_lp_backends_agree() -> None:
    pytest.importorskip("highspy")
    fast = plan_speed(_circle(), 1.0, 2.0, 3.0, n=200, max_excess=None, lp_backend="highspy")
    ref = plan_speed(_circle(), 1.0, 2.0, 3.0, n=200, max_excess=None, lp_backend="linprog")
    assert fast.duration == pytest.approx(ref.duration, rel=1e-6)
    assert np.allclose(fast.b, ref.b, rtol=1e-5, atol=1e-9 * ref.b.max())


def test_uniform_grid_keeps_parameter() -> None:
    plan = plan_speed(_circle(), 1.0, 2.0, 3.0, n=101, grid="uniform")
    assert plan.grid == "uniform"
    assert np.allclose(plan.u, np.linspace(0.0, 1.0, 101))


@pytest.mark.parametrize("n", [50, 99, 104])
def test_last_setpoint_is_the_limit_at_the_end(n: int) -> None:
    # For these n, h * (n - 1) rounds below 1: u = 1 fell off the profile spline
    # and the last row's acceleration and jerk were NaN.
    plan = plan_speed(_circle(), 1.0, 2.0, 3.0, n=n)
    sp = plan.setpoints(plan.control_period / 10.0)
    for x in (sp.t, sp.u, sp.p, sp.v, sp.a, sp.j):
        assert np.all(np.isfinite(x))
    # The end values continue the profile (left limits at u = 1), not zeros.
    assert np.allclose(sp.a[-1], sp.a[-2], atol=0.01 * 2.0)
    assert np.allclose(sp.j[-1], sp.j[-2], atol=0.01 * 3.0)
    assert np.linalg.norm(sp.j[-1]) > 0.5


def _dense_norms(plan: SpeedPlan, amax: float, jmax: float | None) -> tuple[float, float]:
    """Largest ``|a| / amax`` and ``|j| / jmax`` of the chain-rule setpoints at ``T / 10``."""
    sp = plan.setpoints(plan.control_period / 10.0)
    acc = float(np.max(np.linalg.norm(sp.a, axis=1))) / amax
    jerk = 0.0 if jmax is None else float(np.max(np.linalg.norm(sp.j, axis=1))) / jmax
    return acc, jerk


@pytest.mark.parametrize("jmax", [None, 3.0])
def test_norm_limits_on_a_circle(jmax: float | None) -> None:
    amax, sides = 2.0, 16
    plan = plan_speed(_circle(), 10.0, amax, jmax, n=500, norm_sides=sides)
    assert plan.norm_sides == sides
    acc, jerk = _dense_norms(plan, amax, jmax)
    assert acc <= 1.0 + 0.02
    assert jerk <= 1.0 + 0.02
    ver = plan.verify()  # finite differences of the positions, measured as norms
    assert ver.max_excess <= 0.02
    if jmax is None:
        # The acceleration binds, at least at the polygon's inner radius.
        assert acc >= np.cos(np.pi / sides) - 1e-3
    # Per axis the same limits allow up to sqrt(2) times the norm on the diagonals.
    box = plan_speed(_circle(), 10.0, amax, jmax, n=500)
    assert box.norm_sides is None
    box_acc, box_jerk = _dense_norms(box, amax, jmax)
    assert max(box_acc, box_jerk) > 1.3
    assert box.duration < plan.duration


def test_norm_limits_on_a_coverage_spiral() -> None:
    plan = plan_speed(square_spiral(1.0), 3.0, 5.0, 3.0, n=1000, norm_sides=16)
    acc, jerk = _dense_norms(plan, 5.0, 3.0)
    assert acc <= 1.0 + 0.02 and jerk <= 1.0 + 0.02
    assert plan.excess_estimate <= 0.02
    assert plan.verify().max_excess <= 0.02
    assert jerk > 0.95  # the jerk norm binds
    # Per axis (as before): the same 30.69 s plan, whose jerk norm exceeds jmax.
    box = plan_speed(square_spiral(1.0), 3.0, 5.0, 3.0, n=1000)
    assert 30.0 < box.duration < 31.0 < plan.duration
    assert _dense_norms(box, 5.0, 3.0)[1] > 1.2


def test_norm_limits_on_a_3d_path() -> None:
    th = np.linspace(0.0, 1.0, 60)
    helix = make_interp_spline(
        th, np.column_stack([np.cos(2 * np.pi * th), np.sin(2 * np.pi * th), 0.5 * th]), k=5
    )
    plan = plan_speed(helix, 10.0, 2.0, None, n=400, norm_sides=16)
    sp = plan.setpoints(plan.control_period / 10.0)
    assert np.max(np.linalg.norm(sp.a[:, :2], axis=1)) <= 2.0 * 1.02
    assert np.max(np.abs(sp.a[:, 2])) <= 2.0 * 1.02


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"norm_sides": 5}, r"^norm_sides: got 5, expected an even integer"),
        ({"norm_sides": 2}, r"^norm_sides: got 2, expected an integer >= 4"),
        ({"norm_sides": 8, "amax": [1.0, 2.0]}, r"^amax: got .*, expected a number"),
        ({"norm_sides": 8, "jmax": [1.0, 2.0]}, r"^jmax: got .*, expected a number"),
    ],
)
def test_bad_norm_input(kwargs: dict[str, object], match: str) -> None:
    args: dict[str, object] = {"vmax": 1.0, "amax": 1.0, "jmax": None, "n": 50}
    args.update(kwargs)
    with pytest.raises(InputError, match=match):
        plan_speed(_circle(), **args)  # type: ignore[arg-type]


def test_norm_needs_a_planar_or_spatial_path() -> None:
    x = np.linspace(0.0, 1.0, 8)
    line = make_interp_spline(x, x[:, None], k=3)
    with pytest.raises(InputError, match=r"^norm_sides: got 8 for a 1-D path"):
        plan_speed(line, 1.0, 1.0, norm_sides=8)
