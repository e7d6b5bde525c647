"""The closed form (sparse LU on the KKT system) against independent references.

References used here, none of which goes through ``skyquill.spline``'s Gram
matrices, derivative maps or ``skyquill.optimize.assemble``:

* the classic quintic minimum-jerk polynomial ``10 s^3 - 15 s^4 + 6 s^5``;
* a dense KKT system built in numpy from B-spline basis functions evaluated
  by ``scipy.interpolate.BSpline`` in the time domain, with Gauss-Legendre
  Gram matrices and the paper's line / plane quadratic forms (paper 003
  eqs. 10-12, 15, 24-27, 42);
* the QP route (a loose, inactive limit, or ``solve_qp`` on the assembled QP);
* Gauss-Legendre quadrature of the returned trajectory's jerk.
"""

from __future__ import annotations

import dataclasses
from math import comb

import numpy as np
import pytest
from numpy.typing import NDArray
from scipy.interpolate import BSpline

from skyquill.limits import BoxLimit
from skyquill.optimize import (
    Boundary,
    Interpolation,
    LineDeviation,
    PlaneDeviation,
    PointDeviation,
    SmoothingProblem,
    solve,
)
from skyquill.optimize.assemble import assemble, problem_cost
from skyquill.optimize.solve import BANDED, _to_qp
from skyquill.solvers import solve_qp

Array = NDArray[np.float64]


# ------------------------------------------------------------------ problem factories
def boundary_only(dim: int = 2, degree: int = 5, n_ctrl: int = 14) -> SmoothingProblem:
    """Rest to rest, pure minimum jerk."""
    return SmoothingProblem(
        dim=dim,
        degree=degree,
        n_ctrl=n_ctrl,
        duration=3.0,
        boundary=Boundary.rest(np.zeros(dim), np.arange(1.0, dim + 1.0), 3),
    )


def boundary_interpolation(dim: int = 2) -> SmoothingProblem:
    """Rest to rest through interior waypoints and both end points.

    The end points repeat what the boundary conditions already fix, so the
    equalities are redundant but consistent.
    """
    rng = np.random.default_rng(7)
    start, end = np.zeros(dim), np.ones(dim)
    points = np.vstack([start, rng.uniform(-1, 2, (3, dim)), end])
    return SmoothingProblem(
        dim=dim,
        degree=5,
        n_ctrl=16,
        duration=4.0,
        boundary=Boundary.rest(start, end, 3),
        interpolation=(Interpolation([0.0, 1.0, 2.0, 3.0, 4.0], points),),
    )


def boundary_interior_interpolation(dim: int = 2) -> SmoothingProblem:
    """Rest to rest through interior waypoints only (independent equalities)."""
    rng = np.random.default_rng(8)
    return SmoothingProblem(
        dim=dim,
        degree=5,
        n_ctrl=16,
        duration=4.0,
        boundary=Boundary.rest(np.zeros(dim), np.ones(dim), 3),
        interpolation=(Interpolation([0.7, 2.1, 3.3], rng.uniform(-1, 2, (3, dim))),),
    )


def boundary_points(dim: int = 3, degree: int = 4, seed: int = 3) -> SmoothingProblem:
    """Rest to rest, smoothing through noisy points, snap and jerk cost."""
    rng = np.random.default_rng(seed)
    times = np.sort(rng.uniform(0.0, 5.0, 12))
    return SmoothingProblem(
        dim=dim,
        degree=degree,
        n_ctrl=20,
        duration=5.0,
        smoothness={3: 1.0, 2: 0.1},
        boundary=Boundary.rest(np.zeros(dim), np.ones(dim), min(3, degree)),
        deviations=(PointDeviation(times, rng.normal(size=(12, dim)), weight=30.0),),
    )


def with_line(dim: int = 2, weight: float = 10.0) -> SmoothingProblem:
    """Point deviations plus a line deviation on a window (axis-coupled)."""
    base = boundary_points(dim=dim, degree=5, seed=11)
    line = LineDeviation(np.zeros(dim), np.ones(dim), 1.25, 3.5, weight=weight)
    return dataclasses.replace(base, deviations=(*base.deviations, line))


def with_plane(weight: float = 10.0) -> SmoothingProblem:
    """3-D point deviations plus a plane deviation on a window (axis-coupled)."""
    base = boundary_points(dim=3, degree=5, seed=12)
    plane = PlaneDeviation([0.3, -0.2, 1.0], [0.0, 0.0, 0.5], 1.5, 3.5, weight=weight)
    return dataclasses.replace(base, deviations=(*base.deviations, plane))


def with_line_and_plane() -> SmoothingProblem:
    base = with_line(dim=3)
    plane = PlaneDeviation([0.0, 0.0, 1.0], [0.0, 0.0, 0.2], 2.0, 5.0, weight=4.0)
    return dataclasses.replace(base, deviations=(*base.deviations, plane))


CLOSED_FORM_CASES = {
    "boundary-only": boundary_only,
    "boundary-only-degree3": lambda: boundary_only(dim=3, degree=3, n_ctrl=9),
    "boundary+interpolation": boundary_interior_interpolation,
    "boundary+redundant-interpolation": boundary_interpolation,
    "boundary+points": boundary_points,
    "boundary+points-degree6": lambda: boundary_points(dim=2, degree=6),
}
COUPLED_CASES = {
    "line": with_line,
    "plane": with_plane,
    "line+plane": with_line_and_plane,
}


def loose_limit(problem: SmoothingProblem) -> SmoothingProblem:
    """The same problem with a limit far from active: ``solve`` takes the QP route."""
    return dataclasses.replace(problem, limits=(BoxLimit.symmetric(1, 1e6, problem.dim),))


def rel_diff(a: Array, b: Array) -> float:
    return float(np.abs(a - b).max() / max(1.0, float(np.abs(b).max())))


# ------------------------------------------------------------------ dense reference
def basis_functions(problem: SmoothingProblem) -> list[BSpline]:
    """The M basis functions in *time*, knots of paper 003 eq. (4) divided by alpha."""
    k, M, T = problem.degree, problem.n_ctrl, problem.duration
    L = M - k
    knots = np.concatenate([np.zeros(k), np.linspace(0.0, T, L + 1), np.full(k, T)])
    return [BSpline(knots, np.eye(M)[i], k) for i in range(M)]


def evaluate_basis(funcs: list[BSpline], t: Array, order: int = 0) -> Array:
    """Matrix (len(t), M) of basis-function derivatives at times t."""
    return np.column_stack([f.derivative(order)(t) if order else f(t) for f in funcs])


def quadrature(T: float, n_spans: int, n_nodes: int = 10) -> tuple[Array, Array]:
    """Gauss-Legendre nodes and weights on every knot span of [0, T]."""
    x, w = np.polynomial.legendre.leggauss(n_nodes)
    h = T / n_spans
    t = ((np.arange(n_spans)[:, None] + 0.5 * (x + 1.0)[None, :]) * h).ravel()
    return t, np.tile(0.5 * h * w, n_spans)


def active_controls(problem: SmoothingProblem, t_start: float, t_end: float) -> Array:
    """Indicator of control points whose basis function is non-zero on (t_start, t_end)."""
    k, M, T = problem.degree, problem.n_ctrl, problem.duration
    L = M - k
    i = np.arange(M)
    lo = np.maximum(0, i - k) * T / L  # support of N_i in time
    hi = np.minimum(L, i + 1) * T / L
    return ((lo < t_end) & (hi > t_start)).astype(float)


def dense_reference(problem: SmoothingProblem) -> Array:
    """Minimiser of the problem's cost under its equalities by one dense KKT solve.

    Built from scratch: cost ``sum_n sigma_n ∫ ||p^(n)||^2 + sum_i w ||p(t_i) - P_i||^2
    + sum_lines/planes w sum_(active c) (c - w)' Q (c - w)`` with ``x = C.ravel()``.
    """
    funcs = basis_functions(problem)
    M, d, T = problem.n_ctrl, problem.dim, problem.duration
    eye = np.eye(d)
    t_q, w_q = quadrature(T, M - problem.degree)
    H = np.zeros((M * d, M * d))
    f = np.zeros(M * d)
    for order, sigma in problem.smoothness.items():
        B = evaluate_basis(funcs, t_q, order)
        H += sigma * np.kron(B.T @ (w_q[:, None] * B), eye)
    for term in problem.deviations:
        if isinstance(term, PointDeviation):
            B = evaluate_basis(funcs, term.times)
            H += term.weight * np.kron(B.T @ B, eye)
            f -= 2.0 * term.weight * (B.T @ term.points).ravel()
        else:
            if isinstance(term, LineDeviation):
                u = (term.b - term.a) / np.linalg.norm(term.b - term.a)
                Q, anchor = eye - np.outer(u, u), term.a  # any point on the line
            else:
                n = term.normal / np.linalg.norm(term.normal)
                Q, anchor = np.outer(n, n), term.anchor
            act = active_controls(problem, term.t_start, term.t_end)
            H += term.weight * np.kron(np.diag(act), Q)
            f -= 2.0 * term.weight * np.kron(act, Q @ anchor)
    rows, rhs = [], []
    for bc in problem.boundary:
        for t_end, value in ((0.0, bc.start), (T, bc.end)):
            if value is not None:
                rows.append(evaluate_basis(funcs, np.array([t_end]), bc.order))
                rhs.append(value[None, :])
    for interp in problem.interpolation:
        rows.append(evaluate_basis(funcs, interp.times))
        rhs.append(interp.points)
    E, e = np.vstack(rows), np.vstack(rhs)
    # Redundant rows (a boundary point also interpolated) would make the KKT
    # matrix singular: keep an independent subset, chosen by the SVD rank.
    keep: list[int] = []
    for r in range(E.shape[0]):
        if np.linalg.matrix_rank(E[[*keep, r]], tol=1e-9) > len(keep):
            keep.append(r)
    E_full = np.kron(E[keep], eye)
    m = E_full.shape[0]
    K = np.block([[2.0 * H, E_full.T], [E_full, np.zeros((m, m))]])
    sol = np.linalg.solve(K, np.concatenate([-f, e[keep].ravel()]))
    return sol[: M * d].reshape(M, d)


# ------------------------------------------------------------------ quintic
@pytest.mark.parametrize("duration", [1.0, 2.5])
@pytest.mark.parametrize("distance", [1.0, -3.0])
def test_single_span_min_jerk_is_the_classic_quintic(duration: float, distance: float) -> None:
    problem = SmoothingProblem(
        dim=1,
        degree=5,
        n_ctrl=6,
        duration=duration,
        boundary=Boundary.rest([0.0], [distance], 3),
    )
    result = solve(problem)
    assert result.method == "closed_form"
    assert result.margin == 0.0
    t = np.linspace(0.0, duration, 201)
    s = t / duration
    quintic = distance * (10 * s**3 - 15 * s**4 + 6 * s**5)
    p = result.trajectory.evaluate(t)[:, 0]
    assert np.abs(p - quintic).max() <= 1e-9 * abs(distance)
    # One span: the B-spline is a Bézier curve; the quintic's Bernstein
    # coefficients are (0, 0, 0, 1, 1, 1) * distance.
    ctrl = result.trajectory.control_points[:, 0]
    assert np.abs(ctrl - distance * np.array([0, 0, 0, 1, 1, 1.0])).max() <= 1e-9 * abs(distance)
    # ∫ jerk^2 of the quintic = 720 D^2 / T^5.
    assert result.cost == pytest.approx(720.0 * distance**2 / duration**5, rel=1e-9)


def test_single_span_min_jerk_against_bernstein_kkt() -> None:
    """Independent numpy KKT in the Bernstein basis (no spline code at all)."""
    k, T, D = 5, 2.0, 1.7
    P = np.polynomial.Polynomial
    bern = [P([0, 1]) ** i * P([1, -1]) ** (k - i) * comb(k, i) for i in range(k + 1)]
    jerk = [b.deriv(3) for b in bern]  # d^3/ds^3; d/dt = (1/T) d/ds
    V = np.array([[(a * b).integ()(1.0) - (a * b).integ()(0.0) for b in jerk] for a in jerk])
    V /= T**5  # ∫_0^T (p''')^2 dt with s = t/T
    E = np.array([[b.deriv(n)(end) / T**n for b in bern] for end in (0.0, 1.0) for n in range(3)])
    e = np.array([0.0, 0.0, 0.0, D, 0.0, 0.0])
    K = np.block([[2 * V, E.T], [E, np.zeros((6, 6))]])
    ref = np.linalg.solve(K, np.concatenate([np.zeros(6), e]))[:6]
    problem = SmoothingProblem(
        dim=1, degree=k, n_ctrl=6, duration=T, boundary=Boundary.rest([0.0], [D], 3)
    )
    got = solve(problem).trajectory.control_points[:, 0]
    assert np.abs(got - ref).max() <= 1e-9 * D


# ------------------------------------------------------------------ dense reference
@pytest.mark.parametrize(
    "make",
    [*CLOSED_FORM_CASES.values(), *COUPLED_CASES.values()],
    ids=[*CLOSED_FORM_CASES, *COUPLED_CASES],
)
def test_closed_form_matches_dense_kkt(make: object) -> None:
    problem = make()  # type: ignore[operator]
    result = solve(problem)
    assert result.method == "closed_form"
    assert result.solver in ("sparse-lu", BANDED)
    ref = dense_reference(problem)
    assert rel_diff(result.trajectory.control_points, ref) <= 1e-9


# ------------------------------------------------------------------ closed form == QP
@pytest.mark.parametrize(
    "make",
    [*CLOSED_FORM_CASES.values(), *COUPLED_CASES.values()],
    ids=[*CLOSED_FORM_CASES, *COUPLED_CASES],
)
@pytest.mark.parametrize("backend", ["clarabel", "piqp"])
def test_closed_form_equals_qp_route(make: object, backend: str) -> None:
    problem = make()  # type: ignore[operator]
    closed = solve(problem)
    qp = solve(loose_limit(problem), backend)
    assert closed.method == "closed_form"
    assert qp.method == "qp"
    assert qp.solver == backend
    assert rel_diff(qp.trajectory.control_points, closed.trajectory.control_points) <= 1e-8
    assert qp.cost == pytest.approx(closed.cost, rel=1e-8)


@pytest.mark.parametrize(
    "make",
    [*CLOSED_FORM_CASES.values(), *COUPLED_CASES.values()],
    ids=[*CLOSED_FORM_CASES, *COUPLED_CASES],
)
@pytest.mark.parametrize("backend", ["clarabel", "piqp", "osqp"])
def test_closed_form_equals_solve_qp_on_assembled(make: object, backend: str) -> None:
    """The assembled equality-only QP, straight to each backend."""
    problem = make()  # type: ignore[operator]
    closed = solve(problem)
    qp = _to_qp(assemble(problem))
    assert qp.h.size == 0
    sol = solve_qp(qp, backend)
    assert sol.status == "optimal"
    assert sol.x is not None
    C = sol.x.reshape(problem.n_ctrl, problem.dim)
    # OSQP is first-order: it meets 1e-10 residuals but not 1e-8 on the iterate.
    tol = 1e-6 if backend == "osqp" else 1e-8
    assert rel_diff(C, closed.trajectory.control_points) <= tol
    # The reported cost is evaluated term by term, not from the scaled QP.
    assert problem_cost(problem, C)["total"] == pytest.approx(closed.cost, rel=1e-8, abs=1e-12)
    # The closed form's multipliers (from its KKT solve) are the backend's duals.
    assert sol.y is not None
    assert closed.y.shape == sol.y.shape == (closed.n_equalities,)
    assert closed.z.shape == (0,)
    assert rel_diff(sol.y, closed.y) <= 1e3 * tol


# ------------------------------------------------------------------ cost terms
def jerk_integral(result_traj: object, problem: SmoothingProblem, order: int = 3) -> float:
    t, w = quadrature(problem.duration, problem.n_ctrl - problem.degree, n_nodes=12)
    jerk = result_traj.evaluate(t, order)  # type: ignore[attr-defined]
    return float(np.sum(w * np.sum(jerk**2, axis=1)))


@pytest.mark.parametrize("make", list(CLOSED_FORM_CASES.values()), ids=list(CLOSED_FORM_CASES))
def test_smoothness_cost_is_the_integral(make: object) -> None:
    problem = make()  # type: ignore[operator]
    result = solve(problem)
    expected = sum(
        sigma * jerk_integral(result.trajectory, problem, order)
        for order, sigma in problem.smoothness.items()
    )
    assert result.cost_terms["smoothness"] == pytest.approx(expected, rel=1e-9)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_point_deviation_cost_is_the_sum_of_squared_residuals(seed: int) -> None:
    problem = boundary_points(seed=seed)
    result = solve(problem)
    (term,) = problem.deviations
    assert isinstance(term, PointDeviation)
    residual = result.trajectory.evaluate(term.times) - term.points
    expected = term.weight * float(np.sum(residual**2))
    assert result.cost_terms["deviation"] == pytest.approx(expected, rel=1e-9)
    assert result.cost == pytest.approx(
        result.cost_terms["smoothness"] + result.cost_terms["deviation"], rel=1e-12
    )
    assert result.cost_terms["total"] == result.cost


def test_flat_deviation_cost_is_the_control_point_distance_sum() -> None:
    problem = with_line(weight=3.0)
    result = solve(problem)
    line = problem.deviations[-1]
    point = problem.deviations[0]
    assert isinstance(line, LineDeviation)
    assert isinstance(point, PointDeviation)
    C = result.trajectory.control_points
    u = (line.b - line.a) / np.linalg.norm(line.b - line.a)
    rel = C - line.a
    dist2 = np.sum(rel**2, axis=1) - (rel @ u) ** 2
    act = active_controls(problem, line.t_start, line.t_end)
    residual = result.trajectory.evaluate(point.times) - point.points
    expected = line.weight * float(act @ dist2) + point.weight * float(np.sum(residual**2))
    assert result.cost_terms["deviation"] == pytest.approx(expected, rel=1e-9)


# ------------------------------------------------------------------ lines and planes
def line_distance(p: Array, a: Array, b: Array) -> Array:
    u = (b - a) / np.linalg.norm(b - a)
    rel = p - a
    return np.sqrt(np.maximum(np.sum(rel**2, axis=1) - (rel @ u) ** 2, 0.0))


def plane_distance(p: Array, normal: Array, anchor: Array) -> Array:
    return np.abs((p - anchor) @ normal) / np.linalg.norm(normal)


@pytest.mark.parametrize("dim", [2, 3])
def test_strong_line_weight_pulls_the_window_onto_the_line(dim: int) -> None:
    weak = solve(with_line(dim=dim, weight=1.0))
    strong_problem = with_line(dim=dim, weight=1e7)
    strong = solve(strong_problem)
    line = strong_problem.deviations[-1]
    assert isinstance(line, LineDeviation)
    act = active_controls(strong_problem, line.t_start, line.t_end).astype(bool)
    d_weak = line_distance(weak.trajectory.control_points[act], line.a, line.b)
    d_strong = line_distance(strong.trajectory.control_points[act], line.a, line.b)
    assert d_strong.max() <= 1e-3
    assert d_strong.max() < 0.05 * d_weak.max()
    # Paper 003 eq. (22): on the window the curve is never farther from the
    # line than the farthest active control point.
    for result in (weak, strong):
        t = np.linspace(line.t_start, line.t_end, 4001)
        curve = line_distance(result.trajectory.evaluate(t), line.a, line.b)
        ctrl = line_distance(result.trajectory.control_points[act], line.a, line.b)
        assert curve.max() <= ctrl.max() * (1.0 + 1e-12) + 1e-14


def test_strong_plane_weight_pulls_the_window_onto_the_plane() -> None:
    weak = solve(with_plane(weight=1.0))
    strong_problem = with_plane(weight=1e7)
    strong = solve(strong_problem)
    plane = strong_problem.deviations[-1]
    assert isinstance(plane, PlaneDeviation)
    act = active_controls(strong_problem, plane.t_start, plane.t_end).astype(bool)
    d_weak = plane_distance(weak.trajectory.control_points[act], plane.normal, plane.anchor)
    d_strong = plane_distance(strong.trajectory.control_points[act], plane.normal, plane.anchor)
    assert d_strong.max() <= 1e-3
    assert d_strong.max() < 0.05 * d_weak.max()
    for result in (weak, strong):
        t = np.linspace(plane.t_start, plane.t_end, 4001)
        curve = plane_distance(result.trajectory.evaluate(t), plane.normal, plane.anchor)
        ctrl = plane_distance(result.trajectory.control_points[act], plane.normal, plane.anchor)
        assert curve.max() <= ctrl.max() * (1.0 + 1e-12) + 1e-14


def test_window_controls_match_independent_support() -> None:
    """The engine penalises exactly the control points whose support meets the window."""
    from skyquill.optimize.assemble import _window_controls

    problem = boundary_points(degree=4)
    for t0, t1 in [(0.0, 5.0), (1.25, 3.5), (0.5, 0.75), (4.9, 5.0), (1.0, 2.0)]:
        got = _window_controls(problem, t0, t1)
        assert np.array_equal(got, active_controls(problem, t0, t1)), (t0, t1)


# ------------------------------------------------------------------ edge times
@pytest.mark.parametrize("duration", [0.14974874371859298, 1.3437185929648243])
def test_point_at_the_final_time(duration: float) -> None:
    """``alpha * duration`` rounds above the last knot for these durations."""
    problem = SmoothingProblem(
        dim=1,
        degree=3,
        n_ctrl=6,
        duration=duration,
        boundary=(Boundary(0, [0.0]),),
        deviations=(PointDeviation([duration], [[1.0]], weight=10.0),),
        interpolation=(Interpolation([0.5 * duration, duration], [[0.5], [1.0]]),),
    )
    result = solve(problem)
    assert result.trajectory.evaluate(np.array([duration]))[0, 0] == pytest.approx(1.0, abs=1e-9)


def test_contradictory_equalities_in_closed_form_are_infeasible() -> None:
    from skyquill.errors import InfeasibleError

    problem = dataclasses.replace(
        boundary_only(), interpolation=(Interpolation([0.0], [[5.0, 0.0]]),)
    )
    with pytest.raises(InfeasibleError, match="contradict") as info:
        solve(problem)
    assert info.value.families == ("equalities",)


def test_accel_gain_is_the_least_squares_fit_of_p_plus_c_a() -> None:
    """The deviation of ``p(t_i) + c a(t_i)`` with gains per axis: the engine's optimum is
    the dense least-squares solution built here from the basis rows directly."""
    rng = np.random.default_rng(3)
    n, M, k = 30, 14, 5
    times = np.sort(rng.uniform(0.0, 3.0, n))
    times[0], times[-1] = 0.0, 3.0
    pts = rng.normal(0.0, 0.2, (n, 3))
    gain = np.array([-0.03, -0.03, 0.0])
    problem = SmoothingProblem(
        3, k, M, 3.0, smoothness={3: 1e-4}, deviations=(PointDeviation(times, pts, 1.0, gain),)
    )
    got = solve(problem).trajectory
    basis, alpha = problem.basis, problem.alpha
    B0 = basis.design_matrix(alpha * times, 0).toarray()
    B2 = basis.design_matrix(alpha * times, 2).toarray() * alpha**2
    gram = 1e-4 * alpha**5 * basis.gram(3).toarray()
    for axis in range(3):
        rows = B0 + gain[axis] * B2
        expected = np.linalg.solve(gram + rows.T @ rows, rows.T @ pts[:, axis])
        assert np.allclose(got.control_points[:, axis], expected, rtol=1e-7, atol=1e-9)
    tip = got.evaluate(times) + gain * got.evaluate(times, 2)
    residual = float(np.sum((tip - pts) ** 2))
    assert got.duration == 3.0
    assert problem_cost(problem, got.control_points)["deviation"] == pytest.approx(residual)
