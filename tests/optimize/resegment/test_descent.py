"""The re-segmentation descent: monotone, keeps or prices the total time, validates."""

from __future__ import annotations

from typing import Literal

import numpy as np
import pytest
from resegment_cases import limited_spiral, spiral

from skyquill.errors import InputError
from skyquill.optimize import solve
from skyquill.optimize.resegment import point_fit_factory, resegment, time_gradient
from skyquill.optimize.workspace import Workspace


# ------------------------------------------------------------------ descent
@pytest.mark.parametrize("step_rule", ["bb", "double", "lbfgs"])
def test_fixed_mode_descends_monotonically_and_keeps_total_time(
    step_rule: Literal["bb", "double", "lbfgs"],
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


def test_lbfgs_keeps_frozen_segments_and_converges_in_fewer_steps_than_bb() -> None:
    pts, times = spiral(30)
    make = point_fit_factory(pts, 22)
    frozen = np.zeros(29, dtype=bool)
    frozen[:3] = frozen[-2:] = True
    runs = {
        rule: resegment(pts, times, make, max_iter=300, step_rule=rule, frozen=frozen)
        for rule in ("bb", "lbfgs")
    }
    for out in runs.values():
        assert out.status == "converged"
        assert np.all(np.diff(out.history) <= 0.0)
        np.testing.assert_allclose(np.diff(out.times)[frozen], np.diff(times)[frozen], atol=1e-12)
        assert abs(out.total_time - times[-1]) <= 1e-12 * times[-1]
    bb, lbfgs = runs["bb"], runs["lbfgs"]
    assert lbfgs.cost == pytest.approx(bb.cost, rel=1e-6)
    assert lbfgs.n_solves < bb.n_solves
    # Step for step it is at least as far down (the spiral: 515.11 against 515.16 at 6).
    short = {r: resegment(pts, times, make, max_iter=6, step_rule=r, frozen=frozen) for r in runs}
    assert short["lbfgs"].cost <= short["bb"].cost


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


def test_the_callers_solve_is_the_first_iterate_instead_of_a_second_solve() -> None:
    pts, times, make = limited_spiral(24, 18, 8)
    again = resegment(pts, times, make, mode="fixed", max_iter=4)
    first = solve(make(times))
    given = resegment(pts, times, make, mode="fixed", max_iter=4, initial_result=first)
    assert given.n_solves == again.n_solves - 1
    assert given.history[0] == first.cost
    assert np.allclose(given.times, again.times, rtol=1e-8, atol=0.0)
    a, b = again.result.trajectory.control_points, given.result.trajectory.control_points
    assert np.abs(a - b).max() <= 1e-8 * np.abs(a).max()


def test_a_solve_at_other_times_is_not_taken_as_the_first_iterate() -> None:
    pts, times = spiral(12)
    make = point_fit_factory(pts, 16)
    other = solve(make(times * np.linspace(1.0, 1.2, times.size) * times[-1] / (1.2 * times[-1])))
    with pytest.raises(InputError, match="initial_result: got a solve whose point times"):
        resegment(pts, times, make, initial_result=other)
    with pytest.raises(InputError, match="make_problem: got duration"):
        resegment(pts, times, make, initial_result=solve(make(2.0 * times)))


def test_a_callers_workspace_carries_its_setup_into_the_run() -> None:
    pts, times, make = limited_spiral(24, 18, 8)
    workspace = Workspace()
    first = solve(make(times), workspace=workspace)
    own = resegment(pts, times, make, mode="fixed", max_iter=4, initial_result=first)
    shared = resegment(
        pts, times, make, mode="fixed", max_iter=4, initial_result=first, workspace=workspace
    )
    assert workspace.assembly.hits >= shared.n_solves  # every solve re-used the blocks
    a, b = own.result.trajectory.control_points, shared.result.trajectory.control_points
    assert np.abs(a - b).max() <= 1e-8 * np.abs(a).max()


def test_interior_descent_never_solves_a_conic_program(monkeypatch: pytest.MonkeyPatch) -> None:
    """With ``interior=True`` and nothing binding at the start, every trial is the closed
    form (a trial where a limit would bind is rejected unsolved): no conic program is
    solved, the cost still falls, and the result meets the limits."""
    import importlib

    from skyquill.limits import vehicle_limits

    solve_module = importlib.import_module("skyquill.optimize.solve")
    pts, times = spiral(24)
    free = solve(point_fit_factory(pts, 18)(times)).trajectory.sample(500.0)
    peaks = (float(np.abs(x).max()) for x in (free.v, free.a, free.j))
    limits = vehicle_limits(2, *(10.0 * p for p in peaks), None)  # the hull is looser
    make = point_fit_factory(pts, 18, limits=limits)
    first = solve(make(times), workspace=Workspace())
    assert first.method == "closed_form"
    calls: list[int] = []
    original = solve_module._solve_qp

    def counting(*args: object, **kwargs: object) -> object:
        calls.append(1)
        return original(*args, **kwargs)

    monkeypatch.setattr(solve_module, "_solve_qp", counting)
    out = resegment(pts, times, make, interior=True, max_iter=10)
    assert calls == []
    assert out.result.method == "closed_form"
    assert out.cost <= first.cost
    assert out.result.verification.max_excess <= 1e-9


def test_frozen_segments_keep_their_durations_and_the_rest_descends() -> None:
    """A descent with some segments frozen moves time among the others only, keeps the
    total, and still lowers the cost; every segment frozen: nothing moves."""
    rng = np.random.default_rng(4)
    points = np.cumsum(rng.normal(0.0, 0.3, (12, 2)), axis=0)
    times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.5, 1.5, 11))])
    make = point_fit_factory(points, 20)
    frozen = np.zeros(11, dtype=bool)
    frozen[:3] = frozen[-2:] = True
    out = resegment(points, times, make, mode="fixed", max_iter=6, frozen=frozen)
    np.testing.assert_allclose(np.diff(out.times)[frozen], np.diff(times)[frozen], rtol=1e-9)
    assert out.times[-1] == times[-1]
    assert out.history[-1] < out.history[0]
    still = resegment(points, times, make, mode="fixed", frozen=np.ones(11, dtype=bool))
    np.testing.assert_allclose(still.times, times, rtol=0, atol=1e-12)
