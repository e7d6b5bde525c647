"""The closed-form rest-to-rest profile against Ruckig, the independent reference.

Ruckig (Berscheid & Kröger, RSS 2021) computes time-optimal jerk-limited profiles by its
own case analysis and root finding; here its phases, total duration and densely sampled
states are the reference for :mod:`skyquill.optimize.double_s`, on lengths from a
micrometre to 3.5 km and limits over two decades, and on the boundaries between the
profile's cases (where a limit is reached exactly).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st
from ruckig_reference import merged_phases, ruckig_move

from skyquill.optimize.double_s import JERK_SIGNS, MIN_PHASE_S, cruise, rest_to_rest

#: Relative tolerance on durations (of the move's total): the closed form and Ruckig agree
#: to a few ulps; 1e-9 leaves room for neither to be exact.
REL = 1e-9


def _states(t: np.ndarray, jerk: float, at: np.ndarray) -> np.ndarray:
    """Position, speed and acceleration (3, S) at times ``at`` of a move from rest at 0
    with phases ``t`` (7,) of jerks ``JERK_SIGNS * jerk``, integrated phase by phase."""
    p = v = a = 0.0
    start = 0.0
    out = np.empty((3, at.size))
    for duration, sign in zip(t.tolist(), JERK_SIGNS.tolist(), strict=True):
        j = sign * jerk
        inside = (at >= start) & (at <= start + duration)
        s = at[inside] - start
        out[:, inside] = [
            p + s * (v + s * (a / 2 + s * j / 6)),
            v + s * (a + s * j / 2),
            a + s * j,
        ]
        p, v, a = (
            p + duration * (v + duration * (a / 2 + duration * j / 6)),
            v + duration * (a + duration * j / 2),
            a + duration * j,
        )
        start += duration
    return out


def _check_againstruckig_move(length: float, v: float, a: float, j: float) -> None:
    reference = ruckig_move(length, v, a, j)
    assume(reference is not None)
    assert reference is not None
    t = rest_to_rest(np.array([length]), v, a, j)[0]
    total = float(reference.duration)
    assert t.sum() == pytest.approx(total, rel=REL)
    profile = reference.profiles[0][0]
    ours = merged_phases(t, JERK_SIGNS * j, REL * total)
    theirs = merged_phases(np.array(profile.t), np.array(profile.j), REL * total)
    assert [p[1] for p in ours] == [p[1] for p in theirs]
    np.testing.assert_allclose([p[0] for p in ours], [p[0] for p in theirs], atol=REL * total)
    # Densely sampled states: positions to the length, speeds and accelerations to their
    # limits, all at the same relative tolerance.
    at = np.linspace(0.0, min(t.sum(), total), 101)
    got = _states(t, j, at)
    want = np.array([reference.at_time(float(s))[:3] for s in at])[:, :, 0].T
    scale = np.array([[length], [v], [a]])
    assert np.all(np.abs(got - want) <= 1e-8 * scale)


_LIMITS = st.tuples(
    st.floats(0.1, 10.0),  # vmax, m/s
    st.floats(0.1, 10.0),  # amax, m/s^2
    st.floats(0.5, 100.0),  # jmax, m/s^3
)


@settings(max_examples=300, deadline=None)
@given(st.floats(-6.0, np.log10(3.5e3)), _LIMITS)
@example(np.log10(2.0), (1.0, 2.0, 5.0))  # the textbook S-curve: 0.4 / 0.1 / 0.4, cruise 1.1
def test_rest_to_rest_is_ruckigs_profile(
    log_length: float, limits: tuple[float, float, float]
) -> None:
    _check_againstruckig_move(10.0**log_length, *limits)


@settings(max_examples=200, deadline=None)
@given(
    _LIMITS,
    st.sampled_from(["amax reached", "vmax reached", "vmax at amax"]),
    st.floats(-1e-6, 1e-6),
)
def test_rest_to_rest_is_ruckigs_profile_where_a_limit_is_just_reached(
    limits: tuple[float, float, float], boundary: str, nudge: float
) -> None:
    v, a, j = limits
    if boundary == "vmax at amax":  # the speed limit reached just as the acceleration's is
        v = a * a / j * (1.0 + nudge)
        length = 2.0 * v * (v / a + a / j) * (1.0 + abs(nudge))
    elif boundary == "amax reached":  # the shortest move reaching the acceleration limit
        length = 2.0 * a**3 / j**2 * (1.0 + nudge)
    else:  # the shortest move reaching the speed limit
        ramp = v / a + a / j if v * j >= a * a else 2.0 * np.sqrt(v / j)
        length = v * ramp * (1.0 + nudge)
    _check_againstruckig_move(length, v, a, j)


def test_jerk_only_moves_have_ruckigs_threemerged_phases() -> None:
    # Too short to reach either limit: +j, -j for twice as long, +j (Ruckig's layout).
    t = rest_to_rest(np.array([1e-3]), 2.0, 3.0, 10.0)[0]
    t1 = (1e-3 / 20.0) ** (1 / 3)
    np.testing.assert_allclose(t, [t1, 0, 2 * t1, 0, 0, 0, t1], rtol=1e-15)


def test_limits_one_per_move() -> None:
    lengths = np.array([1e-4, 0.5, 3.0, 40.0])
    v, a, j = np.array([1.0, 2.0, 0.5, 3.0]), np.array([2.0, 1.0, 4.0, 0.3]), np.full(4, 7.0)
    together = rest_to_rest(lengths, v, a, j)
    for i, length in enumerate(lengths):
        alone = rest_to_rest(np.array([length]), float(v[i]), float(a[i]), float(j[i]))
        np.testing.assert_array_equal(together[i], alone[0])


@settings(max_examples=100, deadline=None)
@given(_LIMITS, st.floats(1.0 + 1e-6, 1e4))
def test_cruise_is_the_profile_of_every_move_that_cruises(
    limits: tuple[float, float, float], stretch: float
) -> None:
    v, a, j = limits
    profile = cruise(v, a, j)
    assert profile is not None
    length = stretch * 2.0 * v * profile.ramp_s  # long enough to cruise
    t = rest_to_rest(np.array([length]), v, a, j)[0]
    kept = t > MIN_PHASE_S
    durations = profile.durations.copy()
    durations[profile.at_cruise] = length / v - profile.ramp_s
    np.testing.assert_allclose(durations, t[kept], rtol=1e-12, atol=1e-12 * t.sum())
    # Its coefficients (along +x from 0 to the length) are the states at each phase's
    # start, integrated phase by phase.
    coeffs = (profile.mix @ np.array([1.0, 0.0, length])).reshape(-1, 4)
    state = _phase_starts(t, j)[:, kept]
    np.testing.assert_allclose(coeffs[:, 0], state[0], atol=1e-12 * max(1.0, length))
    np.testing.assert_allclose(coeffs[:, 1], state[1], atol=1e-12 * v)
    np.testing.assert_allclose(coeffs[:, 2], state[2] / 2, atol=1e-12 * a)
    np.testing.assert_allclose(coeffs[:, 3], JERK_SIGNS[kept] * j / 6, rtol=1e-15)


def _phase_starts(t: np.ndarray, jerk: float) -> np.ndarray:
    """Position, speed and acceleration (3, 7) at the start of each phase ``t`` (7,) of a
    move from rest, jerks ``JERK_SIGNS * jerk``."""
    out = np.zeros((3, 8))
    for i, (d, sign) in enumerate(zip(t.tolist(), JERK_SIGNS.tolist(), strict=True)):
        p, v, a = out[:, i]
        j = sign * jerk
        out[:, i + 1] = [
            p + d * (v + d * (a / 2 + d * j / 6)),
            v + d * (a + d * j / 2),
            a + d * j,
        ]
    return out[:, :7]


def test_cruise_refuses_limits_whose_jerk_phases_vanish() -> None:
    assert cruise(1.0, 1e-13, 1.0) is None
