"""The reduced contact model against the closed-loop simulator flying into the same bumper."""

from __future__ import annotations

import pytest

from skyquill.painting.crosscheck import simulated_touch
from skyquill.painting.mission import ContactModel


@pytest.mark.parametrize("speed", [0.12, 0.2, 0.3])
def test_detection_matches_the_simulator(speed: float) -> None:
    check = simulated_touch(approach_speed_mps=speed)
    sim, model = check["sim"], check["model"]
    assert sim["detected"] and model["detected"]
    assert abs(sim["delay_s"] - model["delay_s"]) <= 1.0 / ContactModel().imu_rate_hz + 1e-9
    assert abs(sim["squeeze_m"] - model["squeeze_m"]) < 1e-3


def test_a_gentle_touch_is_missed_by_both() -> None:
    check = simulated_touch(approach_speed_mps=0.08)
    assert not check["sim"]["detected"] and not check["model"]["detected"]
