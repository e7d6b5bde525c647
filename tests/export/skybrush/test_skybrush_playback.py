"""Skybrush playback: the module against a second, literal copy of the server's and firmware's code.

(The copy keeps the server's idioms, ``int(round(x))`` and pairs by ``zip``, on purpose.)
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.export.skybrush.playback import played_trajectory, quantize, scaling_factor


def reference_segments(traj: dict[str, Any]) -> tuple[list[int], list[list[list[int]]]]:
    """skybrush-server's iter_segments(absolute=True) and SegmentEncoder, line by line in Python.

    Returns each segment's duration (ms) and its stored points per axis (start included).
    """
    points = list(traj["points"])
    if traj.get("takeoffTime", 0.0) > 0:
        home = traj.get("home") or points[0][1]
        points.insert(0, [-traj["takeoffTime"], home, []])
    coords = [c for p in traj["points"] for c in [p[1], *p[2]]]
    extremum = math.ceil(max(abs(x) for c in coords for x in c) * 1000)
    scale = 1000 / math.ceil((extremum + 1) / 32768)
    durations, stored = [], []
    for (t0, p0, _), (t1, p1, control) in itertools.pairwise(points):
        dt = round(t1 - t0, 3)
        durations.append(math.floor(dt * 1000))
        per_axis = []
        for axis in range(3):
            xs = [int(q[axis] * scale) for q in [p0, *control, p1]]
            first, *rest = xs
            if all(x == first for x in rest):
                per_axis.append([first])
            elif len(rest) == 2:
                raised = ((first + 2 * rest[0]) / 3, (2 * rest[0] + rest[1]) / 3, rest[1])
                per_axis.append([first, *(int(round(x)) for x in raised)])  # noqa: RUF046
            else:
                per_axis.append(xs)
        stored.append(per_axis)
    return durations, stored


def reference_positions(traj: dict[str, Any], t: np.ndarray) -> np.ndarray:
    """De Casteljau in float64 on the stored integers (mm), at firmware times ``t`` (s)."""
    durations, stored = reference_segments(traj)
    starts = np.concatenate([[0], np.cumsum(durations)]) / 1000
    out = np.empty((t.size, 3))
    for n, tn in enumerate(t):
        i = min(int(np.searchsorted(starts, tn, side="right")) - 1, len(durations) - 1)
        u = (tn - starts[i]) / (durations[i] / 1000)
        for axis in range(3):
            ctrl = [float(c) for c in stored[i][axis]]
            while len(ctrl) > 1:
                ctrl = [(1 - u) * a + u * b for a, b in itertools.pairwise(ctrl)]
            out[n, axis] = ctrl[0] / 1000
    return out


SHOW = {
    "version": 1,
    "points": [
        [0.0, [0.0, 0.0, 1.0], []],
        [0.25, [0.1, -0.05, 1.2], [[0.03, 0.0, 1.05], [0.07, -0.04, 1.15]]],  # cubic
        [0.6, [0.2, -0.05, 1.2], [[0.15, -0.05, 1.2]]],  # quadratic, two constant axes
        [1.0, [0.3, 0.1, 1.0], []],  # straight
        [1.5, [0.3, 0.1, 1.0], [[0.3, 0.1, 1.0], [0.3, 0.1, 1.0]]],  # still
    ],
}


@pytest.mark.parametrize("takeoff", [0.0, 2.0])
def test_the_module_plays_what_a_literal_copy_of_skybrush_plays(takeoff: float) -> None:
    traj = {**SHOW, "takeoffTime": takeoff}
    played = played_trajectory("t", traj)
    durations, _ = reference_segments(traj)
    assert played.durations_ms.tolist() == durations
    t = np.linspace(0.0, sum(durations) / 1000, 3001)
    expected = reference_positions(traj, t)
    # float32 in the firmware: a few micrometres on metre-sized coordinates
    assert np.abs(played.positions(t) - expected).max() < 5e-6
    assert np.abs(played.trajectory().evaluate(t) - expected).max() < 5e-6
    if takeoff:  # the still segment at the first keyframe before take-off
        np.testing.assert_allclose(played.positions(np.array([0.0, 1.9])), [[0, 0, 1]] * 2)


def test_the_servers_floor_and_truncation_are_copied() -> None:
    # 1.001 s is stored as 1000 ms (floor of 1000.9999...), and 0.0009 m as 0 mm
    traj = {"points": [[0.0, [0.0, 0.0, 1.0], []], [1.001, [0.0009, -0.0009, 1.0], []]]}
    played = played_trajectory("t", traj)
    assert played.durations_ms.tolist() == [1000]
    np.testing.assert_allclose(played.positions(np.array([1.0])), [[0.0, 0.0, 1.0]])
    assert quantize(np.array([0.0019, -0.0019]), 1).tolist() == [1, -1]


def test_a_show_beyond_32_m_is_stored_in_coarser_units() -> None:
    assert scaling_factor(np.array([32.766])) == 1
    assert scaling_factor(np.array([-32.767])) == 2
    traj = {"points": [[0.0, [40.0, 0.0, 1.0], []], [1.0, [40.0031, 0.0, 1.0], []]]}
    played = played_trajectory("t", traj)
    assert played.scale == 2
    assert played.positions(np.array([1.0]))[0, 0] == pytest.approx(40.002, abs=1e-6)


@pytest.mark.parametrize(
    ("points", "match"),
    [
        ([[0.0, [0, 0, 0], []], [0.0004, [0, 0, 1], []]], r"t.points\[1\]\[0\]: got 0.0004 after"),
        ([[0.0, [0, 0, 0], []], [70.0, [0, 0, 1], []]], r"got a 70 s segment, expected at most 65"),
        ([[0.0, [0, 0, 0], []], [1.0, [0, 0, 1], [[0, 0, 0]] * 3]], r"got 3 control points"),
        ([[0.0, [1e6, 0, 0], []]], r"expected a show Skybrush can store"),
    ],
)
def test_what_skybrush_cannot_play_is_named(points: list[Any], match: str) -> None:
    with pytest.raises(InputError, match=match):
        played_trajectory("t", {"points": points})


_FACTS = (1, 1, 2, 6, 24, 120, 720, 5040)


def reference_bezier(points: np.ndarray) -> np.ndarray:
    """libskybrush's ``sb_poly_make_bezier`` on one axis of one segment, float32, as poly.c."""
    n = points.size - 1
    out = np.zeros(4, dtype=np.float32)
    if n == 0:
        out[0] = points[0]
        return out
    if n == 1:
        out[0], out[1] = points[0], points[1] - points[0]
        return out
    for j in range(n + 1):
        coeff = np.float32(0.0)
        sign = -1 if j % 2 else 1
        for i in range(j + 1):
            term = np.float32(sign) * points[i]
            coeff = coeff + term / np.float32(_FACTS[i]) / np.float32(_FACTS[j - i])
            sign = -sign
        out[j] = coeff * np.float32(_FACTS[n]) / np.float32(_FACTS[n - j])
    return out


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10**6), count=st.integers(2, 30), takeoff=st.sampled_from([0.0, 1.5]))
def test_every_segment_at_once_is_bit_for_bit_the_firmwares_one_at_a_time(
    seed: int, count: int, takeoff: float
) -> None:
    rng = np.random.default_rng(seed)
    times = np.round(np.cumsum(rng.uniform(0.001, 3.0, count)), 3)
    still = rng.random((count, 3)) < 0.3  # axes that do not move
    positions = rng.uniform(-60, 60, (count, 3))
    positions[1:] = np.where(still[1:], positions[:-1], positions[1:])
    points = []
    for k in range(count):
        controls = [] if k == 0 else rng.uniform(-60, 60, (int(rng.integers(0, 3)), 3)).tolist()
        points.append([float(times[k]), positions[k].tolist(), controls])
    traj = {"version": 1, "points": points, "takeoffTime": takeoff}
    played = played_trajectory("t", traj)
    durations, stored = reference_segments(traj)
    assert played.durations_ms.tolist() == durations
    for k, per_axis in enumerate(stored):
        for axis, series in enumerate(per_axis):
            ints = np.array(series, dtype=np.int64) * played.scale
            expected = reference_bezier(ints.astype(np.float32))
            np.testing.assert_array_equal(played.coeffs_mm[k, :, axis], expected)
