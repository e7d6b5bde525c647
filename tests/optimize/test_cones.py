"""Exact norm limits through second-order cones: dense checks, costs, routing, infeasibility.

The reference is independent of the engine: the trajectory is sampled at
20,000 times with ``evaluate`` and the Euclidean norms compared with the
radius. Limits are set to a fraction of the unconstrained fit's peak norms,
so they are active.
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.typing import NDArray

from skyquill.errors import InfeasibleError
from skyquill.limits import NormLimit, VehicleLimits
from skyquill.optimize import Boundary, FitResult, PointDeviation, SmoothingProblem, solve
from skyquill.optimize.assemble import assemble
from skyquill.optimize.solve import _hull_excess, _to_qp
from skyquill.spline import HullKind

Array = NDArray[np.float64]
N_CHECK = 20_000


def noisy_curve(kind: str, n: int = 600, duration: float = 8.0, seed: int = 0) -> Array:
    """Samples of a 3-D curve with 1 cm noise (rest-to-rest time law)."""
    t = np.linspace(0.0, duration, n)
    u = t / duration
    s = 10 * u**3 - 15 * u**4 + 6 * u**5
    if kind == "helix":
        p = np.column_stack([np.cos(2 * np.pi * s), np.sin(2 * np.pi * s), 0.8 * s])
    else:  # a climbing figure eight: large vertical speed too
        p = np.column_stack([np.sin(2 * np.pi * s), np.sin(4 * np.pi * s) / 2, 1.5 * s])
    return p + 0.01 * np.random.default_rng(seed).standard_normal(p.shape)


def problem(
    points: Array, duration: float, limits: tuple[object, ...] = (), hull: HullKind = "bspline"
) -> SmoothingProblem:
    t = np.linspace(0.0, duration, points.shape[0])
    return SmoothingProblem(
        dim=points.shape[1],
        degree=5,
        n_ctrl=60 + 5,
        duration=duration,
        smoothness={3: 1.0},
        deviations=(PointDeviation(t, points, 1e4),),
        boundary=Boundary.rest(points[0], points[-1], 3),
        limits=limits,  # type: ignore[arg-type]
        hull=hull,
    )


def peak_norms(fit: FitResult, n: int = N_CHECK) -> dict[int, float]:
    t = np.linspace(0.0, fit.trajectory.duration, n)
    return {
        k: float(np.linalg.norm(fit.trajectory.evaluate(t, k), axis=1).max()) for k in (1, 2, 3)
    }


def tight_limits(points: Array, duration: float, fraction: float) -> VehicleLimits:
    free = peak_norms(solve(problem(points, duration)))
    return VehicleLimits(fraction * free[1], fraction * free[2], fraction * free[3])


@pytest.mark.parametrize(
    ("kind", "fraction", "hull"),
    [("helix", 0.7, "bspline"), ("helix", 0.5, "bezier"), ("eight", 0.6, "bspline")],
)
def test_cones_hold_on_dense_samples(kind: str, fraction: float, hull: HullKind) -> None:
    points, duration = noisy_curve(kind), 8.0
    vl = tight_limits(points, duration, fraction)
    fit = solve(problem(points, duration, vl.derivative_limits(3), hull))
    assert fit.solver == "clarabel"
    assert fit.n_cones > 0 and fit.n_inequalities == 0
    peaks = peak_norms(fit)
    for order in (1, 2, 3):
        bound = vl.norm(order)
        assert bound is not None
        assert peaks[order] <= bound * (1 + 1e-9), order
    # At least one norm is active: the limits bind, so the test tests something.
    assert max(peaks[k] / (vl.norm(k) or 1.0) for k in (1, 2, 3)) > 0.999
    check = fit.verification
    assert check.n_samples >= 10_000
    assert check.max_excess <= 1e-9
    assert [c.label for c in check.checks] == [
        "speed norm (cone)",
        "acceleration norm (cone)",
        "jerk norm (cone)",
    ]
    assert check.max_speed <= vl.norm(1) * (1 + 1e-9)  # type: ignore[operator]


def test_cones_cost_no_more_than_inscribed_polytopes() -> None:
    """The ball contains every inscribed polytope: a larger feasible set, a lower optimum."""
    points, duration = noisy_curve("helix"), 8.0
    vl = tight_limits(points, duration, 0.7)
    costs = {}
    for sides in (None, 8, 16):
        fit = solve(problem(points, duration, vl.derivative_limits(3, sides=sides)))
        assert fit.verification.max_excess <= 1e-9
        costs[sides] = fit.cost
    assert costs[None] <= costs[16] * (1 + 1e-6)
    assert costs[16] <= costs[8] * (1 + 1e-6)


def test_cones_mixed_with_boxes_and_2d() -> None:
    points = noisy_curve("helix")[:, :2]
    free = peak_norms(solve(problem(points, 8.0)))
    vl = VehicleLimits(vmax=0.8 * free[1], amax_axis=0.8 * free[2], jmax=0.8 * free[3])
    fit = solve(problem(points, 8.0, vl.derivative_limits(2)))
    assert fit.solver == "clarabel" and fit.n_inequalities > 0 and fit.n_cones > 0
    assert fit.verification.max_excess <= 1e-9
    peaks = peak_norms(fit)
    assert peaks[1] <= 0.8 * free[1] * (1 + 1e-9)
    t = np.linspace(0.0, 8.0, N_CHECK)
    assert np.abs(fit.trajectory.evaluate(t, 2)).max() <= 0.8 * free[2] * (1 + 1e-9)


def test_cone_problem_ignores_a_qp_only_solver_name() -> None:
    points = noisy_curve("helix", n=200)
    fit = solve(problem(points, 8.0, (NormLimit(1, 0.9),)), solver="osqp")
    assert fit.solver == "clarabel"
    assert fit.verification.max_excess <= 1e-9


def test_norms_that_do_not_bind_are_solved_as_a_qp_with_the_same_optimum() -> None:
    """Loose balls: the box relaxation's optimum meets them, so no conic solve is needed."""
    points = noisy_curve("helix", n=200)
    free = solve(problem(points, 8.0))
    loose = tuple(NormLimit(k, 2.0 * v) for k, v in peak_norms(free).items())
    fit = solve(problem(points, 8.0, loose))
    assert fit.solver == "piqp" and fit.n_cones > 0
    assert fit.cone_z is not None and not np.any(fit.cone_z)
    np.testing.assert_allclose(
        fit.trajectory.control_points, free.trajectory.control_points, atol=1e-6
    )
    assert fit.verification.max_excess == 0.0
    # Binding balls: the conic program (Clarabel) decides.
    tight = tuple(NormLimit(k, 0.7 * v) for k, v in peak_norms(free).items())
    assert solve(problem(points, 8.0, tight)).solver == "clarabel"


def test_infeasible_cone_names_its_family() -> None:
    """A 1 m rise in 1 s cannot keep the speed under 0.5 m/s: the speed cone is named."""
    start, end = np.zeros(3), np.array([0.0, 0.0, 1.0])
    prob = SmoothingProblem(
        dim=3,
        degree=5,
        n_ctrl=15,
        duration=1.0,
        boundary=Boundary.rest(start, end, 3),
        limits=(NormLimit(1, 0.5), NormLimit(3, 1e6)),
    )
    with pytest.raises(InfeasibleError, match=r"speed norm \(cone\)") as info:
        solve(prob)
    assert info.value.families == ("limit: speed norm (cone)",)


def test_cone_is_looser_than_its_polytope_at_the_same_duration() -> None:
    """A move the cone allows and the inscribed 8-gon globe cannot.

    The mean velocity over the move is displacement / duration and lies in the
    convex hull of the velocity hull points, so no polytope whose reach along
    the move is below the mean speed can hold them. Along the normal of the
    globe's nearest facet the reach is its inscribed fraction (0.86 vmax); a
    mean speed of 0.9 vmax fits the ball, not the globe.
    """
    vmax = 1.0
    A, b = NormLimit(1, vmax, 8).halfspaces()
    direction = A[int(np.argmin(b))]
    base = dict(
        dim=3,
        degree=5,
        n_ctrl=25,
        duration=1.0 / (0.9 * vmax),
        boundary=Boundary.rest(np.zeros(3), direction, 3),
    )
    ok = solve(SmoothingProblem(limits=(NormLimit(1, vmax),), **base))  # type: ignore[arg-type]
    assert ok.verification.max_excess <= 1e-9
    assert ok.verification.max_speed > 0.9 * vmax
    with pytest.raises(InfeasibleError, match=r"speed norm \(8-gon globe\)"):
        solve(SmoothingProblem(limits=(NormLimit(1, vmax, 8),), **base))  # type: ignore[arg-type]


def test_margin_shrinks_the_radius_and_the_check_sees_the_cone() -> None:
    """The margin loop's two halves for cones: tightened radius in, untightened check out."""
    points = noisy_curve("helix", n=100)
    asm = assemble(problem(points, 8.0, (NormLimit(1, 0.5), NormLimit(2, 2.0, 8))))
    assert asm.cones is not None
    n_points = asm.cones.radius.size
    qp = _to_qp(asm, 1e-3)
    assert qp.cones is not None
    assert qp.cones.dims == (4,) * n_points
    np.testing.assert_allclose(qp.cones.b[::4], 0.5 * (1 - 1e-3))
    assert not np.any(qp.cones.b.reshape(n_points, 4)[:, 1:])
    # At rest everything holds; move one control point and compare with the
    # speed limit's own measure on the velocity hull points.
    C = np.tile([1.0, 0.0, 0.0], (asm.F.shape[0], 1))
    assert _hull_excess(asm, C.ravel()) == 0.0
    prob = problem(points, 8.0)
    C[3] += [0.1, -0.2, 0.15]
    hull_v = prob.alpha * (prob.basis.hull_map(1) @ C)
    expected = NormLimit(1, 0.5).relative_excess(hull_v)[1]
    assert expected > 0.1
    speed_only = assemble(problem(points, 8.0, (NormLimit(1, 0.5),)))
    assert _hull_excess(speed_only, C.ravel()) == pytest.approx(expected, rel=1e-12)
