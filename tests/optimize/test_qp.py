"""The QP route: limits, corridors, two backends, hull kinds, infeasibility, margins.

Random problems are made feasible *by construction*: a witness trajectory
(the boundary-only minimum-jerk solution, a straight rest-to-rest move)
is computed first, and every limit and corridor is chosen so that the
witness's B-spline hull points satisfy it with slack (the Bézier hull is
inside the B-spline hull, so the witness is feasible for both kinds). Limits
are then set to 0.6-0.9 of the unconstrained optimum's dense maxima whenever
that is still above the witness, so they are active.
"""

from __future__ import annotations

import dataclasses
import itertools
from dataclasses import dataclass, replace

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray

from skyquill.errors import InfeasibleError
from skyquill.limits import BoxLimit, CylinderLimit, DerivativeLimit
from skyquill.optimize import (
    Boundary,
    Corridor,
    FitResult,
    Interpolation,
    PointDeviation,
    SmoothingProblem,
    solve,
)
from skyquill.optimize.assemble import assemble
from skyquill.spline import basis_for

Array = NDArray[np.float64]
BACKENDS = ["clarabel", "piqp", "osqp"]

SETTINGS = settings(
    max_examples=25,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
    derandomize=True,
)


# ------------------------------------------------------------------ factories
@dataclass(frozen=True)
class Spec:
    """Structure of a random problem; the numbers come from ``seed``."""

    dim: int
    degree: int
    n_ctrl: int
    seed: int


specs = st.builds(
    Spec,
    dim=st.integers(2, 3),
    degree=st.integers(3, 6),
    n_ctrl=st.integers(8, 30),
    seed=st.integers(0, 2**32 - 1),
)


def base_problem(spec: Spec) -> SmoothingProblem:
    """Rest to rest with random point deviations; no inequalities."""
    rng = np.random.default_rng(spec.seed)
    d = spec.dim
    duration = float(rng.uniform(2.0, 6.0))
    n_pts = int(rng.integers(3, 9))
    times = np.sort(rng.uniform(0.05, 0.95, n_pts)) * duration
    points = rng.uniform(-1.0, 1.0, (n_pts, d))
    start, end = rng.uniform(-0.5, 0.5, d), rng.uniform(-0.5, 0.5, d)
    return SmoothingProblem(
        dim=d,
        degree=spec.degree,
        n_ctrl=spec.n_ctrl,
        duration=duration,
        boundary=Boundary.rest(start, end, min(3, spec.degree)),
        deviations=(PointDeviation(times, points, weight=float(rng.uniform(1.0, 100.0))),),
    )


def witness(problem: SmoothingProblem) -> Array:
    """Control points of a trajectory that meets the boundary conditions, (M, d)."""
    bare = dataclasses.replace(problem, deviations=(), limits=(), corridors=())
    return solve(bare).trajectory.control_points


def hull_points(problem: SmoothingProblem, C: Array, order: int) -> Array:
    """B-spline hull points of derivative ``order`` in SI units, (P, d)."""
    basis = basis_for(problem.degree, problem.n_ctrl)
    return np.asarray(problem.alpha**order * (basis.hull_map(order) @ C))


def dense_max(result: FitResult, order: int) -> Array:
    t = result.trajectory.dense_times()
    return np.abs(result.trajectory.evaluate(t, order)).max(axis=0)


def dense_hmax(result: FitResult, order: int) -> float:
    t = result.trajectory.dense_times()
    v = result.trajectory.evaluate(t, order)
    return float(np.hypot(v[:, 0], v[:, 1]).max())


def box_limits(
    problem: SmoothingProblem, free: FitResult, W: Array, fracs: Array
) -> tuple[DerivativeLimit, ...]:
    """Per-axis symmetric boxes on speed, acceleration and jerk."""
    out: list[DerivativeLimit] = []
    for order, frac in zip((1, 2, 3), fracs, strict=True):
        need = np.abs(hull_points(problem, W, order)).max(axis=0)
        bound = np.maximum(frac * dense_max(free, order), 1.05 * need + 1e-3)
        out.append(BoxLimit(order, -bound, bound))
    return tuple(out)


def cylinder_limits(
    problem: SmoothingProblem, free: FitResult, W: Array, fracs: Array, sides: int
) -> tuple[DerivativeLimit, ...]:
    """Horizontal ``sides``-gon (and vertical bounds in 3-D) on speed, acceleration, jerk."""
    out: list[DerivativeLimit] = []
    inradius = np.cos(np.pi / sides)
    for order, frac in zip((1, 2, 3), fracs, strict=True):
        H = hull_points(problem, W, order)
        need_r = float(np.hypot(H[:, 0], H[:, 1]).max()) / inradius
        r = max(frac * dense_hmax(free, order), 1.05 * need_r + 1e-3)
        z: dict[str, float] = {}
        if problem.dim == 3:
            zb = max(frac * float(dense_max(free, order)[2]), 1.05 * float(np.abs(H[:, 2]).max()))
            z = {"z_lower": -zb - 1e-3, "z_upper": zb + 1e-3}
        out.append(CylinderLimit(order, r, sides=sides, **z))
    return tuple(out)


def box_corridors(problem: SmoothingProblem, W: Array, n_windows: int) -> tuple[Corridor, ...]:
    """Axis-aligned boxes around the witness on consecutive windows.

    Each box holds the witness's control points active on its window (so the
    witness is inside: convex hull) plus 5 cm.
    """
    edges = np.linspace(0.0, problem.duration, n_windows + 1)
    basis = basis_for(problem.degree, problem.n_ctrl)
    eye = np.eye(problem.dim)
    out = []
    for t0, t1 in itertools.pairwise(edges):
        first, last = basis.spans_in_window(problem.alpha * t0, problem.alpha * t1)
        pts = W[first : last + problem.degree + 1]
        hi, lo = pts.max(axis=0) + 0.05, pts.min(axis=0) - 0.05
        out.append(Corridor(np.vstack([eye, -eye]), np.concatenate([hi, -lo]), t0, t1))
    return tuple(out)


def constrained(
    spec: Spec, kind: str, hull: str = "bspline", corridors: bool = False
) -> SmoothingProblem:
    """A random feasible problem; ``kind`` is "box", "cyl6", "cyl8" or "none"."""
    rng = np.random.default_rng(spec.seed + 1)
    problem = base_problem(spec)
    free = solve(problem)
    W = witness(problem)
    fracs = rng.uniform(0.6, 0.9, 3)
    limits: tuple[DerivativeLimit, ...] = ()
    if kind == "box":
        limits = box_limits(problem, free, W, fracs)
    elif kind.startswith("cyl"):
        limits = cylinder_limits(problem, free, W, fracs, int(kind[3:]))
    regions = box_corridors(problem, W, int(rng.integers(1, 4))) if corridors else ()
    return dataclasses.replace(problem, limits=limits, corridors=regions, hull=hull)  # type: ignore[arg-type]


def scale_of(C: Array) -> float:
    return max(1.0, float(np.abs(C).max()))


# ------------------------------------------------------------------ two backends
@SETTINGS
@given(spec=specs, kind=st.sampled_from(["box", "cyl6", "cyl8"]), corridors=st.booleans())
def test_clarabel_and_piqp_agree(spec: Spec, kind: str, corridors: bool) -> None:
    problem = constrained(spec, kind, corridors=corridors)
    a = solve(problem, "clarabel")
    b = solve(problem, "piqp")
    assert a.method == b.method == "qp"
    assert a.cost == pytest.approx(b.cost, rel=1e-6)
    Ca, Cb = a.trajectory.control_points, b.trajectory.control_points
    assert float(np.abs(Ca - Cb).max()) <= 1e-5 * scale_of(Ca)


# ------------------------------------------------------------------ guarantees
@SETTINGS
@given(
    spec=specs,
    kind=st.sampled_from(["box", "cyl6", "cyl8", "none"]),
    corridors=st.booleans(),
    hull=st.sampled_from(["bspline", "bezier"]),
)
def test_limits_and_corridors_hold_densely(
    spec: Spec, kind: str, corridors: bool, hull: str
) -> None:
    problem = constrained(spec, kind, hull=hull, corridors=corridors or kind == "none")
    result = solve(problem)
    assert result.method == "qp"
    check = result.verification
    assert check.max_excess <= 1e-9, check.checks
    assert check.corridor_excess_m <= 1e-9
    assert len(check.checks) == len(problem.limits)
    assert all(c.guaranteed for c in check.checks)
    assert result.margin > 0.0


@SETTINGS
@given(spec=specs, kind=st.sampled_from(["box", "cyl6", "cyl8"]), corridors=st.booleans())
def test_bezier_hull_is_never_costlier(spec: Spec, kind: str, corridors: bool) -> None:
    """The Bézier hull is inside the B-spline hull: a looser constraint, a lower cost."""
    bspline = constrained(spec, kind, hull="bspline", corridors=corridors)
    bezier = dataclasses.replace(bspline, hull="bezier")
    c_bspline = solve(bspline).cost
    c_bezier = solve(bezier).cost
    assert c_bezier <= c_bspline * (1.0 + 1e-9)


def test_limits_are_active_and_tightening_changes_the_answer() -> None:
    """A sanity check on the factory: the limits it makes bind."""
    spec = Spec(dim=2, degree=5, n_ctrl=20, seed=4)
    free = solve(base_problem(spec))
    problem = constrained(spec, "box")
    result = solve(problem)
    assert result.cost > free.cost * (1.0 + 1e-6)
    assert result.verification.max_excess <= 1e-9


# ------------------------------------------------------------------ infeasibility
def rest_problem(**kwargs: object) -> SmoothingProblem:
    args: dict[str, object] = {
        "dim": 2,
        "degree": 5,
        "n_ctrl": 12,
        "duration": 1.0,
        "boundary": Boundary.rest(np.zeros(2), np.ones(2), 3),
    }
    args.update(kwargs)
    return SmoothingProblem(**args)  # type: ignore[arg-type]


@pytest.mark.parametrize("backend", ["clarabel", "piqp"])
@pytest.mark.parametrize("coupled", [False, True])
def test_jerk_limit_too_small_is_infeasible(backend: str, coupled: bool) -> None:
    # Rest to rest over 1 m in 1 s needs a peak jerk of at least 32 m/s^3.
    lim: DerivativeLimit = (
        CylinderLimit(3, 1.0, sides=8) if coupled else BoxLimit.symmetric(3, 1.0, 2)
    )
    with pytest.raises(InfeasibleError, match="jerk") as info:
        solve(rest_problem(limits=(lim,)), backend)
    assert len(info.value.families) == 1
    assert "jerk" in info.value.families[0]


@pytest.mark.parametrize("backend", ["clarabel", "piqp"])
def test_corridor_excluding_the_start_is_infeasible(backend: str) -> None:
    eye = np.eye(2)
    cor = Corridor(np.vstack([eye, -eye]), [2.0, 2.0, -0.5, -0.5], 0.0, 0.4)
    ok = Corridor(np.vstack([eye, -eye]), [2.0, 2.0, 1.0, 1.0], 0.4, 1.0)
    with pytest.raises(InfeasibleError, match=r"corridor\[0\]") as info:
        solve(rest_problem(duration=2.0, corridors=(cor, ok)), backend)
    assert len(info.value.families) == 1
    assert info.value.families[0].startswith("corridor[0]")


@pytest.mark.parametrize("backend", ["clarabel", "piqp"])
@pytest.mark.parametrize("with_limit", [False, True])
def test_contradictory_equalities_are_infeasible(backend: str, with_limit: bool) -> None:
    limits = (BoxLimit.symmetric(1, 100.0, 2),) if with_limit else ()
    problem = rest_problem(
        duration=3.0,
        limits=limits,
        interpolation=(Interpolation([0.0, 1.5], [[0.3, 0.0], [0.5, 0.5]]),),
    )
    with pytest.raises(InfeasibleError, match="contradict") as info:
        solve(problem, backend)
    assert info.value.families == ("equalities",)


def test_redundant_consistent_equalities_solve_on_both_routes() -> None:
    interp = Interpolation([0.0, 1.5, 3.0], [[0.0, 0.0], [0.8, -0.2], [1.0, 1.0]])
    closed = solve(rest_problem(duration=3.0, interpolation=(interp,)))
    qp = solve(
        rest_problem(duration=3.0, interpolation=(interp,), limits=(BoxLimit.symmetric(1, 1e6, 2),))
    )
    assert closed.method == "closed_form"
    assert qp.method == "qp"
    assert qp.cost == pytest.approx(closed.cost, rel=1e-8)


# ------------------------------------------------------------------ margin loop
def test_margin_is_reported() -> None:
    spec = Spec(dim=3, degree=4, n_ctrl=16, seed=11)
    qp = solve(constrained(spec, "cyl8", corridors=True))
    closed = solve(base_problem(spec))
    assert qp.method == "qp"
    assert 0.0 < qp.margin <= 1e-5
    assert closed.margin == 0.0
    assert qp.n_inequalities > 0
    assert closed.n_inequalities == 0
    assert qp.n_variables == spec.n_ctrl * spec.dim


def test_input_limit_of_a_chain_of_integrators_holds() -> None:
    """Paper 003 §3.8: the input of a 4th-order chain is snap; limit it like any derivative."""
    from skyquill.limits import BoxLimit
    from skyquill.optimize import Boundary, PointDeviation, SmoothingProblem, solve

    t = np.linspace(0.0, 4.0, 80)
    points = np.column_stack([np.sin(t), np.cos(2 * t)])
    free = SmoothingProblem(
        2,
        6,
        30,
        4.0,
        smoothness={4: 1.0},
        deviations=(PointDeviation(t, points, 1e3),),
        boundary=Boundary.rest(points[0], points[-1], 4),
    )
    snap_free = np.abs(solve(free).trajectory.evaluate(t, 4)).max()
    limit = BoxLimit.symmetric(4, 0.5 * snap_free, 2)
    result = solve(replace(free, limits=(limit,)))
    snap = result.trajectory.evaluate(result.trajectory.dense_times(), 4)
    assert np.abs(snap).max() <= 0.5 * snap_free * (1 + 1e-9)
    assert result.verification.max_excess <= 1e-9
    assert result.trajectory.verify((limit,)).max_excess <= 1e-9


# ------------------------------------------------------------------ duals
def stationarity(result: FitResult) -> tuple[float, Array]:
    """Relative residual of ``2 H x + f + A_eq' y + G' z = 0`` and the slack of the
    QP that was solved (``h`` tightened by ``margin``, as in ``solve``)."""
    asm = assemble(result.problem)
    x = result.trajectory.control_points.ravel()
    A_eq = sp.kron(asm.E, sp.eye_array(result.problem.dim))
    quad, f = 2.0 * (asm.hessian() @ x), asm.linear()
    residual = quad + f + A_eq.T @ result.y + asm.G_ineq.T @ result.z
    size = max(float(np.linalg.norm(quad)), float(np.linalg.norm(f)), 1e-300)
    tightened = asm.h_ineq - result.margin * np.maximum(np.abs(asm.h_ineq), 1e-3)
    return float(np.linalg.norm(residual)) / size, tightened - asm.G_ineq @ x


@settings(max_examples=10, deadline=None, derandomize=True)
@given(spec=specs, kind=st.sampled_from(["box", "cyl8"]), backend=st.sampled_from(BACKENDS))
def test_result_keeps_the_duals_of_the_solved_qp(spec: Spec, kind: str, backend: str) -> None:
    """``FitResult.y``, ``.z`` satisfy the KKT conditions of the (tightened) QP whose
    minimiser is the returned trajectory."""
    result = solve(constrained(spec, kind), backend)
    assert result.y.shape == (result.n_equalities,)
    assert result.z.shape == (result.n_inequalities,)
    residual, slack = stationarity(result)
    assert residual <= 1e-6
    z_scale = max(float(np.abs(result.z).max(initial=0.0)), 1.0)
    assert result.z.min(initial=0.0) >= -1e-6 * z_scale
    assert float(np.abs(result.z * slack).max(initial=0.0)) <= 1e-6 * z_scale * scale_of(slack)
