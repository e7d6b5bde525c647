"""The speed plan as a trajectory: the chain rule of the LP's own profile, at every time."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import make_interp_spline

from skyquill.coverage.speed import plan_speed
from skyquill.trajectory import RetimedPath, dense_times


def _circle(radius: float = 1.0):  # type: ignore[no-untyped-def]
    u = np.linspace(0.0, 1.0, 41)
    angle = 2 * np.pi * u
    return make_interp_spline(u, radius * np.c_[np.cos(angle), np.sin(angle)], k=5)


@pytest.mark.parametrize(("jmax", "grid"), [(None, "uniform"), (3.0, "uniform"), (3.0, "adaptive")])
def test_trajectory_is_the_profiles_chain_rule(jmax: float | None, grid: str) -> None:
    plan = plan_speed(_circle(), 1.0, 2.0, jmax, n=300, grid=grid)  # type: ignore[arg-type]
    traj = plan.trajectory(z=2.0)
    assert isinstance(traj, RetimedPath) and traj.dim == 3
    # Same duration as the LP's own time model (to the walk's quadrature).
    assert traj.duration == pytest.approx(plan.duration, rel=2e-3)
    t = dense_times(traj.breakpoints)
    for order in range(4):
        assert np.all(np.isfinite(traj.evaluate(t, order)))
    np.testing.assert_allclose(traj.evaluate(t)[:, 2], 2.0)
    ends = np.array([0.0, traj.duration])
    np.testing.assert_allclose(traj.evaluate(ends, 1), 0.0, atol=1e-9)
    # The plan's check is the one dense check of this trajectory, within the LP's 2 %.
    check = plan.verify(z=2.0)
    assert check.max_excess <= 0.02 and not check.checks[0].guaranteed


def test_exact_law_without_jerk_limit_matches_the_grid_model() -> None:
    plan = plan_speed(_circle(), 1.0, 2.0, None, n=200)
    traj = plan.trajectory()
    # b is linear per interval: u(t) is exactly quadratic there, so the duration is exact.
    assert traj.duration == pytest.approx(plan.duration, rel=1e-12)
    u = traj.timing.evaluate(traj.breakpoints)[:, 0]
    np.testing.assert_allclose(u, plan._sigma, atol=1e-12)


def test_quintic_law_is_scipys_hermite_interpolant() -> None:
    # The closed form replaces BPoly.from_derivatives (a Python loop per piece).
    from skyquill.coverage.speed.retime import quintic_law
    from skyquill.trajectory.retimed import RetimedPath as Reference

    rng = np.random.default_rng(7)
    t = np.concatenate([[0.0], np.cumsum(rng.uniform(0.005, 0.05, 200))])
    u = np.cumsum(rng.uniform(0.0, 1.0, t.size))
    u = (u - u[0]) / (u[-1] - u[0])
    ud, udd = rng.uniform(0.0, 2.0, t.size), rng.normal(0.0, 5.0, t.size)
    law = quintic_law(t, u, ud, udd)
    reference = Reference.from_samples(_circle(), t, u, ud, udd).timing
    probe = np.sort(rng.uniform(0.0, t[-1], 2000))
    for order in range(4):
        np.testing.assert_allclose(
            law.evaluate(probe, order), reference.evaluate(probe, order), rtol=1e-8, atol=1e-8
        )
