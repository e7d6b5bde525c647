"""The limit-keeping rounding to Skybrush's grid: the cheapest combinations first, same pick."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.export.skybrush import grid_rounding, keyframes
from skyquill.limits import VehicleLimits
from skyquill.trajectory import SplineTrajectory


def rounding_inputs(seed: int, lift: float) -> list[tuple[Any, ...]]:
    """What :func:`skybrush_keyframes` rounds for a random fast spline at its limits."""
    ctrl = np.random.default_rng(seed).uniform(-3.0, 3.0, (14, 3)) + np.array([0, 0, lift])
    ctrl[:5], ctrl[-5:] = ctrl[0], ctrl[-1]  # at rest at both ends
    traj = SplineTrajectory(ctrl, 5, 8.0)
    t = np.linspace(0.0, traj.duration, 2001)
    # limits at the spline's own maxima: the rounding has to search where it touches them
    peaks = [float(np.linalg.norm(traj.evaluate(t, n), axis=1).max()) for n in (1, 2, 3)]
    limits = VehicleLimits(*peaks).derivative_limits(3)
    seen: list[tuple[Any, ...]] = []

    def record(*args: Any) -> grid_rounding.Rounding:
        seen.append(args)
        return grid_rounding.round_to_grid(*args)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(keyframes, "round_to_grid", record)
        keyframes.skybrush_keyframes(traj, limits)
    return seen


def searched_the_same(args: tuple[Any, ...]) -> int:
    """Round ``args`` with the :data:`NEAREST` cheapest combinations first and with every
    combination at once: the same result; how many segments were searched."""
    first = grid_rounding.round_to_grid(*args)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(grid_rounding, "NEAREST", 10**9)  # every combination at once
        every = grid_rounding.round_to_grid(*args)
    assert np.array_equal(first.units, every.units)
    assert (first.adjusted, first.unresolved) == (every.adjusted, every.unresolved)
    assert first.hull_excess == every.hull_excess
    return first.adjusted + len(first.unresolved)


@given(seed=st.integers(0, 2**16), lift=st.floats(1.0, 400.0))
@settings(max_examples=10, deadline=None)
def test_the_cheapest_combinations_first_pick_what_evaluating_all_picks(
    seed: int, lift: float
) -> None:
    """Evaluating the cheapest combinations first gives the same units, the same searched and
    unresolved segments as evaluating every combination (a spline far out too: coarser
    units)."""
    for args in rounding_inputs(seed, lift):
        searched_the_same(args)


def test_the_splines_compared_are_searched() -> None:
    """The comparison above means something: these splines' rounding searches segments."""
    assert sum(searched_the_same(args) for args in rounding_inputs(0, 1.0)) > 0
