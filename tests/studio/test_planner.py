"""The studio's planner on its own: the stages it reports, from the planner's real steps."""

from __future__ import annotations

import logging

import pytest

from skyquill.calligraphy import mission
from skyquill.studio.models import PlanRequest
from skyquill.studio.planner import run_plan


def test_progress_follows_the_solves_the_flight_and_the_files() -> None:
    """Each solve of the route is a stage (the planning's DEBUG records); the bar only rises."""
    seen: list[tuple[float, str]] = []
    output = run_plan(
        PlanRequest(text="L", target="skybrush"),
        progress=lambda fraction, stage, known=True: seen.append((fraction, stage)),
        file_url=lambda name: name,
        plan_id="0123456789ab",
    )
    fractions = [f for f, _ in seen]
    stages = [s for _, s in seen]
    assert fractions == sorted(fractions) and fractions[0] > 0.0 and fractions[-1] < 1.0
    assert "drone 1 of 1: fitting the flight to the limits (solve 1)" in stages
    assert "flying drone 1 of 1 in simulation" in stages
    assert stages[-1] == "writing the show (file 2 of 2)"
    assert output.result.plan_id == "0123456789ab"
    # The listener is gone afterwards: the mission logger is as it was.
    assert mission.logger.level == logging.NOTSET and not mission.logger.handlers


def test_a_progress_callback_that_raises_stops_the_plan() -> None:
    """The way a plan is stopped from inside: the first solve's report raises."""

    def stop(fraction: float, stage: str, known: bool = True) -> None:
        if "fitting" in stage:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_plan(PlanRequest(text="L"), progress=stop, file_url=str, plan_id="0" * 12)
    assert not mission.logger.handlers
