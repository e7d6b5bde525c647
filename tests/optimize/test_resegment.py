"""Time re-segmentation (paper 000 §5.4): analytic gradient, projection, descent.

The analytic gradient (envelope theorem) is checked against central finite
differences of the engine's optimal cost on random small problems of every
kind the gradient handles: point deviations (several smoothness orders),
interpolated points, non-zero boundary derivatives, deviations at fixed
times, and the QP route with active speed / acceleration / jerk limits. On
the QP route the reference differences the *polished* cost (the exact
minimiser on the active set); the backends' own cost is optimal to ~1e-8
relative only, so its quotient is held to 1e-4.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray

from skyquill.errors import InfeasibleError, InputError
from skyquill.io.points import read_points_csv
from skyquill.limits import BoxLimit, vehicle_limits
from skyquill.optimize import (
    Boundary,
    Interpolation,
    PointDeviation,
    SmoothingProblem,
    solve,
)
from skyquill.optimize.resegment import (
    finite_difference_gradient,
    point_fit_factory,
    resegment,
    time_gradient,
)

Array = NDArray[np.float64]
Factory = Callable[[Array], SmoothingProblem]

SPIRAL = Path(__file__).resolve().parents[2] / "examples" / "spiral.csv"
SETTINGS = settings(
    max_examples=50,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
    derandomize=True,
)


def _close(analytic: Array, reference: Array, rtol: float = 1e-5) -> None:
    err = float(np.linalg.norm(analytic - reference))
    assert err <= rtol * float(np.linalg.norm(reference)) + 1e-9, (err, analytic, reference)


# ------------------------------------------------------------------ factories
@dataclass(frozen=True)
class Spec:
    """Structure of a random problem; the numbers come from ``seed``."""

    kind: str
    dim: int
    degree: int
    n_points: int
    extra_ctrl: int
    seed: int


specs = st.builds(
    Spec,
    kind=st.sampled_from(["points", "orders", "interpolation", "moving_ends", "fixed_times"]),
    dim=st.integers(1, 3),
    degree=st.integers(3, 5),
    n_points=st.integers(4, 8),
    extra_ctrl=st.integers(2, 6),
    seed=st.integers(0, 2**16),
)


def random_problem(spec: Spec) -> tuple[Array, Factory]:
    """Initial times and ``make_problem`` of one random problem of ``spec.kind``."""
    rng = np.random.default_rng(spec.seed)
    n, d, k = spec.n_points, spec.dim, spec.degree
    times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.3, 1.5, n - 1))])
    pts = np.cumsum(rng.normal(0.0, 1.0, (n, d)), axis=0)
    weight = float(10.0 ** rng.uniform(0.0, 3.0))
    n_ctrl = max(n + k + 1, k + 1 + spec.extra_ctrl)
    smoothness = {3: 1.0} if spec.kind != "orders" else {2: 0.3, k: 0.05}
    boundary: tuple[Boundary, ...] = Boundary.rest(pts[0], pts[-1], min(3, k))
    if spec.kind == "moving_ends":
        boundary = (
            Boundary(0, pts[0], pts[-1]),
            Boundary(1, rng.normal(0.0, 1.0, d), rng.normal(0.0, 1.0, d)),
            Boundary(2, None, rng.normal(0.0, 1.0, d)),
        )
    fixed_t = np.array([0.2, 0.9]) * times[-1]  # stays inside [0, duration] under tiny steps
    fixed_p = rng.normal(0.0, 1.0, (2, d))

    def make(t: Array) -> SmoothingProblem:
        deviations = [PointDeviation(t, pts, weight)]
        if spec.kind == "fixed_times":
            deviations.append(PointDeviation(fixed_t, fixed_p, 0.5 * weight))
        return SmoothingProblem(
            dim=d,
            degree=k,
            n_ctrl=n_ctrl,
            duration=float(t[-1]),
            smoothness=smoothness,
            deviations=tuple(deviations) if spec.kind != "interpolation" else (),
            interpolation=(Interpolation(t, pts),) if spec.kind == "interpolation" else (),
            boundary=boundary,
        )

    return times, make


def spiral(n: int) -> tuple[Array, Array]:
    """``n`` points of the hand-drawn spiral, subsampled evenly, times from 0."""
    pts, t = read_points_csv(SPIRAL)
    assert t is not None
    idx = np.linspace(0, pts.shape[0] - 1, n).round().astype(int)
    return pts[idx], t[idx] - t[idx[0]]


def limited_spiral(n: int, n_ctrl: int, coupled: int | None) -> tuple[Array, Array, Factory]:
    """Spiral fit with speed / acceleration / jerk limits at 0.8 / 0.7 / 0.7 of the free fit."""
    pts, times = spiral(n)
    free = solve(point_fit_factory(pts, n_ctrl)(times)).trajectory.sample(500.0)
    vmax, amax, jmax = (float(np.abs(x).max()) for x in (free.v, free.a, free.j))
    limits = vehicle_limits(2, 0.8 * vmax, 0.7 * amax, 0.7 * jmax, coupled)
    return pts, times, point_fit_factory(pts, n_ctrl, limits=limits)


# ------------------------------------------------------------------ gradient
@SETTINGS
@given(spec=specs)
def test_gradient_matches_central_differences(spec: Spec) -> None:
    times, make = random_problem(spec)
    grad = time_gradient(times, make)
    reference = finite_difference_gradient(times, make, step=1e-5)
    _close(grad.grad_segments, reference)
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
    _close(n / (n - 1) * (g - g.mean()), reference)


@pytest.mark.parametrize("coupled", [None, 8])
def test_qp_gradient_matches_central_differences(coupled: int | None) -> None:
    _, times, make = limited_spiral(24, 18, coupled)
    grad = time_gradient(times, make)
    assert grad.result.method == "qp"
    assert grad.n_active > 0
    assert grad.stationarity_residual < 1e-8
    exact = finite_difference_gradient(times, make, step=1e-5, polished=True)
    _close(grad.grad_segments, exact, rtol=1e-6)
    _close(grad.grad_segments, finite_difference_gradient(times, make, step=1e-5), rtol=1e-4)


@settings(max_examples=20, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2**16), dim=st.integers(2, 3), fraction=st.floats(0.5, 0.9))
def test_qp_gradient_random(seed: int, dim: int, fraction: float) -> None:
    rng = np.random.default_rng(seed)
    n = 7
    pts = np.cumsum(rng.normal(0.0, 0.5, (n, dim)), axis=0)
    times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.5, 1.5, n - 1))])
    free = solve(point_fit_factory(pts, 14, degree=4, weight=100.0)(times))
    acc = float(np.abs(free.trajectory.sample(500.0).a).max())
    limit = BoxLimit.symmetric(2, fraction * acc, dim)
    make = point_fit_factory(pts, 14, degree=4, weight=100.0, limits=(limit,))
    try:
        grad = time_gradient(times, make)
    except InfeasibleError:
        assume(False)
        return
    assert grad.n_active > 0
    assert grad.stationarity_residual < 1e-8
    assert grad.polished_cost <= grad.cost * (1.0 + 1e-12)
    exact = finite_difference_gradient(times, make, step=1e-5, polished=True)
    _close(grad.grad_segments, exact, rtol=1e-6)
    # The backend's cost is optimal to ~1e-8 relative only: its quotient agrees to ~1e-5.
    _close(grad.grad_segments, finite_difference_gradient(times, make, step=1e-5), rtol=1e-4)


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


# ------------------------------------------------------------------ descent
@pytest.mark.parametrize("step_rule", ["bb", "double"])
def test_fixed_mode_descends_monotonically_and_keeps_total_time(
    step_rule: Literal["bb", "double"],
) -> None:
    pts, times = spiral(30)
    make = point_fit_factory(pts, 22)
    out = resegment(pts, times, make, mode="fixed", max_iter=300, step_rule=step_rule)
    assert out.status == "converged"
    assert np.all(np.diff(out.history) <= 0.0)
    assert out.history[-1] < 0.5 * out.history[0]
    assert abs(out.total_time - times[-1]) <= 1e-12 * times[-1]
    assert np.all(np.abs(out.total_time_history - times[-1]) <= 1e-12 * times[-1])
    assert np.all(np.diff(out.times) > 0.0)
    assert out.times[0] == 0.0
    assert out.cost == out.history[-1]
    assert out.n_solves >= out.iterations + 1
    # At the end the projected gradient is small against where it started.
    start = time_gradient(times, make).grad_segments
    assert out.gradient_norm < 1e-3 * float(np.linalg.norm(start - start.mean()))


def test_free_mode_with_penalty_converges_to_a_finite_time() -> None:
    pts, times = spiral(30)
    make = point_fit_factory(pts, 22)
    rho = 20.0
    out = resegment(pts, times, make, mode="free", time_penalty=rho, max_iter=500, tol=1e-8)
    assert out.status == "converged"
    assert np.all(np.diff(out.history) <= 0.0)
    assert np.isfinite(out.total_time)
    # Stationary along the scaling direction: rho D = 5 E_jerk (module docstring).
    energy = out.result.cost_terms["smoothness"]
    assert rho * out.total_time == pytest.approx(5.0 * energy, rel=1e-4)
    # A larger price buys a shorter time.
    dearer = resegment(pts, times, make, mode="free", time_penalty=4 * rho, max_iter=500)
    assert dearer.total_time < out.total_time


def test_free_mode_without_penalty_drifts_to_longer_times() -> None:
    pts, times = spiral(20)
    out = resegment(pts, times, point_fit_factory(pts, 16), mode="free", max_iter=40)
    assert out.status == "max_iter"
    assert np.all(np.diff(out.history) < 0.0)
    assert out.total_time > 1.5 * times[-1]
    assert out.total_time_history[-1] > out.total_time_history[-10]


def test_qp_descent_stays_feasible_and_monotone() -> None:
    pts, times, make = limited_spiral(24, 18, 8)
    out = resegment(pts, times, make, mode="fixed", max_iter=15)
    assert out.result.method == "qp"
    assert np.all(np.diff(out.history) <= 0.0)
    assert out.history[-1] < out.history[0]
    assert out.result.verification.max_excess <= 1e-9


def test_default_problem_and_two_points() -> None:
    pts, times = spiral(12)
    out = resegment(pts, times + 3.0, max_iter=5)  # shifted to start at 0
    assert out.initial_times[0] == 0.0
    assert out.history[-1] <= out.history[0]
    two = resegment(pts[:2], np.array([0.0, 1.0]), mode="fixed")
    assert two.status == "converged"
    assert two.iterations == 0


# ------------------------------------------------------------------ validation
def test_rejects_bad_arguments() -> None:
    pts, times = spiral(8)
    make = point_fit_factory(pts, 14)
    with pytest.raises(InputError, match="mode: got 'loose'"):
        resegment(pts, times, make, mode="loose")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="step_rule: got 'newton'"):
        resegment(pts, times, make, step_rule="newton")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="time_penalty: got -1"):
        resegment(pts, times, make, mode="free", time_penalty=-1.0)
    with pytest.raises(InputError, match="times: got times\\[2\\]"):
        resegment(pts, times[[0, 1, 3, 2, 4, 5, 6, 7]], make)
    with pytest.raises(InputError, match="times: got an array of shape"):
        resegment(pts, times[:5], make)
    with pytest.raises(InputError, match="times: got 1 time\\(s\\), expected at least 2"):
        resegment(pts[:1], times[:1])
    with pytest.raises(InputError, match="times: got times\\[0\\] = 1, expected 0"):
        time_gradient(times + 1.0, make)


def test_rejects_a_factory_that_breaks_the_contract() -> None:
    pts, times = spiral(8)
    good = point_fit_factory(pts, 14)

    def padded(t: Array) -> SmoothingProblem:
        p = good(t)
        return SmoothingProblem(
            p.dim, p.degree, p.n_ctrl, p.duration + 1.0, p.smoothness, p.deviations
        )

    def growing(t: Array) -> SmoothingProblem:
        n_ctrl = 14 if t[-1] == times[-1] else 15
        return point_fit_factory(pts, n_ctrl)(t)

    with pytest.raises(InputError, match="expected duration == times\\[-1\\]"):
        resegment(pts, times, padded)
    with pytest.raises(InputError, match="expected the same n_ctrl = 14"):
        resegment(pts, times, growing, mode="free", time_penalty=1.0)


def test_terms_on_subsets_of_the_times_move_with_them() -> None:
    """A writing mission weights stroke samples and transits differently: two point terms
    on disjoint subsets of the times. The analytic gradient must still match finite
    differences (each subset's points move with their times)."""
    from skyquill.optimize import Boundary, PointDeviation, SmoothingProblem
    from skyquill.optimize.resegment import finite_difference_gradient, time_gradient

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
