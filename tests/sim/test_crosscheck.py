"""skyquill's simulator against RotorPy on the same reference and the same control law.

Both fly paper 000's RPT law as printed (no lag or drag feed-forward, which
would be tuned to one vehicle model and not the other) on the same 0.5 m
writing trajectory; the tracking RMSEs must agree within a factor of 3.
"""

from __future__ import annotations

import pytest

pytest.importorskip("rotorpy")

from skyquill.sim import RPTController, simulate
from skyquill.sim.rotorpy_adapter import fly_rotorpy
from skyquill.trajectory import SplineTrajectory


def test_tracking_rmse_agrees_with_rotorpy_within_a_factor_of_3(writing: SplineTrajectory) -> None:
    traj = writing
    ours = simulate(traj, controller=RPTController(lag_s=0.0, drag_per_mass=0.0))
    theirs = fly_rotorpy(traj, RPTController(lag_s=0.0, drag_per_mass=0.0), rate_hz=100.0)
    ratio = ours.rmse_m / theirs.rmse_m
    print(f"RMSE skyquill {ours.rmse_m * 1e3:.2f} mm, RotorPy {theirs.rmse_m * 1e3:.2f} mm")
    assert 1 / 3 <= ratio <= 3
