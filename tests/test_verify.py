"""Tests for skyquill.verify: the dense check on trajectories with known derivatives."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray
from scipy.interpolate import make_lsq_spline

from skyquill.limits import BoxLimit, CylinderLimit, NormLimit
from skyquill.trajectory import PiecewisePolynomial, SplineTrajectory, dense_times
from skyquill.trajectory.base import check_times
from skyquill.verify import Verification, _Peaks, verify

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Region:
    """A minimal corridor region for verify()."""

    A: FloatArray
    b: FloatArray
    t_start: float
    t_end: float


def _time_knots(k: int, M: int, duration: float) -> FloatArray:
    L = M - k
    s = np.concatenate([np.zeros(k + 1), np.arange(1, L, dtype=float), np.full(k + 1, L)])
    return s * duration / L


def _polynomial_trajectory(coeffs: FloatArray, k: int, M: int, duration: float) -> SplineTrajectory:
    """Spline reproducing p(t) = sum_j coeffs[j] t^j exactly (degree <= k), by least squares."""
    t = np.linspace(0.0, duration, 4 * M)
    p = sum(c[None, :] * t[:, None] ** j for j, c in enumerate(coeffs))
    spline = make_lsq_spline(t, p, _time_knots(k, M, duration), k)
    return SplineTrajectory(np.asarray(spline.c), k, duration)


def _line(v: FloatArray, p0: FloatArray, k: int, M: int, duration: float) -> SplineTrajectory:
    """Constant velocity by Greville abscissae (linear precision of B-splines)."""
    knots = _time_knots(k, M, duration)
    greville = np.array([knots[i + 1 : i + k + 1].mean() for i in range(M)])
    return SplineTrajectory(p0[None, :] + greville[:, None] * v[None, :], k, duration)


# ------------------------------------------------------------------ known maxima
def test_constant_velocity_line() -> None:
    v = np.array([3.0, -4.0, 0.0])
    traj = _line(v, np.array([1.0, 2.0, 3.0]), k=3, M=12, duration=2.0)
    # The spline really is the line p0 + v t.
    t = np.linspace(0.0, 2.0, 7)
    np.testing.assert_allclose(traj.evaluate(t), [1.0, 2.0, 3.0] + t[:, None] * v, atol=1e-12)
    res = verify(traj)
    assert isinstance(res, Verification)
    assert res.n_samples >= 10_000
    assert res.max_speed == pytest.approx(5.0, rel=1e-12)
    np.testing.assert_allclose(res.max_velocity, [3.0, 4.0, 0.0], atol=1e-11)
    np.testing.assert_allclose(res.max_acc, 0.0, atol=1e-9)
    np.testing.assert_allclose(res.max_jerk, 0.0, atol=1e-8)
    assert res.max_horizontal_acc == pytest.approx(0.0, abs=1e-9)
    assert res.checks == ()
    assert res.max_excess == 0.0
    assert res.corridor_excess_m == 0.0


def test_speed_limits_exceeded_by_the_line() -> None:
    traj = _line(np.array([3.0, -4.0, 0.0]), np.zeros(3), k=4, M=10, duration=1.0)
    box = BoxLimit.symmetric(1, 3.5, 3)  # |v_y| = 4 exceeds by 0.5 / 3.5
    cyl = CylinderLimit(1, 4.0, z_lower=-1.0, z_upper=1.0)  # |v_xy| = 5 exceeds by 1 / 4
    roomy = BoxLimit.symmetric(1, 6.0, 3)
    res = verify(traj, [box, cyl, roomy], guaranteed=False)
    assert [c.label for c in res.checks] == ["speed box", "speed cylinder (8-gon)", "speed box"]
    assert [c.order for c in res.checks] == [1, 1, 1]
    assert res.checks[0].max_value == pytest.approx(4.0, rel=1e-12)
    assert res.checks[0].relative_excess == pytest.approx(0.5 / 3.5, rel=1e-9)
    assert res.checks[1].max_value == pytest.approx(5.0, rel=1e-12)
    assert res.checks[1].relative_excess == pytest.approx(0.25, rel=1e-9)
    assert res.checks[2].relative_excess == 0.0
    assert not any(c.guaranteed for c in res.checks)
    assert res.max_excess == pytest.approx(0.25, rel=1e-9)


def test_constant_acceleration() -> None:
    """p = a t^2 / 2: speed grows to |a| T, acceleration is a, jerk is 0."""
    a = np.array([1.0, 2.0, -2.0])  # |a| = 3
    T = 2.0
    traj = _polynomial_trajectory(
        np.array([np.zeros(3), np.zeros(3), a / 2]), k=5, M=11, duration=T
    )
    np.testing.assert_allclose(traj.evaluate(np.array([0.3, 1.7]), 2), [a, a], atol=1e-9)
    acc_box = BoxLimit.symmetric(2, 1.5, 3)  # |a_y| = |a_z| = 2 exceed by 1/3
    acc_cyl = CylinderLimit(2, 2.0, z_lower=-3.0, z_upper=3.0)  # sqrt(5) exceeds 2
    res = verify(traj, [acc_box, acc_cyl])
    assert res.max_speed == pytest.approx(3.0 * T, rel=1e-9)
    np.testing.assert_allclose(res.max_velocity, np.abs(a) * T, rtol=1e-9)
    np.testing.assert_allclose(res.max_acc, np.abs(a), rtol=1e-9)
    np.testing.assert_allclose(res.max_jerk, 0.0, atol=1e-7)
    assert res.max_horizontal_acc == pytest.approx(np.sqrt(5.0), rel=1e-9)
    assert res.max_horizontal_jerk == pytest.approx(0.0, abs=1e-7)
    assert res.checks[0].relative_excess == pytest.approx(1.0 / 3.0, rel=1e-8)
    assert res.checks[1].relative_excess == pytest.approx((np.sqrt(5.0) - 2.0) / 2.0, rel=1e-8)
    assert all(c.guaranteed for c in res.checks)
    assert res.max_excess == pytest.approx(1.0 / 3.0, rel=1e-8)


def test_higher_order_limit_matches_own_dense_maximum() -> None:
    rng = np.random.default_rng(3)
    traj = SplineTrajectory(rng.uniform(-1, 1, size=(14, 2)), 5, 3.0)
    snap_bound = 1.0
    res = verify(traj, [BoxLimit.symmetric(4, snap_bound, 2)])
    snap = traj.evaluate(traj.dense_times(), 4)
    peak = float(np.abs(snap).max())
    assert res.checks[0].order == 4
    assert res.checks[0].label == "snap box"
    assert res.checks[0].max_value == pytest.approx(peak, rel=1e-12)
    assert res.checks[0].relative_excess == pytest.approx(max(0.0, peak - snap_bound) / snap_bound)
    assert len(res.max_jerk) == 2
    # Dense sampling never beats the hull bound of the jerk (convex hull property).
    hull = float(np.abs(traj.derivative_control_points(3)).max())
    assert max(res.max_jerk) <= hull * (1 + 1e-12)


# ------------------------------------------------------------------ corridors
def test_corridor_excess_sign() -> None:
    # x = t on [0, 4].
    traj = _line(np.array([1.0, 0.0, 0.0]), np.zeros(3), k=3, M=10, duration=4.0)
    dt = 4.0 / (traj.dense_times().size - 1)
    x_le = np.array([[1.0, 0.0, 0.0]])
    inside = Region(x_le, np.array([10.0]), 0.0, 4.0)
    res = verify(traj, corridors=[inside])
    assert res.corridor_excess_m == pytest.approx(4.0 - 10.0, abs=1e-9)  # negative: inside

    # x <= 2.5 only on [0, 2]: inside by 0.5 (up to one sample step).
    early = Region(x_le, np.array([2.5]), 0.0, 2.0)
    assert verify(traj, corridors=[early]).corridor_excess_m == pytest.approx(-0.5, abs=dt)

    # x <= 2.5 on [0, 3]: out by 0.5.
    late = Region(x_le, np.array([2.5]), 0.0, 3.0)
    res = verify(traj, corridors=[late])
    assert res.corridor_excess_m == pytest.approx(0.5, abs=dt)
    assert res.corridor_excess_m > 0

    # Several corridors: the largest excursion; -x <= -1 on [1.5, 4] (x >= 1) is inside.
    floor = Region(-x_le, np.array([-1.0]), 1.5, 4.0)
    res = verify(traj, corridors=[early, floor])
    assert res.corridor_excess_m == pytest.approx(-0.5, abs=dt)
    assert verify(traj, corridors=[floor]).corridor_excess_m == pytest.approx(-0.5, abs=dt)
    assert verify(traj, corridors=[early, late, floor]).corridor_excess_m == pytest.approx(
        0.5, abs=dt
    )
    # Corridors do not contribute to the limit excess.
    assert res.max_excess == 0.0


def test_as_dict_is_plain() -> None:
    traj = _line(np.array([1.0, 1.0]), np.zeros(2), k=2, M=6, duration=1.0)
    d = verify(traj, [BoxLimit.symmetric(1, 2.0, 2)]).as_dict()
    assert d["max_speed"] == pytest.approx(np.sqrt(2.0))
    assert d["checks"][0]["label"] == "speed box"
    assert set(d) >= {"n_samples", "max_speed", "checks", "corridor_excess_m", "max_excess"}


@settings(max_examples=40, deadline=None)
@given(
    pieces=st.integers(1, 30),
    n_coef=st.integers(1, 6),
    seed=st.integers(0, 2**32 - 1),
)
def test_piecewise_polynomial_checked_per_piece_where_constant_is_checked_at_every_sample(
    pieces: int, n_coef: int, seed: int
) -> None:
    # Orders at and above the degree are evaluated once per piece: the report must be the
    # one of evaluating every order at every dense sample, bit for bit.
    rng = np.random.default_rng(seed)
    breaks = np.concatenate([[0.0], np.cumsum(rng.uniform(0.01, 3.0, pieces))])
    traj = PiecewisePolynomial(breaks, rng.normal(size=(pieces, n_coef, 3)))
    limits = [
        NormLimit(1, 1.5),
        CylinderLimit(2, 1.0, z_lower=-0.5, z_upper=0.7),
        BoxLimit(3, -np.ones(3), np.ones(3)),
        NormLimit(4, 2.0),
    ]
    t = check_times(traj)  # the dense times and each inner breakpoint from the left
    every = _Peaks(limits, (), 3)
    every.add(t, {n: traj.evaluate(t, n) for n in (1, 2, 3, 4)})
    assert verify(traj, limits, guaranteed=False) == every.result(t.size, False)


def test_the_jerk_peak_at_a_curve_knot_is_checked() -> None:
    # A quartic path through a bent polyline, flown rest to rest: its jerk has kinks where
    # the path crosses the curve's knots, peaks the evenly spaced samples step over.
    from scipy.interpolate import make_interp_spline

    from skyquill.trajectory import RetimedPath, concatenate

    u = np.linspace(0.0, 1.0, 9)
    pts = np.column_stack([u, 0.3 * np.abs(np.sin(7.0 * u))])
    curve = make_interp_spline(u, pts, k=4)
    t = np.linspace(0.0, 3.0, 7)  # few timing pieces: 20 samples each, far apart
    x = t / 3.0
    law = (10 * x**3 - 15 * x**4 + 6 * x**5, (30 * x**2 - 60 * x**3 + 30 * x**4) / 3.0,
           (60 * x - 180 * x**2 + 120 * x**3) / 9.0)  # fmt: skip
    traj = RetimedPath.from_samples(curve, t, *law)
    kinks = traj.kink_times()
    knots = np.unique(curve.t)[1:-1]
    np.testing.assert_allclose(traj.timing.evaluate(kinks)[:, 0], knots, atol=1e-12)
    jerk_at = np.linalg.norm(traj.evaluate(kinks, 3), axis=1)
    sampled = np.linalg.norm(traj.evaluate(dense_times(traj.breakpoints), 3), axis=1).max()
    res = verify(traj, [NormLimit(3, 1e-6)])
    assert res.checks[0].max_value == pytest.approx(max(sampled, jerk_at.max()), rel=1e-12)
    assert jerk_at.max() > sampled  # the case the kinks are sampled for
    # In a sequence, on its clock.
    start = traj.evaluate(np.array([0.0]))[0]
    seq = concatenate([_hold(start), traj])
    np.testing.assert_allclose(seq.kink_times(), 1.0 + kinks)
    assert verify(seq, [NormLimit(3, 1e-6)]).checks[0].max_value >= jerk_at.max()


def _hold(at: FloatArray) -> PiecewisePolynomial:
    """A one-second hold at ``at`` (2-D)."""
    return PiecewisePolynomial(np.array([0.0, 1.0]), np.zeros((1, 1, 2)) + at)


def test_a_jump_at_a_breakpoint_is_checked_from_both_sides() -> None:
    # Jerk 10 t on the first piece, 0 on the second: its largest value, 10, is the first
    # piece's end, which the breakpoint's own sample (the second piece's start) never shows.
    first = np.array([[0.0], [0.0], [0.0], [0.0], [10.0 / 24.0]])  # p = 10 t^4 / 24
    v, a = 10.0 / 6.0, 10.0 / 2.0  # at t = 1: p' = 10 t^3 / 6, p'' = 10 t^2 / 2
    second = np.array([[10.0 / 24.0], [v], [a / 2.0], [0.0], [0.0]])
    traj = PiecewisePolynomial(np.array([0.0, 1.0, 2.0]), np.stack([first, second]))
    res = verify(traj, [NormLimit(3, 5.0)])
    assert res.checks[0].max_value == pytest.approx(10.0, rel=1e-9)
    assert max(res.max_jerk) == pytest.approx(10.0, rel=1e-9)


# ------------------------------------------------------------------ sequences and the memo
def _legs() -> tuple[PiecewisePolynomial, PiecewisePolynomial]:
    """Two stop-and-go flights meeting at rest."""
    from skyquill.optimize.legs import LegLimits, stop_and_go

    lim = LegLimits(2.0, 3.0, 10.0)
    first = stop_and_go(np.array([[0.0, 0.0, 1.0], [4.0, 1.0, 1.0], [4.0, 6.0, 1.0]]), lim)
    second = stop_and_go(np.array([[4.0, 6.0, 1.0], [0.0, 9.0, 2.0]]), lim)
    return first.trajectory, second.trajectory


LEG_LIMITS = (
    CylinderLimit(1, 1.9, z_lower=-1.9, z_upper=1.9),
    CylinderLimit(2, 3.0, z_lower=-3.0, z_upper=3.0),
    BoxLimit.symmetric(3, 9.0, 3),
)


def test_a_sequence_is_checked_piece_by_piece() -> None:
    from skyquill.trajectory import RestToRestSequence
    from skyquill.verify import _checked

    a, b = _legs()
    whole = verify(RestToRestSequence((a, b)), LEG_LIMITS, guaranteed=False)
    parts = [verify(p, LEG_LIMITS, guaranteed=False) for p in (a, b)]
    assert whole.n_samples == sum(p.n_samples for p in parts)
    assert whole.max_excess == max(p.max_excess for p in parts) > 0.0  # speed and jerk over
    for i, check in enumerate(whole.checks):
        assert check.max_value == max(p.checks[i].max_value for p in parts)
    # The sequence sampled as one: the same peaks (its samples are other times of the same
    # functions; these legs peak on plateaus that both sample).
    direct = _checked(RestToRestSequence((a, b)), LEG_LIMITS, (), False)
    assert whole.max_excess == pytest.approx(direct.max_excess, rel=1e-9)
    assert whole.max_acc == pytest.approx(direct.max_acc, rel=1e-9)
    assert whole.max_jerk == pytest.approx(direct.max_jerk, rel=1e-9)


def test_a_trajectory_checked_before_is_not_checked_again(monkeypatch: pytest.MonkeyPatch) -> None:
    import pickle

    import skyquill.verify as verify_module

    a, _ = _legs()
    first = verify(a, LEG_LIMITS)
    # The check travels with the trajectory (a coverage piece checked in a worker process).
    back = pickle.loads(pickle.dumps(a))

    def not_again(*args: object) -> Verification:
        raise AssertionError("checked again")

    monkeypatch.setattr(verify_module, "_checked", not_again)
    assert verify(a, LEG_LIMITS) is first
    assert verify(back, LEG_LIMITS) == first
    # Other limits are another check.
    with pytest.raises(AssertionError, match="checked again"):
        verify(a, LEG_LIMITS[:2])
