"""The analytic time gradient (envelope theorem) against central finite differences.

Checked on random small problems of every kind the gradient handles: point
deviations (several smoothness orders), interpolated points, non-zero
boundary derivatives, deviations at fixed times, and the QP route with active
speed / acceleration / jerk limits. On the QP route the reference differences
the *polished* cost (the exact minimiser on the active set); the backends'
own cost is optimal to ~1e-8 relative only, so its quotient is held to 1e-4.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from resegment_cases import (
    SETTINGS,
    Spec,
    close,
    limited_random,
    limited_spiral,
    random_problem,
    specs,
    spiral,
)

from skyquill.errors import InfeasibleError
from skyquill.optimize import Boundary, PointDeviation, SmoothingProblem, solve
from skyquill.optimize.resegment import (
    finite_difference_gradient,
    point_fit_factory,
    time_gradient,
)


@SETTINGS
@given(spec=specs)
def test_gradient_matches_central_differences(spec: Spec) -> None:
    times, make = random_problem(spec)
    grad = time_gradient(times, make)
    reference = finite_difference_gradient(times, make, step=1e-5)
    close(grad.grad_segments, reference)
    assert grad.stationarity_residual < 1e-8
    # df/dT_i is the sum of df/dt_j over the later points.
    assert np.allclose(grad.grad_segments, np.cumsum(grad.grad_times[::-1])[::-1][1:])


@SETTINGS
@given(spec=specs)
def test_fixed_mode_perturbation_is_the_scaled_projection(spec: Spec) -> None:
    # Paper eq. (56), total time fixed: g_i = 1 at i, -1/(N-2) elsewhere (N-1 segments).
    times, make = random_problem(spec)
    g = time_gradient(times, make).grad_segments
    n = g.size
    reference = finite_difference_gradient(times, make, step=1e-5, mode="fixed")
    close(n / (n - 1) * (g - g.mean()), reference)


@pytest.mark.parametrize("coupled", [None, 8])
def test_qp_gradient_matches_central_differences(coupled: int | None) -> None:
    _, times, make = limited_spiral(24, 18, coupled)
    grad = time_gradient(times, make)
    assert grad.result.method == "qp"
    assert grad.n_active > 0
    assert grad.stationarity_residual < 1e-8
    exact = finite_difference_gradient(times, make, step=1e-5, polished=True)
    close(grad.grad_segments, exact, rtol=1e-6)
    close(grad.grad_segments, finite_difference_gradient(times, make, step=1e-5), rtol=1e-4)


@settings(max_examples=20, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2**16), dim=st.integers(2, 3), fraction=st.floats(0.5, 0.9))
def test_qp_gradient_random(seed: int, dim: int, fraction: float) -> None:
    times, make = limited_random(seed, dim, fraction)
    try:
        grad = time_gradient(times, make)
    except InfeasibleError:
        assume(False)
        return
    assert grad.n_active > 0
    assert grad.stationarity_residual < 1e-8
    assert grad.polished_cost <= grad.cost * (1.0 + 1e-12)
    exact = finite_difference_gradient(times, make, step=1e-5, polished=True)
    close(grad.grad_segments, exact, rtol=1e-6)
    # The backend's cost is optimal to ~1e-8 relative only: its quotient agrees to ~1e-5.
    close(grad.grad_segments, finite_difference_gradient(times, make, step=1e-5), rtol=1e-4)


def test_scaling_identity_and_cost_falls_with_time() -> None:
    # Uniform scaling keeps s_i, so only alpha moves: T . grad f = -5 E_jerk (envelope).
    pts, times = spiral(20)
    make = point_fit_factory(pts, 16)
    grad = time_gradient(times, make)
    energy = grad.result.cost_terms["smoothness"]
    scaling = float(np.diff(times) @ grad.grad_segments)
    assert scaling == pytest.approx(-5.0 * energy, rel=1e-8)
    costs = [solve(make(kappa * times)).cost for kappa in (1.0, 1.5, 2.0, 4.0, 8.0)]
    assert np.all(np.diff(costs) < 0.0)


def test_terms_on_subsets_of_the_times_move_with_them() -> None:
    """A writing mission weights stroke samples and transits differently: two point terms
    on disjoint subsets of the times. The analytic gradient must still match finite
    differences (each subset's points move with their times)."""

    rng = np.random.default_rng(5)
    n = 14
    t0 = np.cumsum(np.r_[0.0, rng.uniform(0.2, 0.5, n - 1)])
    pts = np.cumsum(rng.normal(0.0, 0.1, (n, 2)), axis=0)
    heavy = np.arange(n) % 3 != 0

    def make(times: np.ndarray) -> SmoothingProblem:
        return SmoothingProblem(
            2,
            5,
            16,
            float(times[-1]),
            deviations=(
                PointDeviation(times[heavy], pts[heavy], 1e3),
                PointDeviation(times[~heavy], pts[~heavy], 10.0),
            ),
            boundary=Boundary.rest(pts[0], pts[-1], 3),
        )

    analytic = time_gradient(t0, make).grad_segments
    numeric = finite_difference_gradient(t0, make, step=1e-6, scheme="central")
    assert np.allclose(analytic, numeric, rtol=1e-5, atol=1e-6 * np.abs(numeric).max())


@pytest.mark.parametrize("gain", [(-0.03, -0.03, 0.0), (-0.05, 0.02, -0.01), (0.04, 0.04, 0.04)])
def test_accel_gain_gradient_matches_central_differences(gain: tuple[float, ...]) -> None:
    """A brush tip's deviation ``p + c a`` (gains per axis, some axes sharing one): the
    gradient gains the third-derivative rows and the explicit ``alpha`` term of ``c a``."""
    rng = np.random.default_rng(11)
    n = 12
    t0 = np.cumsum(np.r_[0.0, rng.uniform(0.2, 0.5, n - 1)])
    pts = np.cumsum(rng.normal(0.0, 0.1, (n, 3)), axis=0)

    def make(times: np.ndarray) -> SmoothingProblem:
        return SmoothingProblem(
            3,
            5,
            16,
            float(times[-1]),
            deviations=(PointDeviation(times, pts, 1e3, accel_gain=np.array(gain)),),
            boundary=Boundary.rest(pts[0], pts[-1], 3),
        )

    grad = time_gradient(t0, make)
    close(grad.grad_segments, finite_difference_gradient(t0, make, step=1e-5))
