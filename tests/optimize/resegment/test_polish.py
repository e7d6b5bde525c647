"""Polishing a QP solution: the exact minimiser on the active set of the solver's duals."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import scipy.sparse as sp
from resegment_cases import limited_random, limited_spiral

from skyquill.optimize import solve
from skyquill.optimize.assemble import assemble, problem_cost
from skyquill.optimize.resegment.polish import polish
from skyquill.optimize.solve import FitResult, _closed_form_kkt, _to_qp

CASES = ["spiral-box", "spiral-cylinder", "random-1", "random-2", "random-90"]


def limited_result(case: str) -> FitResult:
    """A solve with active limits: the spiral (PIQP) or a random problem (Clarabel)."""
    kind, detail = case.split("-")
    if kind == "spiral":
        _, times, make = limited_spiral(24, 18, None if detail == "box" else 8)
        return solve(make(times))
    times, make = limited_random(int(detail), 2, 0.66)
    return solve(make(times), "clarabel")


@pytest.mark.parametrize("case", CASES)
def test_polished_point_meets_the_kkt_conditions_exactly(case: str) -> None:
    result = limited_result(case)
    asm = assemble(result.problem)
    x0 = result.trajectory.control_points.ravel()
    out = polish(_to_qp(asm, result.margin), x0, result.z)
    assert out is not None
    A_eq = sp.kron(asm.E, sp.eye_array(result.problem.dim))
    quad, f = 2.0 * (asm.hessian() @ out.x), asm.linear()
    residual = quad + f + A_eq.T @ out.y + asm.G_ineq.T @ out.z
    assert np.linalg.norm(residual) <= 1e-12 * max(np.linalg.norm(quad), np.linalg.norm(f))
    scale = np.maximum(np.abs(asm.h_ineq), 1e-3)
    tightened = asm.h_ineq - result.margin * scale
    slack = (tightened - asm.G_ineq @ out.x) / scale
    assert slack.min() >= -1e-12
    assert out.z.min() >= 0.0
    assert np.all(slack[out.z > 0.0] <= 1e-12)
    # Close to the solver's point, and no costlier.
    assert np.abs(out.x - x0).max() <= 1e-5 * max(1.0, float(np.abs(x0).max()))
    cost = problem_cost(result.problem, out.x.reshape(x0.size // result.problem.dim, -1))
    assert cost["total"] <= result.cost * (1.0 + 1e-12)


def test_dependent_active_rows_give_no_polished_point() -> None:
    """Every active row twice: dependent rows, no LICQ, no polished point."""
    result = limited_result(CASES[0])
    qp = _to_qp(assemble(result.problem), result.margin)
    x0 = result.trajectory.control_points.ravel()
    twice = replace(qp, G=sp.csc_array(sp.vstack([qp.G, qp.G])), h=np.concatenate([qp.h, qp.h]))
    assert polish(qp, x0, result.z) is not None
    assert polish(twice, x0, np.concatenate([result.z, result.z])) is None


def test_only_tight_rows_are_held() -> None:
    """All multipliers ~0 (nothing active) and equal: a relative threshold alone would hold
    every row (more rows than unknowns); rows with slack at the solver's point are not held."""
    result = limited_result(CASES[0])
    qp = _to_qp(assemble(result.problem), result.margin)
    x0 = result.trajectory.control_points.ravel()
    assert qp.G.shape[0] > x0.size
    out = polish(qp, x0, np.full(qp.G.shape[0], 1e-12))
    assert out is not None
    assert np.count_nonzero(out.z) < x0.size


@pytest.mark.parametrize("loose", [True, False])
def test_the_per_axis_closed_form_polishes_as_the_full_kkt_solve(loose: bool) -> None:
    """Nothing held (loose limits): the closed form replaces the KKT solve, same point and
    duals; with active rows it is not used (the active set decides)."""
    _, times, make = limited_spiral(24, 18, None)
    problem = make(times)
    if loose:
        problem = replace(
            problem,
            limits=tuple(
                replace(lim, lower=10.0 * lim.lower, upper=10.0 * lim.upper)
                for lim in problem.limits
            ),
        )
    result = solve(problem)
    asm = assemble(problem)
    qp = _to_qp(asm, result.margin)
    x0 = result.trajectory.control_points.ravel()
    calls = []

    def per_axis() -> tuple[np.ndarray, np.ndarray]:
        calls.append(1)
        C, y = _closed_form_kkt(asm)
        return C.ravel(), y

    full = polish(qp, x0, result.z)
    fast = polish(qp, x0, result.z, equality_solve=per_axis)
    assert full is not None and fast is not None
    assert len(calls) == (1 if loose else 0)
    assert np.abs(fast.x - full.x).max() <= 1e-10 * np.abs(full.x).max()
    assert np.abs(fast.y - full.y).max() <= 1e-7 * np.abs(full.y).max()
    assert np.array_equal(fast.z > 0.0, full.z > 0.0)
