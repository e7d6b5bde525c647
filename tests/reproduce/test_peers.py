"""Tests for the minimum-snap peer wrapper ``skyquill.reproduce.peers``."""

from __future__ import annotations

import itertools
import sys

import numpy as np
import pytest
from numpy.polynomial.legendre import leggauss
from numpy.typing import NDArray

from skyquill.reproduce.peers import PeerFit, minsnap_interpolate
from skyquill.trajectory import PiecewisePolynomial

ms = pytest.importorskip("minsnap_trajectories")


def _problem(
    dim: int = 3, n_wp: int = 6, t0: float = 0.0, seed: int = 0
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    rng = np.random.default_rng(seed)
    waypoints = rng.uniform(-2.0, 2.0, size=(n_wp, dim))
    times = t0 + np.concatenate([[0.0], np.cumsum(rng.uniform(0.5, 2.0, size=n_wp - 1))])
    return waypoints, times


@pytest.mark.parametrize("dim", [1, 2, 3])
@pytest.mark.parametrize("t0", [0.0, 1.5, -0.75])
def test_passes_through_waypoints(dim: int, t0: float) -> None:
    waypoints, times = _problem(dim=dim, t0=t0, seed=dim)
    fit = minsnap_interpolate(waypoints, times)
    traj, times = fit.trajectory, times - fit.start_time
    assert traj.degree == 7
    assert traj.coeffs.shape == (len(times) - 1, 8, dim)
    np.testing.assert_array_equal(traj.breaks, times)
    assert traj.duration == pytest.approx(times[-1] - times[0])
    assert fit.solve_time_s >= 0.0
    np.testing.assert_allclose(traj.evaluate(times), waypoints, rtol=0, atol=1e-8)
    # Both one-sided limits at interior waypoints, too.
    eps = 1e-12
    left = traj.evaluate(times[1:-1] - eps)
    np.testing.assert_allclose(left, waypoints[1:-1], rtol=0, atol=1e-8)


def test_agrees_with_peer_evaluation() -> None:
    waypoints, times = _problem(dim=3, n_wp=7, t0=1.5, seed=7)
    fit = minsnap_interpolate(waypoints, times)
    traj, times = fit.trajectory, times - fit.start_time

    # Independent peer solve, on the trajectory's clock, with the same problem settings.
    zero = np.zeros(3)
    refs = [
        ms.Waypoint(time=float(t), position=p, velocity=zero, acceleration=zero, jerk=zero)
        if i in (0, len(times) - 1)
        else ms.Waypoint(time=float(t), position=p)
        for i, (t, p) in enumerate(zip(times, waypoints, strict=True))
    ]
    peer = ms.generate_trajectory(refs, 7, idx_minimized_orders=4, num_continuous_orders=4)

    rng = np.random.default_rng(1)
    t = np.sort(rng.uniform(times[0], times[-1], size=200))
    expected = ms.compute_trajectory_derivatives(peer, t, 5)  # (5, N, d)
    for order in range(5):
        got = traj.evaluate(t, order=order)
        scale = float(np.max(np.abs(expected[order])))
        np.testing.assert_allclose(got, expected[order], rtol=0, atol=1e-8 * scale)


@pytest.mark.parametrize("dim", [1, 3])
def test_rest_at_both_ends(dim: int) -> None:
    waypoints, times = _problem(dim=dim, seed=11)
    fit = minsnap_interpolate(waypoints, times)
    traj, times = fit.trajectory, times - fit.start_time
    ends = times[[0, -1]]
    for order in (1, 2, 3):
        np.testing.assert_allclose(traj.evaluate(ends, order=order), 0.0, rtol=0, atol=1e-8)


def test_snap_integral_matches_quadrature() -> None:
    waypoints, times = _problem(dim=3, n_wp=5, t0=0.4, seed=3)
    fit = minsnap_interpolate(waypoints, times)
    traj, times = fit.trajectory, times - fit.start_time
    exact = traj.squared_derivative_integral(4)

    nodes, weights = leggauss(8)
    total = 0.0
    for a, b in itertools.pairwise(times):
        edges = np.linspace(a, b, 11)
        for lo, hi in itertools.pairwise(edges):
            half = 0.5 * (hi - lo)
            t = 0.5 * (hi + lo) + half * nodes
            snap = traj.evaluate(t, order=4)
            total += half * float(np.sum(weights * np.sum(snap**2, axis=1)))
    assert exact > 0.0
    assert exact == pytest.approx(total, rel=1e-9, abs=0.0)


@pytest.mark.parametrize(("t0", "t1", "x0", "x1"), [(0.0, 1.0, 0.0, 1.0), (0.5, 3.0, -0.3, 2.2)])
def test_two_point_line_is_smoothstep(t0: float, t1: float, x0: float, x1: float) -> None:
    fit = minsnap_interpolate(np.array([[x0], [x1]]), np.array([t0, t1]))
    traj = fit.trajectory
    assert fit.start_time == t0
    T = t1 - t0
    t = np.linspace(0.0, T, 101)
    s = t / T
    closed = x0 + (x1 - x0) * (35 * s**4 - 84 * s**5 + 70 * s**6 - 20 * s**7)
    np.testing.assert_allclose(traj.evaluate(t)[:, 0], closed, rtol=0, atol=1e-9)
    # Coefficients themselves: (x1 - x0) * [0, 0, 0, 0, 35, -84, 70, -20] / T**j.
    ref = (x1 - x0) * np.array([0, 0, 0, 0, 35, -84, 70, -20]) / T ** np.arange(8)
    ref[0] += x0
    np.testing.assert_allclose(traj.coeffs[0, :, 0], ref, rtol=0, atol=1e-9 * max(1.0, abs(x1)))
    # Snap cost of the smoothstep: (x1 - x0)^2 * 100800 / T^7 (s-domain integral 100800).
    exact = (x1 - x0) ** 2 * 100800.0 / T**7
    assert traj.squared_derivative_integral(4) == pytest.approx(exact, rel=1e-9)


def test_evaluate_rejects_out_of_range_and_handles_high_orders() -> None:
    waypoints, times = _problem(dim=2, n_wp=3, t0=1.0, seed=5)
    fit = minsnap_interpolate(waypoints, times)
    traj, times = fit.trajectory, times - fit.start_time
    with pytest.raises(ValueError):
        traj.evaluate(np.array([times[0] - 1e-6]))
    with pytest.raises(ValueError):
        traj.evaluate(np.array([times[-1] + 1e-6]))
    with pytest.raises(ValueError):
        traj.evaluate(times, order=-1)
    np.testing.assert_array_equal(traj.evaluate(times, order=8), 0.0)
    assert traj.evaluate(times, order=7).shape == (3, 2)
    assert traj.squared_derivative_integral(8) == 0.0


@pytest.mark.parametrize(
    ("waypoints", "times", "degree"),
    [
        (np.zeros((1, 3)), np.zeros(1), 7),  # W < 2
        (np.zeros((3, 4)), np.arange(3.0), 7),  # d = 4
        (np.zeros((3, 2)), np.array([0.0, 1.0, 1.0]), 7),  # not strictly increasing
        (np.zeros((3, 2)), np.arange(4.0), 7),  # shape mismatch
        (np.zeros((3, 2)), np.arange(3.0), 5),  # degree too low for min snap
    ],
)
def test_rejects_malformed_input(
    waypoints: NDArray[np.float64], times: NDArray[np.float64], degree: int
) -> None:
    with pytest.raises(ValueError):
        minsnap_interpolate(waypoints, times, degree=degree)


def test_missing_peer_raises_import_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "minsnap_trajectories", None)
    with pytest.raises(ImportError, match="pip install minsnap-trajectories"):
        minsnap_interpolate(np.array([[0.0], [1.0]]), np.array([0.0, 1.0]))


def test_dataclass_is_frozen_and_read_only() -> None:
    traj = PiecewisePolynomial(breaks=np.array([0.0, 1.0]), coeffs=np.ones((1, 8, 1)))
    fit = PeerFit(traj, 0.0, 0.0)
    with pytest.raises(AttributeError):
        fit.solve_time_s = 1.0  # type: ignore[misc]
    with pytest.raises(ValueError):
        traj.coeffs[0, 0, 0] = 2.0
