"""Tests for skyquill.trajectory.SplineTrajectory: evaluation, sampling, conversions."""

from __future__ import annotations

import math

import numpy as np
import numpy.polynomial.polynomial as npp
import pytest
from numpy.typing import NDArray
from scipy.interpolate import BSpline

from skyquill.errors import InputError
from skyquill.spline import ClampedUniformBasis
from skyquill.trajectory import (
    DENSE_MIN_TOTAL,
    DENSE_PER_SPAN,
    Samples,
    SplineTrajectory,
    Trajectory,
)

FloatArray = NDArray[np.float64]

DEGREES = list(range(1, 8))


def _traj(k: int, M: int, duration: float, d: int = 3, seed: int = 0) -> SplineTrajectory:
    C = np.random.default_rng(seed).uniform(-2.0, 2.0, size=(M, d))
    return SplineTrajectory(C, k, duration)


def _time_knots(k: int, M: int, duration: float) -> FloatArray:
    """Eq. (4) knots mapped to time by s = alpha t (eq. 5)."""
    L = M - k
    s = np.concatenate([np.zeros(k + 1), np.arange(1, L, dtype=float), np.full(k + 1, L)])
    return s * duration / L


# ------------------------------------------------------------------ basic properties
@pytest.mark.parametrize(("k", "M", "duration"), [(1, 2, 1.0), (3, 10, 4.5), (5, 12, 0.3)])
def test_duration_alpha_and_knot_times(k: int, M: int, duration: float) -> None:
    traj = _traj(k, M, duration)
    assert isinstance(traj, Trajectory)
    assert traj.duration == duration
    assert traj.dim == 3
    L = M - k
    assert traj.alpha == pytest.approx(L / duration, rel=1e-15)  # eq. (5): T_end = (M-k)/alpha
    np.testing.assert_allclose(traj.knot_times, np.linspace(0.0, duration, L + 1), rtol=1e-14)
    assert traj.knot_times[-1] == pytest.approx(duration, rel=1e-15)


def test_control_points_are_copied_read_only() -> None:
    C = np.zeros((6, 2))
    traj = SplineTrajectory(C, 3, 1.0)
    assert traj.control_points.dtype == np.float64
    with pytest.raises(ValueError, match="read-only"):
        traj.control_points[0, 0] = 1.0
    # Lists are accepted and converted.
    assert SplineTrajectory([[0.0, 0.0], [1.0, 1.0]], 1, 2.0).control_points.shape == (2, 2)


@pytest.mark.parametrize("k", DEGREES)
def test_evaluate_matches_direct_basis(k: int) -> None:
    M, duration = k + 6, 3.7
    traj = _traj(k, M, duration, seed=k)
    basis = ClampedUniformBasis(k, M)
    t = np.concatenate(
        [[0.0, duration], np.random.default_rng(k).uniform(0, duration, 200), traj.knot_times]
    )
    for n in range(k + 1):
        got = traj.evaluate(t, n)
        want = traj.alpha**n * (basis.design_matrix(traj.alpha * t, n) @ traj.control_points)
        scale = max(1.0, float(np.abs(want).max()))
        assert got.shape == (t.size, 3)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-11 * scale, err_msg=f"order {n}")
    # Orders above the degree are identically zero.
    np.testing.assert_array_equal(traj.evaluate(t, k + 1), np.zeros((t.size, 3)))


def test_evaluate_end_points_are_first_and_last_control_points() -> None:
    traj = _traj(4, 11, 2.0)
    ends = traj.evaluate(np.array([0.0, 2.0]))
    np.testing.assert_allclose(ends[0], traj.control_points[0], atol=1e-14)
    np.testing.assert_allclose(ends[1], traj.control_points[-1], atol=1e-14)


def test_time_scaling_changes_derivatives_by_alpha_power() -> None:
    """Same control points, twice the duration: the n-th derivative scales by 2^-n."""
    a = _traj(5, 12, 1.5, seed=3)
    b = SplineTrajectory(a.control_points, 5, 3.0)
    u = np.linspace(0.0, 1.0, 41)
    for n in range(6):
        np.testing.assert_allclose(
            b.evaluate(3.0 * u, n) * 2.0**n,
            a.evaluate(1.5 * u, n),
            atol=1e-10 * max(1.0, float(np.abs(a.evaluate(1.5 * u, n)).max())),
        )


def test_evaluate_tolerates_round_off_at_the_ends() -> None:
    traj = _traj(3, 8, 2.0)
    got = traj.evaluate(np.array([-1e-12, 2.0 + 1e-12]))
    np.testing.assert_allclose(got, traj.evaluate(np.array([0.0, 2.0])), atol=1e-12)


# ------------------------------------------------------------------ sampling
@pytest.mark.parametrize(("duration", "rate"), [(2.0, 10.0), (1.05, 10.0), (3.0, 7.0), (0.5, 1.0)])
def test_sample_includes_both_ends_at_rate(duration: float, rate: float) -> None:
    traj = _traj(3, 9, duration, d=2)
    smp = traj.sample(rate)
    assert isinstance(smp, Samples)
    t = smp.t
    assert t.ndim == 1
    assert t[0] == 0.0
    assert t[-1] == pytest.approx(duration, abs=1e-12)
    assert t[-1] <= duration
    steps = np.diff(t)
    assert np.all(steps > 0)
    # Regular steps of 1/rate, except possibly a shorter last one to reach the end.
    np.testing.assert_allclose(steps[:-1], 1.0 / rate, rtol=1e-9)
    assert steps[-1] <= 1.0 / rate + 1e-12
    assert t.size == math.floor(duration * rate + 1e-9) + 1 + (
        0 if abs(duration * rate - round(duration * rate)) < 1e-9 else 1
    )
    for arr, n in ((smp.p, 0), (smp.v, 1), (smp.a, 2), (smp.j, 3)):
        assert arr.shape == (t.size, 2)
        np.testing.assert_allclose(arr, traj.evaluate(t, n), atol=1e-12)


def test_sample_of_linear_spline_has_zero_acceleration_and_jerk() -> None:
    smp = _traj(1, 5, 2.0).sample(50.0)
    np.testing.assert_array_equal(smp.a, 0.0)
    np.testing.assert_array_equal(smp.j, 0.0)


@pytest.mark.parametrize("rate", [0.0, -5.0])
def test_sample_rejects_bad_rate(rate: float) -> None:
    with pytest.raises(InputError, match=r"rate: got .*, expected a number > 0"):
        _traj(3, 8, 1.0).sample(rate)


@pytest.mark.parametrize(
    ("k", "M", "duration"), [(3, 4, 1.0), (3, 103, 10.0), (5, 1005, 50.0), (3, 2003, 7.3)]
)
def test_dense_times(k: int, M: int, duration: float) -> None:
    traj = _traj(k, M, duration, d=1)
    t = traj.dense_times()
    L = M - k
    assert t.size >= DENSE_MIN_TOTAL == 10_000
    assert t.size >= DENSE_PER_SPAN * L
    assert t[0] == 0.0
    assert t[-1] == duration
    assert np.all(np.diff(t) > 0)
    # Spacing at most a twentieth of a span, so every (closed) span holds >= 20 samples.
    span = duration / L
    assert float(np.diff(t).max()) <= span / 20 * (1 + 1e-9)
    eps = 1e-9 * span
    kt = traj.knot_times
    counts = [int(np.count_nonzero((t >= kt[i] - eps) & (t <= kt[i + 1] + eps))) for i in range(L)]
    assert min(counts) >= 20


# ------------------------------------------------------------------ piecewise polynomial
@pytest.mark.parametrize("k", DEGREES)
@pytest.mark.parametrize("M_extra", [0, 4])
def test_to_piecewise_polynomial_reproduces_evaluate(k: int, M_extra: int) -> None:
    M, duration = k + 1 + M_extra, 2.5
    traj = _traj(k, M, duration, seed=10 * k + M_extra)
    breaks, coeffs = traj.to_piecewise_polynomial()
    L = M - k
    assert breaks.shape == (L + 1,)
    assert coeffs.shape == (L, k + 1, 3)
    np.testing.assert_allclose(breaks, np.linspace(0, duration, L + 1), rtol=1e-14)
    rng = np.random.default_rng(k)
    t = np.concatenate([rng.uniform(0.0, duration, 300), [0.0, duration], breaks[1:-1] + 1e-9])
    span = np.clip(np.searchsorted(breaks, t, side="right") - 1, 0, L - 1)
    tau = t - breaks[span]
    for n in range(k + 1):
        want = traj.evaluate(t, n)
        # numpy.polynomial on the lowest-first coefficients, one sample per column.
        der = npp.polyder(coeffs, n, axis=1)[span]  # (N, k + 1 - n, d)
        got = np.stack([npp.polyval(tau, der[:, :, a].T, tensor=False) for a in range(3)], axis=1)
        scale = max(1.0, float(np.abs(want).max()))
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-10 * scale, err_msg=f"order {n}")


def test_piecewise_polynomial_is_continuous_across_breaks() -> None:
    k = 5
    traj = _traj(k, 12, 3.0, seed=1)
    breaks, coeffs = traj.to_piecewise_polynomial()
    h = np.diff(breaks)
    # C^(k-1): derivatives up to k-1 match at interior breaks.
    for i in range(len(h) - 1):
        for n in range(k):
            left = npp.polyval(h[i], npp.polyder(coeffs[i], n, axis=0))
            right = npp.polyval(0.0, npp.polyder(coeffs[i + 1], n, axis=0))
            np.testing.assert_allclose(left, right, atol=1e-9 * max(1.0, float(np.abs(left).max())))


# ------------------------------------------------------------------ derivative control points
@pytest.mark.parametrize("k", DEGREES)
def test_derivative_control_points(k: int) -> None:
    M, duration = k + 5, 1.7
    traj = _traj(k, M, duration, seed=k)
    alpha = traj.alpha
    knots = _time_knots(k, M, duration)
    # Independent eq. (34) recursion on time knots:
    # c'_i = p (c_{i+1} - c_i) / (t_{i+p+1} - t_{i+1}).
    ctrl = traj.control_points.copy()
    t_knots = knots
    rng = np.random.default_rng(0)
    t = np.concatenate([[0.0, duration], rng.uniform(0.0, duration, 100)])
    for n in range(k + 1):
        got = traj.derivative_control_points(n)
        assert got.shape == (M - n, 3)
        want_map = alpha**n * (ClampedUniformBasis(k, M).derivative_map(n) @ traj.control_points)
        np.testing.assert_allclose(got, want_map, atol=1e-12 * max(1.0, float(np.abs(got).max())))
        np.testing.assert_allclose(got, ctrl, atol=1e-10 * max(1.0, float(np.abs(got).max())))
        # They are the control points of the n-th time derivative (eqs. 33, 35).
        reduced = BSpline(knots[n : len(knots) - n], got, k - n)
        if k - n > 0:
            want = traj.evaluate(t, n)
            np.testing.assert_allclose(
                reduced(t), want, atol=1e-10 * max(1.0, float(np.abs(want).max()))
            )
        if n < k:
            p = k - n
            denom = t_knots[p + 1 : p + ctrl.shape[0]] - t_knots[1 : ctrl.shape[0]]
            ctrl = p * np.diff(ctrl, axis=0) / denom[:, None]
            t_knots = t_knots[1:-1]
    # Boundary values (eq. 41): first / last derivative control points are the end derivatives.
    for n in range(k):
        dcp = traj.derivative_control_points(n)
        ends = traj.evaluate(np.array([0.0, duration]), n)
        scale = max(1.0, float(np.abs(dcp).max()))
        np.testing.assert_allclose(ends, dcp[[0, -1]], atol=1e-10 * scale)


# ------------------------------------------------------------------ input errors
@pytest.mark.parametrize("t", [[-0.1], [0.0, 2.5], [1.0, 2.0 + 1e-6]])
def test_evaluate_rejects_times_outside_duration(t: list[float]) -> None:
    traj = _traj(3, 8, 2.0)
    with pytest.raises(InputError, match=r"t: got times in \[.*\] s, expected within \[0, 2\] s"):
        traj.evaluate(np.array(t))


def test_evaluate_rejects_nan_time_and_bad_order() -> None:
    traj = _traj(3, 8, 2.0)
    with pytest.raises(InputError, match=r"t: got 1 NaN or infinite value\(s\)"):
        traj.evaluate(np.array([0.5, np.nan]))
    with pytest.raises(InputError, match=r"t: got an array of shape \(2, 1\), expected 1 dim"):
        traj.evaluate(np.zeros((2, 1)))
    with pytest.raises(InputError, match=r"order: got -1, expected an integer >= 0"):
        traj.evaluate(np.array([0.5]), -1)


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_rejects_non_finite_control_points(bad: float) -> None:
    C = np.zeros((6, 3))
    C[2, 1] = bad
    with pytest.raises(
        InputError,
        match=r"control_points: got 1 NaN or infinite value\(s\), "
        r"expected finite numbers",
    ):
        SplineTrajectory(C, 3, 1.0)


def test_rejects_control_points_of_wrong_rank() -> None:
    with pytest.raises(
        InputError,
        match=r"control_points: got an array of shape \(6,\), "
        r"expected 2 dimension\(s\)",
    ):
        SplineTrajectory(np.zeros(6), 3, 1.0)


@pytest.mark.parametrize("degree", [0, 8, -2])
def test_rejects_bad_degree(degree: int) -> None:
    with pytest.raises(InputError, match=rf"degree: got {degree}, expected an integer from 1 to 7"):
        SplineTrajectory(np.zeros((10, 2)), degree, 1.0)


def test_rejects_non_integer_degree() -> None:
    with pytest.raises(InputError, match=r"degree: got 3\.5, expected an integer"):
        SplineTrajectory(np.zeros((10, 2)), 3.5, 1.0)  # type: ignore[arg-type]


def test_rejects_too_few_control_points() -> None:
    with pytest.raises(InputError, match=r"n_ctrl: got 3, expected an integer .*degree \+ 1 = 4"):
        SplineTrajectory(np.zeros((3, 2)), 3, 1.0)


@pytest.mark.parametrize(
    ("duration", "pattern"),
    [
        (0.0, r"duration: got 0, expected a number > 0"),
        (-1.0, r"duration: got -1, expected a number > 0"),
        (np.inf, r"duration: got inf, expected a finite number"),
    ],
)
def test_rejects_bad_duration(duration: float, pattern: str) -> None:
    with pytest.raises(InputError, match=pattern):
        SplineTrajectory(np.zeros((6, 2)), 3, duration)
