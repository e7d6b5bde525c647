"""Skybrush keyframes: C2 cubics on the ms and mm grid, near the plan, inside its limits."""

from __future__ import annotations

import json
from itertools import pairwise

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.export.base import ALLOWED_EXCESS
from skyquill.export.skybrush.keyframe_times import MAX_FIT_MS, MIN_FIT_MS
from skyquill.export.skybrush.keyframes import Keyframes, encode, skybrush_keyframes
from skyquill.export.skybrush.playback import played_trajectory, quantize
from skyquill.limits import VehicleLimits
from skyquill.trajectory import PiecewisePolynomial, RestToRestSequence, SplineTrajectory
from skyquill.verify import verify


def spline(
    degree: int, seed: int = 0, duration: float = 6.0, lift: float = 1.0
) -> SplineTrajectory:
    ctrl = np.random.default_rng(seed).uniform(-0.5, 0.5, (18, 3)) + np.array([0.0, 0.0, lift])
    ctrl[:degree], ctrl[-degree:] = ctrl[0], ctrl[-1]  # at rest at both ends
    return SplineTrajectory(ctrl, degree, duration)


def played(frames: object) -> PiecewisePolynomial:
    return played_trajectory("t", {"points": frames.points()}).trajectory()  # type: ignore[attr-defined]


@pytest.mark.parametrize("degree", [3, 5, 7])
def test_keyframes_are_on_the_grid_and_play_within_2_mm(degree: int) -> None:
    traj = spline(degree, seed=degree, duration=5.0123)
    frames = skybrush_keyframes(traj)
    points = frames.points()
    times = np.array([p[0] for p in points])
    ms = np.round(times * 1000)
    assert np.array_equal(times, ms / 1000)  # integer milliseconds, exactly
    assert ms[-1] == 5013 and np.diff(ms).min() >= MIN_FIT_MS and np.diff(ms).max() <= MAX_FIT_MS
    values = np.array([c for p in points for c in [p[1], *p[2]]])
    assert frames.scale == 1
    # each number is the millimetre Skybrush's truncation stores
    np.testing.assert_array_equal(quantize(values, 1), np.round(values * 1000))
    back = played_trajectory("t", {"points": points})
    t = np.linspace(0.0, traj.duration, 50_001)
    error = np.linalg.norm(back.positions(t) - traj.evaluate(t), axis=1)
    assert error.max() <= 2e-3


def test_the_grid_leaves_steps_of_a_couple_of_units_at_the_joins() -> None:
    """The fitted curve is C2 (``test_keyframe_fit.py``); on the grid a join's velocity and
    acceleration steps are those of moving a point by two units: ``2 * 3 u / h`` and
    ``2 * 6 * 2 u / h^2`` over the shorter of its two segments."""
    traj = spline(5, seed=1)
    frames = skybrush_keyframes(traj, VehicleLimits(2.0, 4.0, 40.0).derivative_limits(3))
    back = played(frames)
    joins = frames.times_ms[1:-1] / 1000.0
    h = np.minimum(np.diff(frames.times_ms)[:-1], np.diff(frames.times_ms)[1:]) / 1000.0
    for order, factor in ((1, 6.0), (2, 24.0)):
        step = np.abs(back.evaluate(joins - 1e-9, order) - back.evaluate(joins, order))
        assert np.all(step.max(axis=1) <= factor * 1e-3 / h**order + 1e-9)


def test_the_played_curve_keeps_the_limits_the_plan_touches() -> None:
    """A spline planned against its limits: as played, speed and acceleration at most 1 %
    over them and jerk at most 5 % (the grid cannot do better than its unit)."""
    from skyquill.calligraphy.mission import plan_writing
    from skyquill.strokes import hanzi_strokes

    mission = plan_writing(hanzi_strokes("永"))
    frames = skybrush_keyframes(mission.vehicle_trajectory(), mission.limits)
    check = verify(played(frames), mission.limits, guaranteed=False)
    for report in check.limits_report():
        order = {"speed": 1, "acceleration": 2, "jerk": 3}[report["label"].split()[0]]
        assert report["relative_excess"] <= ALLOWED_EXCESS[order]


def test_numbers_that_truncation_would_lose_are_moved_one_float_out() -> None:
    units = np.array([1001, -1001, 0, 32767, -32767], dtype=np.int64)
    assert int(1001 / 1000 * 1000) == 1000  # the trap: 1.001 * 1000 = 1000.999...
    values = encode(units, 1)
    np.testing.assert_array_equal(quantize(values, 1), units)
    assert np.abs(values - units / 1000).max() < 1e-15


def test_a_large_show_gets_skybrushs_coarser_units() -> None:
    traj = spline(5, seed=4, lift=40.0)  # z up to 40.5 m: beyond int16 millimetres
    frames = skybrush_keyframes(traj)
    assert frames.scale == 2
    back = played_trajectory("t", {"points": frames.points()})
    assert back.scale == 2
    t = np.linspace(0.0, traj.duration, 20_001)
    assert np.linalg.norm(back.positions(t) - traj.evaluate(t), axis=1).max() <= 3e-3


def test_bad_arguments_are_named() -> None:
    flat = SplineTrajectory(np.zeros((6, 2)), 3, 2.0)
    with pytest.raises(InputError, match=r"traj: got a 2-D trajectory, expected 3-D"):
        skybrush_keyframes(flat)
    with pytest.raises(InputError, match=r"margin: got -0.1"):
        skybrush_keyframes(spline(3), margin=-0.1)
    with pytest.raises(InputError, match=r"segment_scale: got 20, expected 0.25 to 8"):
        skybrush_keyframes(spline(3), segment_scale=20.0)


def _time_optimal_move() -> RestToRestSequence:
    """A 6 m rest-to-rest move in Ruckig's phases (cubic pieces), then a 3 s hold."""
    from skyquill.optimize.legs import LegLimits, leg_pieces

    limits = LegLimits(vmax=3.0, amax=2.0, jmax=10.0)
    durations, coeffs = leg_pieces(np.zeros(3), np.array([6.0, 0.0, 0.0]), limits)
    move = PiecewisePolynomial(np.concatenate([[0.0], np.cumsum(durations)]), coeffs)
    hold = PiecewisePolynomial(np.array([0.0, 3.0]), np.array([[[6.0, 0.0, 0.0]]]))
    return RestToRestSequence((move, hold))


def test_cubic_pieces_are_exact_segments_rounded_inside_the_limits() -> None:
    """A time-optimal move is cubic piece by piece: its phases are segments of their own,
    and where it accelerates at amax the rounding holds the acceleration within 1 %."""
    traj = _time_optimal_move()
    limits = VehicleLimits(3.0, 2.0, 10.0).derivative_limits(3)
    keys = skybrush_keyframes(traj, limits)
    assert keys.fit_error_m < 1e-6 and keys.exact_segments == keys.units.shape[0]
    long_phases = [b for a, b in pairwise(traj.breakpoints) if b - a >= 0.1]
    assert set(np.round(np.array(long_phases) * 1000).astype(int)) <= set(keys.times_ms.tolist())
    t = np.linspace(0.0, traj.duration, 20_001)
    back = played(keys)
    assert np.linalg.norm(back.evaluate(t, 2), axis=1).max() <= 2.0 * 1.01
    assert np.linalg.norm(back.evaluate(t, 3), axis=1).max() <= 10.0 * 1.05
    assert np.linalg.norm(back.evaluate(t) - traj.evaluate(t), axis=1).max() <= 3e-3


@pytest.mark.parametrize("jmax", [10.0, None])
def test_jerk_ramps_long_enough_for_a_coarse_grid_play_inside_the_limits(
    jmax: float | None,
) -> None:
    """447 m from the origin (14 mm units): a time-optimal landing at jmax 10 (0.2 s ramps)
    has no keyframes inside its limits near it; at :func:`playable_jerk` it plays exactly."""
    from skyquill.errors import InfeasibleError
    from skyquill.export.skybrush.keyframe_times import playable_jerk
    from skyquill.export.skybrush.refit import played_keyframes
    from skyquill.io.trajectory_json import PlannedTrajectory
    from skyquill.optimize.legs import LegLimits, leg_pieces

    assert playable_jerk(2.0, 10.0, 100.0) == 10.0  # 4 mm units: the limit itself
    jerk = jmax or playable_jerk(2.0, 10.0, 447.0)
    start, goal = np.array([447.0, 30.0, 10.0]), np.array([444.0, 25.0, 4.0])

    def move(a: np.ndarray, b: np.ndarray) -> PiecewisePolynomial:
        durations, coeffs = leg_pieces(a, b, LegLimits(4.0, 2.0, jerk))
        return PiecewisePolynomial(np.concatenate([[0.0], np.cumsum(durations)]), coeffs)

    hold = PiecewisePolynomial(np.array([0.0, 2.0]), np.array([[goal]]))
    pad = goal - np.array([0.0, 0.0, 4.0])
    flight = RestToRestSequence((move(start, goal), hold, move(goal, pad)))
    limits = VehicleLimits(4.0, 2.0, 10.0).derivative_limits(3)
    planned = PlannedTrajectory(flight, (), limits)
    if jmax is not None:
        with pytest.raises(InfeasibleError, match=r"grid of 14 mm units.*lower jerk limit"):
            played_keyframes("d", planned)
        return
    assert 5.0 < jerk < 8.0
    keys = played_keyframes("d", planned)
    assert keys.keyframes.scale == 14 and keys.attempt == 0
    assert keys.keyframes.exact_segments == keys.keyframes.units.shape[0]
    assert keys.delivered.within_allowed


@settings(max_examples=30, deadline=None)
@given(segments=st.integers(1, 30), scale=st.integers(1, 20), seed=st.integers(0, 2**32 - 1))
def test_points_are_each_segment_listed_on_its_own(segments: int, scale: int, seed: int) -> None:
    # show.json's points list, built from one tolist of every number, against the
    # segment-by-segment listing it replaced.
    rng = np.random.default_rng(seed)
    units = rng.integers(-40_000, 40_000, (segments, 4, 3))
    units[1:, 0] = units[:-1, 3]
    times_ms = np.concatenate([[0], np.cumsum(rng.integers(1, 3000, segments))])
    frames = Keyframes(times_ms, units, scale, 0.0)
    values = encode(units, scale)
    times = times_ms / 1000.0
    listed = [[float(times[0]), values[0, 0].tolist(), []]] + [
        [float(times[i + 1]), values[i, 3].tolist(), values[i, 1:3].tolist()]
        for i in range(segments)
    ]
    assert json.dumps(frames.points()) == json.dumps(listed)
