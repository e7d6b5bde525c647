"""The simulation's bounds: step budget and rate range before allocation, rest at both ends."""

from __future__ import annotations

import numpy as np
import pytest

from skyquill.errors import InputError
from skyquill.sim import check_rest_ends, simulate
from skyquill.sim.bounds import MAX_SIM_STEPS, check_steps
from skyquill.trajectory import SplineTrajectory


def _still(duration: float) -> SplineTrajectory:
    return SplineTrajectory(np.zeros((6, 3)), 5, duration)


def test_a_flight_of_a_million_seconds_is_refused_by_the_estimate() -> None:
    # 5e8 steps would be ~100 GB; refused before a single array is made.
    message = (
        r"^trajectory: got a 1e\+06 s flight at 500 Hz \(5e\+08 steps\), expected at most "
        r"2,000,000 steps \(at 500 Hz a flight of at most 4000 s: lower rate_hz or fly it in "
        r"parts\)$"
    )
    with pytest.raises(InputError, match=message):
        simulate(_still(1e6))


@pytest.mark.parametrize("rate", [1e6, 10.0, 0.0, float("nan")])
def test_rate_out_of_range_is_refused(rate: float) -> None:
    with pytest.raises(InputError, match=r"^rate_hz: got "):
        simulate(_still(1.0), rate_hz=rate)


def test_rate_message_says_the_range() -> None:
    with pytest.raises(InputError, match=r"rate_hz: got 1e\+06 Hz, expected 50 to 10000 Hz"):
        simulate(_still(1.0), rate_hz=1e6)


def test_step_budget_edge() -> None:
    assert check_steps((MAX_SIM_STEPS - 1) / 500.0, 500.0) == MAX_SIM_STEPS
    with pytest.raises(InputError, match="expected at most 2,000,000 steps"):
        check_steps(MAX_SIM_STEPS / 500.0, 500.0)


def test_rest_ends_accepts_a_plan(writing: SplineTrajectory) -> None:
    check_rest_ends(writing)


def test_moving_end_is_named() -> None:
    # Quadratic Bezier: starts at rest, ends at 2 * 0.25 m / 1 s = 0.5 m/s.
    moving = SplineTrajectory(np.array([[0.0, 0, 0], [0.0, 0, 0], [0.25, 0, 0]]), 2, 1.0)
    message = (
        r"^trajectory: ends at 0\.5 m/s, expected rest \(a plan from fit/write/cover/paint\); "
        r"a speed of at most 0\.01 m/s at both ends$"
    )
    with pytest.raises(InputError, match=message):
        check_rest_ends(moving)
    check_rest_ends(moving, tolerance=0.6)
    reverse = SplineTrajectory(np.array([[0.25, 0, 0], [0.0, 0, 0], [0.0, 0, 0]]), 2, 1.0)
    with pytest.raises(InputError, match=r"^trajectory: starts at 0\.5 m/s"):
        check_rest_ends(reverse)


def test_rest_tolerance_is_checked(writing: SplineTrajectory) -> None:
    with pytest.raises(InputError, match="tolerance: got -1, expected a number >= 0"):
        check_rest_ends(writing, tolerance=-1.0)
