"""The multipliers the gradient uses are the solve's duals, checked independently."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from resegment_cases import Spec, limited_spiral, random_problem

from skyquill.optimize import solve
from skyquill.optimize.assemble import assemble
from skyquill.optimize.resegment import finite_difference_gradient, time_gradient
from skyquill.optimize.resegment import multipliers as multipliers_module
from skyquill.optimize.resegment.multipliers import multipliers


@pytest.mark.parametrize("kind", ["interpolation", "moving_ends"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_closed_form_multipliers_solve_the_stationarity_condition(kind: str, seed: int) -> None:
    """Reference: ``E' Lambda = -grad J`` by dense least squares."""
    times, make = random_problem(Spec(kind, 2, 5, 6, 4, seed))
    result = solve(make(times))
    assert result.method == "closed_form"
    mult = multipliers(result)
    asm = assemble(result.problem)
    x = result.trajectory.control_points.ravel()
    E = sp.kron(asm.E, sp.eye_array(2)).toarray()
    grad = 2.0 * (asm.hessian() @ x) + asm.linear()
    reference = np.linalg.lstsq(E.T, -grad, rcond=None)[0].reshape(-1, 2)
    assert mult.lam.shape == reference.shape
    np.testing.assert_allclose(mult.lam, reference, rtol=1e-7, atol=1e-9 * np.abs(reference).max())
    assert mult.residual < 1e-10
    assert mult.cost == result.cost


def test_without_a_polished_point_the_solver_duals_are_used(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The fallback: the gradient from the backend's own point and duals, accurate to the
    backend's tolerance (the reason for the polish; module docstring of ``polish``)."""
    _, times, make = limited_spiral(24, 18, None)
    polished = time_gradient(times, make)
    monkeypatch.setattr(multipliers_module, "polish", lambda *args, **kwargs: None)
    raw = time_gradient(times, make)
    assert raw.polished_cost == raw.cost
    assert raw.stationarity_residual < 1e-8
    reference = finite_difference_gradient(times, make, step=1e-5)
    error = float(np.linalg.norm(raw.grad_segments - polished.grad_segments))
    assert error <= 1e-4 * float(np.linalg.norm(reference))
