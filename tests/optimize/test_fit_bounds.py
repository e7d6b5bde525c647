"""``fit_points``: bounded work, and a fit off the points is not a success."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from skyquill.errors import InfeasibleError, InputError
from skyquill.io.points import read_points_csv
from skyquill.limits import VehicleLimits
from skyquill.optimize.fit import (
    GIVEN_TOLERANCE_FRACTION,
    MAX_POINTS,
    FitOptions,
    default_tolerance,
    fit_points,
)

EXAMPLES = Path(__file__).parents[2] / "examples"
FAST = VehicleLimits(1000.0, 1000.0, 10.0)  # speed and acceleration the jerk cannot follow


def test_a_fit_that_cuts_the_spiral_is_refused_with_the_measured_number() -> None:
    points, _ = read_points_csv(EXAMPLES / "spiral.csv")
    message = (
        r"^tolerance_m: the fit is \d+(\.\d+)? mm from the points at most, expected at most "
        r"10\.79 mm; slower timing \(a lower vmax\), looser amax/jmax, a shorter knot_interval "
        r"\(more knots\), a larger tolerance_m or best_effort would help$"
    )
    with pytest.raises(InfeasibleError, match=message) as caught:
        fit_points(points, options=FitOptions(limits=FAST))
    assert caught.value.families == ("fidelity",)


def test_best_effort_returns_the_unfaithful_fit_with_its_deviation() -> None:
    points, _ = read_points_csv(EXAMPLES / "spiral.csv")
    fit = fit_points(points, options=FitOptions(limits=FAST, best_effort=True))
    assert fit.max_deviation_m > 0.1
    assert fit.accel_fraction == pytest.approx(0.5 / 2**3)  # every slowdown was tried


def test_an_explicit_tolerance_replaces_the_default() -> None:
    points, _ = read_points_csv(EXAMPLES / "spiral.csv")
    fit = fit_points(points, options=FitOptions(tolerance_m=2.0, limits=FAST))
    assert fit.max_deviation_m <= 2.0
    with pytest.raises(InfeasibleError, match=r"expected at most 0\.1 mm"):
        fit_points(points, options=FitOptions(tolerance_m=1e-4))


def test_given_tablet_times_keep_the_looser_default() -> None:
    # The tablet's clock is faster than the default limits: the fit lags its clock
    # (74 mm RMS) but keeps the drawing; the default for given times allows it.
    points, times = read_points_csv(EXAMPLES / "spiral.csv")
    fit = fit_points(points, times)
    assert fit.rms_deviation_m == pytest.approx(0.074, abs=0.002)
    assert fit.max_deviation_m <= default_tolerance(points, given_times=True)
    assert fit.accel_fraction is None
    diagonal = np.linalg.norm(np.ptp(points, axis=0))
    assert default_tolerance(points, True) == pytest.approx(GIVEN_TOLERANCE_FRACTION * diagonal)


def test_sharp_waypoints_are_retimed_slower_until_faithful() -> None:
    points, _ = read_points_csv(EXAMPLES / "segments.csv")
    fit = fit_points(points, options=FitOptions(limits=VehicleLimits(1.5, 1.0, 4.0)))
    assert fit.accel_fraction == pytest.approx(0.25)
    assert fit.max_deviation_m <= 0.01 * np.linalg.norm(np.ptp(points, axis=0))


def test_too_many_points_are_refused_before_timing() -> None:
    points = np.zeros((MAX_POINTS + 1, 2))  # 3 MB: the refusal comes before any QP
    with pytest.raises(InputError, match=r"^points: got 200,001 points, expected at most 200,000"):
        fit_points(points)


def test_a_long_plan_is_refused_before_assembly() -> None:
    points = np.array([[0.0, 0.0], [1.0, 0.0]])
    with pytest.raises(InputError, match=r"knot_interval: got 0\.1 s for a 1e\+06 s plan"):
        fit_points(points, np.array([0.0, 1e6]))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"tolerance_m": 0.0}, "tolerance_m: got 0, expected a number > 0"),
        ({"tolerance_m": float("nan")}, "tolerance_m: got nan, expected a finite number"),
        ({"best_effort": 1}, "best_effort: got 1, expected True or False"),
        ({"max_stretches": 51}, "max_stretches: got 51, expected an integer from 0 to 50"),
    ],
)
def test_fidelity_options_are_checked(kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(InputError, match=message):
        FitOptions(**kwargs)  # type: ignore[arg-type]
