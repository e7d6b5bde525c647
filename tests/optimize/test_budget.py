"""The upload budget of a fit: one upload, or chunks flown rest to rest with hovers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from skyquill.errors import InfeasibleError
from skyquill.io.points import read_points_csv
from skyquill.optimize import budget
from skyquill.optimize.budget import _split_point
from skyquill.optimize.fit import FitOptions, fit_points
from skyquill.targets import CRAZYFLIE, is_hover, plan_uploads
from skyquill.trajectory import RestToRestSequence, Trajectory
from skyquill.verify import verify

EXAMPLES = Path(__file__).parents[2] / "examples"


def assert_flies_on_a_crazyflie(traj: Trajectory) -> None:
    """Every upload at most 31 pieces of degree <= 7, at rest (1e-6) where uploads change."""
    uploads = plan_uploads(traj, CRAZYFLIE)  # refuses a part beyond the budget
    assert all(u.pieces <= CRAZYFLIE.max_pieces for u in uploads)
    for u in uploads:
        for order in (1, 2):
            ends = traj.evaluate(np.array([u.start_s, u.end_s]), order)
            assert np.abs(ends).max() <= 1e-6


def test_a_long_spiral_is_split_into_uploads_within_the_tolerance() -> None:
    points, _ = read_points_csv(EXAMPLES / "spiral.csv")
    fit = fit_points(points, None, FitOptions(target=CRAZYFLIE, tolerance_m=0.005))
    assert fit.budget is not None and fit.budget.strategy == "split"
    traj = fit.trajectory
    assert isinstance(traj, RestToRestSequence)
    assert_flies_on_a_crazyflie(traj)
    uploads = fit.budget.uploads
    assert len(uploads) >= 2 and len(uploads) == len(fit.budget.chunks)
    assert [u.hover_before_s for u in uploads] == [0.0] + [CRAZYFLIE.hover_s] * (len(uploads) - 1)
    assert all(is_hover(p) for p in traj.pieces[1::2])
    assert all(c.result.trajectory.degree == 7 for c in fit.budget.chunks)
    # Independent check: the delivered sequence sampled densely, and every point at its time.
    check = verify(traj, fit.limits)
    assert check.max_excess <= 1e-9 and fit.verification.max_excess <= 1e-9
    err = np.linalg.norm(traj.evaluate(fit.times) - points, axis=1)
    assert err.max() <= 0.005 and err.max() == pytest.approx(fit.max_deviation_m)


def test_too_many_uploads_are_refused_with_what_would_fit(monkeypatch: pytest.MonkeyPatch) -> None:
    points, _ = read_points_csv(EXAMPLES / "spiral.csv")
    monkeypatch.setattr(budget, "MAX_UPLOADS", 1)  # the spiral needs 2 at 5 mm
    with pytest.raises(
        InfeasibleError,
        match=r"target: the 3\.683 m path needs more than 1 uploads of 31 pieces within 5 mm, "
        r"expected at most 1; no part of it fitted in one upload yet, so less than 1\.84 m would",
    ):
        fit_points(points, None, FitOptions(target=CRAZYFLIE, tolerance_m=0.005))


def test_the_split_falls_at_the_slowest_point_of_the_middle_third() -> None:
    arc = np.linspace(0.0, 9.0, 10)
    times = np.cumsum(np.ones(10)) - 1.0
    times[5:] += 2.0  # slow from point 4 to point 6: point 5 is the slowest
    times[6:] += 2.0
    assert _split_point(arc, times) == 5
    # Too few points inside the middle third: the one nearest the middle.
    assert _split_point(np.array([0.0, 0.1, 9.9, 10.0]), np.arange(4.0)) in (1, 2)
