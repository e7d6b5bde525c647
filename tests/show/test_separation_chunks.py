"""The separation's grid intervals, built a slice at a time and bounded in number."""

from __future__ import annotations

import numpy as np
import pytest

from skyquill.errors import SolverError
from skyquill.show import separation
from skyquill.show.motion import motion_of
from skyquill.show.separation import guaranteed_separation
from skyquill.trajectory import SplineTrajectory


def _crowd(n: int, spacing: float = 3.2) -> list:  # type: ignore[type-arg]
    """``n`` drones on a line, each circling 0.5 m about its place: neighbours come close."""
    u = np.linspace(0.0, 2 * np.pi, 24)
    circle = 0.5 * np.column_stack([np.cos(u), np.sin(u), np.zeros_like(u)])
    return [
        motion_of(
            f"d{i}", SplineTrajectory(np.array([spacing * i, 0.0, 5.0]) + circle, 5, 20.0), 20.0
        )
        for i in range(n)
    ]


def test_slices_give_the_same_answer_as_one_block(monkeypatch: pytest.MonkeyPatch) -> None:
    motions = _crowd(6)
    whole = guaranteed_separation(motions, 2.0)
    monkeypatch.setattr(separation, "CHUNK", 37)  # many slices, none aligned to a window
    sliced = guaranteed_separation(motions, 2.0)
    assert sliced == whole


def test_more_close_intervals_than_the_ceiling_are_refused(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Issue 25: checking 2,000 drones took 7.19 GiB in these intervals."""
    monkeypatch.setattr(separation, "MAX_INTERVALS", 100)
    with pytest.raises(SolverError, match=r"separation: got [\d,]+ grid intervals .* at most 100"):
        guaranteed_separation(_crowd(6), 2.0)
