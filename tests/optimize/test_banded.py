"""The banded closed form against the KKT system it replaces (an independent route)."""

from __future__ import annotations

import dataclasses

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.optimize import Boundary, PointDeviation, SmoothingProblem, solve
from skyquill.optimize.assemble import assemble
from skyquill.optimize.banded import banded_closed_form
from skyquill.optimize.solve import BANDED, _closed_form


def _problem(seed: int, degree: int, spans_per_s: float, gain: bool) -> SmoothingProblem:
    """Rest to rest through random points (a writing route in miniature), with or without
    the brush tip's acceleration gain on x and y."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(30, 300))
    times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.005, 0.05, n - 1))])
    points = np.cumsum(rng.normal(0.0, 0.01, (n, 3)), axis=0)
    c = np.array([-0.03, -0.03, 0.0]) if gain else None
    duration = float(times[-1])
    return SmoothingProblem(
        dim=3,
        degree=degree,
        n_ctrl=max(1, int(np.ceil(duration * spans_per_s))) + degree,
        duration=duration,
        smoothness={3: 1.0},
        deviations=(
            PointDeviation(times, points, 1e4, c),
            PointDeviation(times[::7], points[::7], 1e5, c),
        ),
        boundary=Boundary.rest(points[0], points[-1], 3),
    )


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    degree=st.integers(3, 7),
    spans_per_s=st.sampled_from([5.0, 20.0, 50.0]),
    gain=st.booleans(),
)
def test_the_banded_closed_form_is_the_kkt_solution(
    seed: int, degree: int, spans_per_s: float, gain: bool
) -> None:
    """Control points and equality multipliers equal the sparse LU of the KKT system's."""
    problem = _problem(seed, degree, spans_per_s, gain)
    banded = banded_closed_form(problem)
    assert banded is not None
    C, y = _closed_form(assemble(problem))
    assert np.abs(banded.C - C).max() <= 1e-8 * np.abs(C).max()
    assert np.abs(banded.y - y).max() <= 1e-6 * max(1.0, float(np.abs(y).max()))


def test_solve_takes_the_banded_route_and_reports_it() -> None:
    result = solve(_problem(1, 5, 20.0, True))
    assert (result.method, result.solver) == ("closed_form", BANDED)


def test_a_hessian_singular_but_for_the_boundary_goes_to_the_kkt_route() -> None:
    """Without deviations only the boundary pins the jerk cost's null space: the Schur
    complement would be meaningless, so the banded route declines and LU solves it."""
    bare = dataclasses.replace(_problem(2, 5, 20.0, False), deviations=())
    assert banded_closed_form(bare) is None
    result = solve(bare)
    assert result.solver == "sparse-lu"
    assert np.allclose(result.trajectory.evaluate(np.array([0.0, bare.duration])),
                       [bare.boundary[0].start, bare.boundary[0].end])  # fmt: skip


def test_other_forms_go_to_the_kkt_route() -> None:
    """Coupled costs (a line or plane term) and interpolated points are not banded here."""
    from skyquill.optimize import Interpolation

    problem = _problem(3, 5, 20.0, False)
    term = problem.deviations[0]
    assert isinstance(term, PointDeviation)
    pinned = dataclasses.replace(
        problem, interpolation=(Interpolation(term.times[5:6], term.points[5:6]),)
    )
    assert banded_closed_form(pinned) is None
    assert solve(pinned).solver == "sparse-lu"
