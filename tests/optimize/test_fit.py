"""The point-fit pipeline behind ``skyquill fit``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from skyquill.errors import InputError, SkyquillError
from skyquill.io.points import read_points_csv
from skyquill.limits import VehicleLimits
from skyquill.optimize.fit import FitOptions, fit_points

EXAMPLES = Path(__file__).parents[2] / "examples"


def test_spiral_fit_is_faithful_and_within_limits() -> None:
    points, _ = read_points_csv(EXAMPLES / "spiral.csv")
    fit = fit_points(points)
    check = fit.result.verification
    assert check.max_excess <= 1e-9
    assert fit.rms_deviation_m < 0.005
    traj = fit.result.trajectory
    ends = traj.evaluate(np.array([0.0, traj.duration]))
    assert np.allclose(ends, points[[0, -1]], atol=1e-9)
    rest = traj.evaluate(np.array([0.0, traj.duration]), 1)
    assert np.allclose(rest, 0.0, atol=1e-9)


def test_polytope_norms_hold_on_the_norm() -> None:
    points, _ = read_points_csv(EXAMPLES / "segments.csv")
    limits = VehicleLimits(vmax=1.5, amax=1.0, jmax=3.0)
    fit = fit_points(points, options=FitOptions(limits=limits, norm_sides=8))
    traj = fit.result.trajectory
    t = traj.dense_times()
    for order, bound in ((1, 1.5), (2, 1.0), (3, 3.0)):
        d = traj.evaluate(t, order)
        assert np.linalg.norm(d, axis=1).max() <= bound * (1 + 1e-9)


def test_given_times_too_fast_are_stretched_and_reported() -> None:
    line = np.column_stack([np.linspace(0, 2.0, 21), np.zeros(21)])
    fit = fit_points(
        line, np.linspace(0, 0.5, 21), FitOptions(limits=VehicleLimits(1.0, 2.0, 10.0))
    )
    assert fit.time_scale > 1.0
    assert fit.result.verification.max_excess <= 1e-9
    assert fit.times[-1] == pytest.approx(0.5 * fit.time_scale)


@pytest.mark.parametrize(
    ("points", "times", "message"),
    [
        (np.zeros((5, 4)), None, r"points: got shape \(5, 4\), expected \(N >= 2, 2 or 3\)"),
        (np.zeros((1, 2)), None, r"points: got shape \(1, 2\)"),
        (np.eye(3)[:, :2], np.array([0.0, 1.0, 1.0]), "times: got times\\[1\\] = 1"),
        (np.eye(3)[:, :2], np.array([0.0, 1.0]), r"times: got an array of shape \(2,\)"),
        (np.array([[0.0, 0.0], [np.inf, 1.0]]), None, "points: got 1 NaN or infinite"),
    ],
)
def test_bad_points_are_named(points: np.ndarray, times: np.ndarray | None, message: str) -> None:
    with pytest.raises(InputError, match=message):
        fit_points(points, times)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"degree": 8}, "degree: got 8, expected an integer from 3 to 7"),
        ({"norm_sides": 2}, "norm_sides: got 2, expected an integer from 3 to 1024"),
        ({"weight": float("nan")}, "weight: got nan, expected a finite number"),
    ],
)
def test_bad_options_are_named(kwargs: dict[str, float], message: str) -> None:
    with pytest.raises(InputError, match=message):
        FitOptions(**kwargs)  # type: ignore[arg-type]


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    hnp.arrays(
        np.float64,
        st.tuples(st.integers(0, 12), st.sampled_from([1, 2, 3, 4])),
        # Small drawings, specials and absurd magnitudes: mid-size plans are
        # valid but slow, and the other tests cover them.
        elements=st.one_of(
            st.floats(-5, 5),
            st.sampled_from([np.nan, np.inf, -np.inf, 0.0]),
            st.floats(1e7, 1e300),
        ),
    )
)
def test_hostile_points_give_input_errors_or_verified_fits(points: np.ndarray) -> None:
    try:
        fit = fit_points(points, options=FitOptions(max_stretches=2))
    except SkyquillError as exc:
        assert str(exc)
        return
    assert fit.result.verification.max_excess <= 1e-9


@pytest.mark.parametrize("sides", [None, 16])
def test_vehicle_norms_hold_on_dense_samples(sides: int | None) -> None:
    """Speed, acceleration and jerk *norms* (3-D), cones or inscribed globe."""
    s = np.linspace(0.0, 1.0, 200)
    points = np.column_stack([np.cos(4 * s), np.sin(4 * s), 1.5 * s])
    vehicle = VehicleLimits(vmax=1.0, amax=1.0, jmax=3.0)
    fit = fit_points(points, options=FitOptions(limits=vehicle, norm_sides=sides))
    assert (fit.result.n_cones > 0) == (sides is None)
    assert fit.result.verification.max_excess <= 1e-9
    traj = fit.result.trajectory
    t = np.linspace(0.0, traj.duration, 20_000)
    for order, bound in ((1, 1.0), (2, 1.0), (3, 3.0)):
        assert np.linalg.norm(traj.evaluate(t, order), axis=1).max() <= bound * (1 + 1e-9)
    labels = [c.label for c in fit.result.verification.checks]
    assert labels[0] == ("speed norm (cone)" if sides is None else "speed norm (16-gon globe)")


def test_bad_limits_are_named() -> None:
    with pytest.raises(InputError, match="vmax: got -1, expected a number > 0"):
        FitOptions(limits=VehicleLimits(vmax=-1.0, amax=1.0))
    with pytest.raises(InputError, match="jmax: got 0, expected a number > 0"):
        FitOptions(limits=VehicleLimits(vmax=1.0, amax=1.0, jmax=0.0))


def test_limits_must_be_vehicle_limits() -> None:
    with pytest.raises(InputError, match=r"limits: got dict, expected VehicleLimits"):
        FitOptions(limits={"vmax": 1.0})  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"expected a speed and an acceleration bound"):
        FitOptions(limits=VehicleLimits(jmax=1.0))
