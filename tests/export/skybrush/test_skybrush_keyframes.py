"""Skybrush keyframes: on the ms and mm grid, within 2 mm of the trajectory as Skybrush plays it."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest

from skyquill.errors import InputError
from skyquill.export.skybrush.keyframes import SEGMENT_MS, encode, skybrush_keyframes
from skyquill.export.skybrush.playback import played_trajectory, quantize
from skyquill.trajectory import PiecewisePolynomial, RestToRestSequence, SplineTrajectory


def spline(
    degree: int, seed: int = 0, duration: float = 6.0, lift: float = 1.0
) -> SplineTrajectory:
    ctrl = np.random.default_rng(seed).uniform(-0.5, 0.5, (18, 3)) + np.array([0.0, 0.0, lift])
    ctrl[:degree], ctrl[-degree:] = ctrl[0], ctrl[-1]  # at rest at both ends
    return SplineTrajectory(ctrl, degree, duration)


@pytest.mark.parametrize("degree", [3, 5, 7])
def test_keyframes_are_on_the_grid_and_play_within_2_mm(degree: int) -> None:
    traj = spline(degree, seed=degree, duration=5.0123)
    frames = skybrush_keyframes(traj)
    points = frames.points()
    times = np.array([p[0] for p in points])
    ms = np.round(times * 1000)
    assert np.array_equal(times, ms / 1000)  # integer milliseconds, exactly
    assert ms[-1] == 5013 and np.diff(ms).max() <= SEGMENT_MS
    values = np.array([c for p in points for c in [p[1], *p[2]]])
    assert frames.scale == 1
    # each number is the millimetre Skybrush's truncation stores
    np.testing.assert_array_equal(quantize(values, 1), np.round(values * 1000))
    played = played_trajectory("t", {"points": points})
    t = np.linspace(0.0, traj.duration, 50_001)
    error = np.linalg.norm(played.positions(t) - traj.evaluate(t), axis=1)
    assert error.max() <= 2e-3
    assert frames.fit_error_m <= 0.5e-3


def test_a_fast_trajectory_is_bisected_on_the_ms_grid() -> None:
    traj = spline(5, seed=3, duration=1.5)  # 18 control points in 1.5 s: large snap
    frames = skybrush_keyframes(traj)
    steps = np.diff(frames.times_ms)
    assert steps.min() < SEGMENT_MS and np.issubdtype(steps.dtype, np.integer)
    played = played_trajectory("t", {"points": frames.points()})
    t = np.linspace(0.0, traj.duration, 20_001)
    assert np.linalg.norm(played.positions(t) - traj.evaluate(t), axis=1).max() <= 2e-3


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
    played = played_trajectory("t", {"points": frames.points()})
    assert played.scale == 2
    t = np.linspace(0.0, traj.duration, 20_001)
    # half a 2 mm unit per axis from rounding, plus the cubic's 0.5 mm
    assert np.linalg.norm(played.positions(t) - traj.evaluate(t), axis=1).max() <= 2.3e-3


def test_bad_arguments_are_named() -> None:
    flat = SplineTrajectory(np.zeros((6, 2)), 3, 2.0)
    with pytest.raises(InputError, match=r"traj: got a 2-D trajectory, expected 3-D"):
        skybrush_keyframes(flat)
    with pytest.raises(InputError, match=r"tolerance: got 0"):
        skybrush_keyframes(spline(3), tolerance=0.0)


def _time_optimal_move() -> RestToRestSequence:
    """A 6 m rest-to-rest move in Ruckig's phases (cubic pieces), then a 3 s hold."""
    from skyquill.optimize.legs import LegLimits, leg_pieces

    limits = LegLimits(vmax=3.0, amax=2.0, jmax=10.0)
    durations, coeffs = leg_pieces(np.zeros(3), np.array([6.0, 0.0, 0.0]), limits)
    move = PiecewisePolynomial(np.concatenate([[0.0], np.cumsum(durations)]), coeffs)
    hold = PiecewisePolynomial(np.array([0.0, 3.0]), np.array([[[6.0, 0.0, 0.0]]]))
    return RestToRestSequence((move, hold))


def test_cubic_pieces_become_exact_segments_and_keep_the_rounding_small() -> None:
    """A time-optimal move is cubic piece by piece: its phases are segments of their own (no
    bisection), so the mm rounding moves the acceleration by far less than on 125 ms ones."""
    traj = _time_optimal_move()
    keys = skybrush_keyframes(traj)
    assert keys.fit_error_m < 1e-6
    long_phases = [b for a, b in pairwise(traj.breakpoints) if b - a >= 0.1]
    assert set(np.round(np.array(long_phases) * 1000).astype(int)) <= set(keys.times_ms.tolist())
    played = played_trajectory("d", {"points": keys.points()}).trajectory()
    t = np.linspace(0.0, traj.duration, 20_001)
    accel = np.linalg.norm(played.evaluate(t, 2), axis=1)
    assert accel.max() <= 2.0 * 1.05
