"""Shared references for the simulation tests."""

from __future__ import annotations

import numpy as np
import pytest

from skyquill.limits import VehicleLimits
from skyquill.optimize.fit import FitOptions, fit_points
from skyquill.trajectory import SplineTrajectory


@pytest.fixture(scope="session")
def writing() -> SplineTrajectory:
    """A 0.5 m figure-eight at 1 m height, <= 1 m/s: a feasible writing stroke."""
    th = np.linspace(0.0, 2 * np.pi, 200)
    pts = np.column_stack([0.25 * np.cos(th), 0.125 * np.sin(2 * th), np.ones(200)])
    fit = fit_points(pts, None, FitOptions(limits=VehicleLimits(1.0, 1.0, 5.0)))
    assert fit.result.verification.max_speed <= 1.0
    return fit.result.trajectory
