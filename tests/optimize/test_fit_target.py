"""fit_points with a target: one upload if it holds the points, else uploads with hovers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from skyquill.errors import InfeasibleError, InputError
from skyquill.io.points import read_points_csv
from skyquill.optimize.fit import FitOptions, default_tolerance, fit_points
from skyquill.targets import CRAZYFLIE, plan_uploads
from skyquill.trajectory import SplineTrajectory
from skyquill.verify import verify

EXAMPLES = Path(__file__).parents[2] / "examples"


def test_the_spiral_fits_one_upload_at_the_default_tolerance() -> None:
    points, _ = read_points_csv(EXAMPLES / "spiral.csv")
    fit = fit_points(points, None, FitOptions(target=CRAZYFLIE))
    assert fit.budget is not None and fit.budget.strategy == "one-upload"
    traj = fit.trajectory
    assert isinstance(traj, SplineTrajectory) and traj.degree == 7
    (upload,) = plan_uploads(traj, CRAZYFLIE)
    assert upload.pieces == CRAZYFLIE.max_pieces
    for order in (1, 2):
        ends = traj.evaluate(np.array([0.0, traj.duration]), order)
        assert np.abs(ends).max() <= 1e-6
    assert verify(traj, fit.limits).max_excess <= 1e-9
    assert fit.max_deviation_m <= default_tolerance(points, False)


def test_timed_points_in_one_upload_keep_their_clock() -> None:
    points, times = read_points_csv(EXAMPLES / "spiral.csv")
    assert times is not None
    fit = fit_points(points, times, FitOptions(target=CRAZYFLIE))
    assert fit.budget is not None and len(fit.budget.uploads) == 1
    assert fit.trajectory.duration == pytest.approx(times[-1] - times[0])
    assert fit.verification.max_excess <= 1e-9


def test_timed_points_that_need_more_uploads_are_refused_with_what_would_fit() -> None:
    points, times = read_points_csv(EXAMPLES / "spiral.csv")
    with pytest.raises(
        InfeasibleError,
        match=r"one crazyflie upload \(31 pieces\) at the given times is .* mm from the points "
        r"at most, expected at most 50 mm; more uploads would change the given timing\. "
        r"A tolerance_m of 0\.\d+ m, or the points without their times \(1 upload\) would fit",
    ):
        fit_points(points, times, FitOptions(target=CRAZYFLIE, tolerance_m=0.05))


def test_timed_points_with_best_effort_get_the_one_upload() -> None:
    points, times = read_points_csv(EXAMPLES / "spiral.csv")
    options = FitOptions(target=CRAZYFLIE, tolerance_m=0.05, best_effort=True)
    fit = fit_points(points, times, options)
    assert fit.max_deviation_m > 0.05 and len(plan_uploads(fit.trajectory, CRAZYFLIE)) == 1


def test_without_a_target_the_fit_is_unchanged() -> None:
    points, _ = read_points_csv(EXAMPLES / "spiral.csv")
    fit = fit_points(points, None, FitOptions())
    assert fit.budget is None and fit.trajectory is fit.result.trajectory
    assert fit.result.trajectory.degree == 5


def test_a_target_must_be_an_upload_target() -> None:
    with pytest.raises(InputError, match=r"target: got str, expected an UploadTarget or None"):
        FitOptions(target="crazyflie")  # type: ignore[arg-type]
