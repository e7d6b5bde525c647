"""A workspace re-uses assembly blocks and PIQP setups: the same solutions as fresh solves."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.typing import NDArray

from skyquill.limits import BoxLimit, NormLimit, vehicle_limits
from skyquill.optimize import SmoothingProblem, solve
from skyquill.optimize.resegment import point_fit_factory
from skyquill.optimize.solve import BANDED, FitResult
from skyquill.optimize.workspace import Workspace

Array = NDArray[np.float64]


def _points(n: int, seed: int) -> tuple[Array, Array]:
    rng = np.random.default_rng(seed)
    pts = np.cumsum(rng.normal(0.0, 0.3, (n, 3)), axis=0)
    times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.4, 1.2, n - 1))])
    return pts, times


def _same(fresh: FitResult, reused: FitResult, rtol: float = 1e-8) -> None:
    """The same minimiser to the backend's tolerance (1e-10 on the QP route)."""
    a, b = fresh.trajectory.control_points, reused.trajectory.control_points
    assert np.abs(a - b).max() <= rtol * np.abs(a).max()
    assert reused.cost == pytest.approx(fresh.cost, rel=rtol)
    assert reused.n_inequalities == fresh.n_inequalities
    assert reused.z.shape == fresh.z.shape
    if reused.method == "closed_form":  # nothing binds: all inequality multipliers 0
        assert not np.any(reused.z) and reused.solver in ("sparse-lu", BANDED)
        assert reused.verification.max_excess == 0.0
    else:
        assert (reused.method, reused.margin) == (fresh.method, fresh.margin)


# The limits: loose exact norms (the closed form meets them; fresh: the box
# relaxation, PIQP), per-axis boxes that bind (the linear QP, PIQP), no limits.
LIMITS = {
    "relaxed cones": lambda: vehicle_limits(3, 50.0, 200.0, 2000.0),
    "binding boxes": lambda: (BoxLimit.symmetric(2, 0.4, 3), BoxLimit.symmetric(3, 2.0, 3)),
    "none": lambda: (),
}


@pytest.mark.parametrize("kind", sorted(LIMITS))
def test_reused_solves_equal_fresh_solves_along_a_time_sequence(kind: str) -> None:
    pts, times = _points(12, 3)
    make = point_fit_factory(pts, 20, limits=LIMITS[kind]())
    workspace = Workspace()
    rng = np.random.default_rng(0)
    for k in range(4):
        # Moved times, the total kept: what a fixed-mode re-segmentation solves.
        T = np.diff(times) * rng.uniform(0.8, 1.2, times.size - 1)
        t = np.concatenate([[0.0], np.cumsum(T * times[-1] / T.sum())])
        t[-1] = times[-1]
        problem = make(t if k else times)
        fresh = solve(problem)
        _same(fresh, solve(problem, workspace=workspace))
        _same(fresh, solve(problem, workspace=workspace))  # the same problem twice
    # The times move, the rest stays: its blocks are built once for the whole sequence.
    assert workspace.assembly.builds == 1 and workspace.assembly.hits >= 7
    if kind == "binding boxes":
        (session,) = workspace.sessions.values()
        assert (session.setups, session.updates) == (1, 7)
    else:  # loose limits: the equality-only minimiser meets them, no QP at all
        assert not workspace.sessions


def test_the_first_problem_solved_again_after_others_is_unchanged() -> None:
    pts, times = _points(10, 5)
    make = point_fit_factory(pts, 18, limits=(BoxLimit.symmetric(2, 0.5, 3),))
    workspace = Workspace()
    first = solve(make(times), workspace=workspace)
    solve(make(times * np.linspace(1.0, 1.1, times.size)), workspace=workspace)
    _same(first, solve(make(times), workspace=workspace))


@pytest.mark.parametrize(
    "change",
    ["duration", "limit", "limit kind", "boundary"],
)
def test_a_problem_that_differs_in_a_reused_block_is_assembled_afresh(change: str) -> None:
    pts, times = _points(10, 7)
    base = dict(limits=(BoxLimit.symmetric(2, 0.6, 3),))
    workspace = Workspace()
    solve(point_fit_factory(pts, 18, **base)(times), workspace=workspace)
    if change == "duration":
        problem = point_fit_factory(pts, 18, **base)(1.3 * times)
    elif change == "limit":
        problem = point_fit_factory(pts, 18, limits=(BoxLimit.symmetric(2, 0.45, 3),))(times)
    elif change == "limit kind":
        problem = point_fit_factory(pts, 18, limits=(NormLimit(2, 0.6, sides=8),))(times)
    else:
        moved = pts.copy()
        moved[-1] += 0.2
        problem = point_fit_factory(moved, 18, **base)(times)
    _same(solve(problem), solve(problem, workspace=workspace))
    assert workspace.assembly.builds == 2  # the second problem's blocks built afresh


def test_the_workspace_hands_the_solved_assembly_to_the_gradient() -> None:
    pts, times = _points(8, 11)
    problem: SmoothingProblem = point_fit_factory(pts, 16)(times)
    workspace = Workspace()
    solve(problem, workspace=workspace)
    assert workspace.assemble(problem) is workspace.assemble(problem)


def test_loose_cones_that_bind_on_the_second_problem_go_to_the_qp() -> None:
    """The closed form first, then a problem where it breaks a limit: the QP decides."""
    pts, times = _points(12, 3)
    loose = solve(point_fit_factory(pts, 20)(times))
    peak = float(np.linalg.norm(loose.trajectory.sample(400.0).a, axis=1).max())
    workspace = Workspace()
    limits = (NormLimit(2, 2.0 * peak, dim=3),)
    first = solve(point_fit_factory(pts, 20, limits=limits)(times), workspace=workspace)
    faster = point_fit_factory(pts, 20, limits=limits)(0.5 * times)
    second = solve(faster, workspace=workspace)
    assert first.method == "closed_form"
    assert second.method == "qp"
    _same(solve(faster), second)
