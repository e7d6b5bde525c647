"""Stop-and-go legs: the time-optimal profile (Ruckig's, checked against it) as exact cubic
pieces, rest at every waypoint."""

from __future__ import annotations

from unittest import mock

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from ruckig import InputParameter, Ruckig, Trajectory
from ruckig_reference import merged_phases, ruckig_move

import skyquill.optimize.legs as legs_module
from skyquill.errors import InputError
from skyquill.limits import vehicle_limits
from skyquill.optimize.legs import (
    REPEAT_TOLERANCE,
    RUCKIG_MAX_DURATION_S,
    LegLimits,
    UntimeableLegError,
    leg_pieces,
    legs_pieces,
    stop_and_go,
)
from skyquill.trajectory import PiecewisePolynomial
from skyquill.verify import verify


def _rest_to_rest(length: float, v: float, a: float, j: float) -> float:
    """Time-optimal rest-to-rest time of a 1-D jerk-limited move (closed form).

    Reaching speed ``w`` from rest takes ``t(w) = w/a + a/j`` (acceleration
    limit reached) or ``2 sqrt(w/j)``, over ``w t(w) / 2``; braking mirrors it.
    """

    def ramp(w: float) -> float:
        return w / a + a / j if w * j >= a * a else 2.0 * np.sqrt(w / j)

    if v * ramp(v) <= length:
        return 2.0 * ramp(v) + (length - v * ramp(v)) / v
    lo, hi = 0.0, v  # the peak speed w with w t(w) = length, by bisection
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if mid * ramp(mid) <= length else (lo, mid)
    return 2.0 * ramp(lo)


@pytest.mark.parametrize("length", [0.3, 2.0, 8.0, 40.0])
def test_leg_time_is_the_closed_form(length: float) -> None:
    legs = stop_and_go(np.array([[0.0, 0.0], [length, 0.0]]), LegLimits(3.0, 5.0, 3.0))
    assert legs.trajectory.duration == pytest.approx(_rest_to_rest(length, 3.0, 5.0, 3.0), rel=1e-6)


def test_diagonal_leg_uses_the_per_axis_limits_along_the_line() -> None:
    # At 45 deg each axis sees a / sqrt(2): the line may accelerate sqrt(2) times harder.
    box = LegLimits(3.0, np.array([5.0, 5.0]), np.array([3.0, 3.0]), per_axis=True)
    leg = stop_and_go(np.array([[0.0, 0.0], [6.0, 6.0]]), box).trajectory
    s2 = np.sqrt(2.0)
    assert leg.duration == pytest.approx(_rest_to_rest(6 * s2, 3.0, 5 * s2, 3 * s2), rel=1e-6)


def test_finite_differences_of_positions_respect_the_limits() -> None:
    pts = np.array([[0.0, 0.0], [8.0, 0.0], [8.0, 2.0], [0.0, 3.0]])
    traj = stop_and_go(pts, LegLimits(3.0, 5.0, 3.0)).trajectory
    t = np.arange(0.0, traj.duration, 0.001)
    p = traj.evaluate(t)
    # Finite differences of the positions (independent of Ruckig's own derivatives).
    assert (np.linalg.norm(np.diff(p, n=3, axis=0), axis=1) / 0.001**3).max() <= 3.0 * 1.001
    assert (np.linalg.norm(np.diff(p, n=2, axis=0), axis=1) / 0.001**2).max() <= 5.0 * 1.001
    assert (np.linalg.norm(np.diff(p, axis=0), axis=1) / 0.001).max() <= 3.0 + 1e-6


def test_leg_matches_ruckig_and_the_s_curve_closed_form() -> None:
    # 2 m at v 1, a 2, j 5: phases 0.4/0.1/0.4 accelerate, 1.1 cruise (the known S-curve).
    durations, _ = leg_pieces(np.zeros(2), np.array([2.0, 0.0]), LegLimits(1.0, 2.0, 5.0))
    assert durations.sum() == pytest.approx(2.9)
    inp = InputParameter(1)
    inp.current_position, inp.target_position = [0.0], [2.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [1.0], [2.0], [5.0]
    ref = Trajectory(1)
    Ruckig(1).calculate(inp, ref)
    traj = stop_and_go(np.array([[0.0, 0.0], [2.0, 0.0]]), LegLimits(1.0, 2.0, 5.0)).trajectory
    for t in np.linspace(0.0, 2.9, 37):
        p, v, a = ref.at_time(float(t))
        got = [traj.evaluate(np.array([t]), n)[0, 0] for n in range(3)]
        np.testing.assert_allclose(got, [p[0], v[0], a[0]], atol=1e-9)


def test_chain_rests_at_every_waypoint_inside_the_limits() -> None:
    pts = np.array([[0.0, 0.0, 1.0], [3.0, 0.0, 1.0], [3.0, 2.0, 1.0], [3.0, 2.0, 1.0], [0, 0, 2]])
    legs = stop_and_go(pts, LegLimits(1.5, 1.0, 3.0))
    traj = legs.trajectory
    np.testing.assert_allclose(traj.evaluate(legs.arrivals), pts, atol=1e-9)
    at_break = traj.evaluate(traj.breaks)
    gap = np.linalg.norm(at_break[:, None, :] - pts[None, :, :], axis=2).min(axis=1)
    joins = traj.breaks[gap < 1e-9]
    assert len(joins) >= 4
    np.testing.assert_allclose(traj.evaluate(joins, 1), 0.0, atol=1e-9)
    np.testing.assert_allclose(
        traj.evaluate(np.array([0.0, traj.duration])), pts[[0, -1]], atol=1e-9
    )
    check = verify(traj, vehicle_limits(3, 1.5, 1.0, 3.0, coupled_sides=64))
    assert check.max_speed <= 1.5 + 1e-9
    assert np.linalg.norm(check.max_acc) <= 1.0 * np.sqrt(3) + 1e-9


def test_per_axis_limits_along_a_diagonal() -> None:
    lim = LegLimits(2.0, np.array([1.0, 1.0]), np.array([4.0, 4.0]), per_axis=True)
    _, a, j = lim.along(np.array([1.0, 1.0]) / np.sqrt(2))
    assert a == pytest.approx(np.sqrt(2)) and j == pytest.approx(4 * np.sqrt(2))
    traj = stop_and_go(np.array([[0.0, 0.0], [5.0, 5.0]]), lim).trajectory
    acc = traj.evaluate(np.linspace(0, traj.duration, 2001), 2)
    assert np.abs(acc).max() <= 1.0 + 1e-9


def test_bad_input() -> None:
    with pytest.raises(InputError, match="waypoints: got 1 point"):
        stop_and_go(np.zeros((1, 2)), LegLimits(1.0, 1.0, 1.0))
    with pytest.raises(InputError, match="coincident"):
        stop_and_go(np.zeros((3, 2)), LegLimits(1.0, 1.0, 1.0))
    with pytest.raises(InputError, match="limits: got 1, expected one per leg"):
        stop_and_go(np.eye(3)[:, :2], [LegLimits(1.0, 1.0, 1.0)])
    with pytest.raises(InputError, match="vmax"):
        stop_and_go(np.eye(2), LegLimits(-1.0, 1.0, 1.0))


def _one_by_one(length: float, v: float, a: float, j: float, speeds: tuple[float, float]) -> float:
    """Ruckig called for one 1-D leg on its own: the reference for the batched call."""
    inp = InputParameter(1)
    inp.current_position, inp.current_velocity = [0.0], [speeds[0]]
    inp.target_position, inp.target_velocity = [length], [speeds[1]]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [v], [a], [j]
    out = Trajectory(1)
    Ruckig(1).calculate(inp, out)
    return float(out.duration)


@settings(max_examples=25, deadline=None)
@given(st.integers(1, 40), st.integers(0, 2**32 - 1), st.booleans())
def test_batched_legs_are_the_legs_timed_one_by_one(k: int, seed: int, per_axis: bool) -> None:
    rng = np.random.default_rng(seed)
    starts, ends = rng.uniform(-20, 20, (k, 3)), rng.uniform(-20, 20, (k, 3))
    lims = [
        LegLimits(
            float(rng.uniform(0.5, 5)),
            rng.uniform(0.5, 5, 3) if per_axis else float(rng.uniform(0.5, 5)),
            rng.uniform(1, 20, 3) if per_axis else float(rng.uniform(1, 20)),
            per_axis=per_axis,
        )
        for _ in range(k)
    ]
    speeds = rng.uniform(0, 1, (k, 2)) * np.array([[lim.vmax for lim in lims]]).T
    legs = legs_pieces(starts, ends, lims, speeds)
    for i in range(k):
        u = (ends[i] - starts[i]) / np.linalg.norm(ends[i] - starts[i])
        ref = _one_by_one(
            float(np.linalg.norm(ends[i] - starts[i])), *lims[i].along(u), tuple(speeds[i])
        )
        assert legs.leg_durations[i] == pytest.approx(ref, rel=1e-12, abs=1e-12)
    # The phases chain into each leg's end, at its end speed.
    ends_at = np.cumsum(legs.durations)
    traj = PiecewisePolynomial(np.r_[0.0, ends_at], legs.coeffs)
    leg_ends = np.cumsum(legs.leg_durations)
    last_piece = np.searchsorted(ends_at, leg_ends - 1e-12)
    for i, piece in enumerate(last_piece):
        tau = legs.durations[piece]
        c = traj.coeffs[piece]
        end = c[0] + tau * (c[1] + tau * (c[2] + tau * c[3]))
        assert np.allclose(end, ends[i], atol=1e-9 * 40)


def _assert_legs_are_ruckigs(
    starts: np.ndarray, ends: np.ndarray, lims: LegLimits | list[LegLimits]
) -> None:
    """Every leg is a fresh Ruckig call's profile: the same phases (durations to 1e-9 of the
    leg's, the same jerks), and the same positions, speeds and accelerations along it,
    sampled densely."""
    legs = legs_pieces(starts, ends, lims)
    breaks = np.r_[0.0, np.cumsum(legs.durations)]
    leg_starts = np.r_[0.0, np.cumsum(legs.leg_durations)]
    # The leg each piece belongs to: the one in flight at the piece's middle.
    owner = np.searchsorted(leg_starts, breaks[:-1] + legs.durations / 2) - 1
    for i, (start, end) in enumerate(zip(starts, ends, strict=True)):
        lim = lims if isinstance(lims, LegLimits) else lims[i]
        length = float(np.linalg.norm(end - start))
        u = (end - start) / length
        v, a, j = lim.along(u)
        ref = ruckig_move(length, v, a, j)
        if ref is None:
            continue
        total = float(ref.duration)
        assert legs.leg_durations[i] == pytest.approx(total, rel=1e-9)
        mine = owner == i
        jerks = legs.coeffs[mine, 3] @ u * 6.0
        profile = ref.profiles[0][0]
        ours = merged_phases(legs.durations[mine], jerks, 1e-9 * total)
        theirs = merged_phases(np.array(profile.t), np.array(profile.j), 1e-9 * total)
        assert [p[1] for p in ours] == pytest.approx([p[1] for p in theirs], rel=1e-12)
        np.testing.assert_allclose(
            [p[0] for p in ours], [p[0] for p in theirs], rtol=0, atol=1e-9 * total
        )
        leg = PiecewisePolynomial(np.r_[0.0, np.cumsum(legs.durations[mine])], legs.coeffs[mine])
        at = np.linspace(0.0, min(total, leg.duration), 41)
        want = np.array([ref.at_time(float(s))[:3] for s in at])[:, :, 0]  # (S, 3): p, v, a
        for n, scale in enumerate((max(length, 1.0), v, a)):
            got = leg.evaluate(at, n)
            expected = (start if n == 0 else 0.0) + want[:, n, None] * u
            assert np.abs(got - expected).max() <= 1e-8 * scale


# Legs up to ~3.5 km: at 0.1-0.2 m/s some take longer than Ruckig times (7,600 s), and
# those must be refused in plain words (Ruckig's binding raised a bare ValueError on them).
_LEGS = st.tuples(
    st.integers(1, 30),
    st.integers(0, 2**32 - 1),
    st.booleans(),
    st.sampled_from([1e-3, 1.0, 1e2, 1e3]),
)


@settings(max_examples=40, deadline=None)
@given(_LEGS, st.booleans())
def test_rest_to_rest_legs_are_a_fresh_ruckig_call(case: tuple, shared: bool) -> None:
    # One LegLimits for all legs (the legs that all cruise share one profile) or one per leg
    # (every leg timed on its own).
    k, seed, per_axis, scale = case
    rng = np.random.default_rng(seed)
    starts, ends = rng.uniform(-scale, scale, (k, 3)), rng.uniform(-scale, scale, (k, 3))
    lim = LegLimits(
        float(rng.uniform(0.1, 10)),
        rng.uniform(0.1, 10, 3) if per_axis else float(rng.uniform(0.1, 10)),
        rng.uniform(0.5, 100, 3) if per_axis else float(rng.uniform(0.5, 100)),
        per_axis=per_axis,
    )
    lims = lim if shared else [lim] * k
    too_long = [i for i in range(k) if _fresh_duration(starts[i], ends[i], lim) > 7.6e3]
    if too_long:
        with pytest.raises(InputError, match=rf"leg {too_long[0]},.* at most 7,600 s"):
            legs_pieces(starts, ends, lims)
    else:
        _assert_legs_are_ruckigs(starts, ends, lims)


def _fresh_duration(start: np.ndarray, end: np.ndarray, lim: LegLimits) -> float:
    """The duration of a fresh one-leg Ruckig call (one degree of freedom: never refused)."""
    length = float(np.linalg.norm(end - start))
    inp = InputParameter(1)
    inp.target_position = [length]
    v, a, j = lim.along((end - start) / length)
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [v], [a], [j]
    out = Trajectory(1)
    Ruckig(1).calculate(inp, out)
    return float(out.duration)


def test_a_leg_longer_than_ruckig_times_is_refused_naming_it() -> None:
    # 1.5 km at 0.15 m/s: about 10,000 s, beyond Ruckig's 7,600 s (its -101, which its
    # Python binding raised as "ValueError: -101 is not a valid Result").
    path = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [1500.0, 0.0], [1500.0, 1.0]])
    with pytest.raises(
        InputError,
        match=r"waypoints: got the leg from waypoint 2 to 3, 1499 m long, which takes 9,994 s "
        r"at a speed limit of 0.15 m/s, expected moves of at most 7,600 s .*add waypoints",
    ):
        stop_and_go(path, LegLimits(0.15, 1.0, 5.0))
    # Alone (one degree of freedom, where Ruckig does not check) it is refused the same way.
    with pytest.raises(InputError, match="leg 0, 1499 m long"):
        leg_pieces(np.zeros(2), np.array([1499.0, 0.0]), LegLimits(0.15, 1.0, 5.0))
    # Split as the message says, it flies.
    split = np.array([[0.0, 0.0], [750.0, 0.0], [1500.0, 0.0]])
    assert stop_and_go(split, LegLimits(0.15, 1.0, 5.0)).trajectory.duration > 9e3


def test_limits_are_checked_when_made() -> None:
    with pytest.raises(InputError, match="amax: got 0, expected a number > 0"):
        LegLimits(1.0, 0, 1.0)
    with pytest.raises(InputError, match=r"jmax: got .*expected a positive limit per axis"):
        LegLimits(1.0, 1.0, [1.0, -1.0], per_axis=True)
    with pytest.raises(
        InputError, match=r"amax: got shape \(2,\), expected a number or shape \(3,\)"
    ):
        stop_and_go(np.eye(3), LegLimits(1.0, [1.0, 2.0], 1.0, per_axis=True))


def test_pieces_too_short_for_a_long_flight_s_clock_are_dropped() -> None:
    # Past 9,000 s a phase of 1e-12 s or a little more can vanish in the clock (at
    # 20,000 s a double moves by 3.6e-12 s): such a piece is dropped, so that the breaks
    # still increase (they are not checked again).
    from skyquill.optimize.legs import _chain

    durations = np.array([2.0e4, 1.5e-12, 2.0])
    coeffs = np.arange(3 * 4 * 2, dtype=float).reshape(3, 4, 2)
    traj = _chain(durations, coeffs)
    np.testing.assert_array_equal(traj.breaks, [0.0, 2.0e4, 2.0e4 + 2.0])
    np.testing.assert_array_equal(traj.coeffs, coeffs[[0, 2]])


@pytest.mark.parametrize(("limits", "phases"), [((2.0, 3.0, 10.0), 7), ((0.5, 3.0, 10.0), 5)])
def test_legs_that_all_cruise_are_the_legs_timed_one_by_one(
    limits: tuple[float, float, float], phases: int
) -> None:
    # One LegLimits for legs that all reach its speed: one shared profile mixed into every
    # leg (seven phases, or five when the speed limit comes before the acceleration's); a
    # list of them times each leg on its own.
    rng = np.random.default_rng(7)
    pts = rng.uniform(0.0, 20.0, (31, 3))
    lim = LegLimits(*limits)
    shared = stop_and_go(pts, lim)
    one_by_one = stop_and_go(pts, [lim] * 30)
    assert shared.trajectory.n_pieces == one_by_one.trajectory.n_pieces == 30 * phases
    np.testing.assert_allclose(shared.arrivals, one_by_one.arrivals, rtol=1e-13)
    np.testing.assert_allclose(
        shared.trajectory.breaks, one_by_one.trajectory.breaks, rtol=1e-13, atol=1e-13
    )
    t = np.linspace(0.0, shared.trajectory.duration, 5001)
    for n, scale in enumerate((20.0, *limits)):
        np.testing.assert_allclose(
            shared.trajectory.evaluate(t, n),
            one_by_one.trajectory.evaluate(t, n),
            rtol=0,
            atol=1e-10 * scale,
        )
    # The waypoints are reached exactly, at rest.
    np.testing.assert_allclose(shared.trajectory.evaluate(shared.arrivals), pts, atol=1e-12)
    np.testing.assert_allclose(shared.trajectory.evaluate(shared.arrivals, 1), 0.0, atol=1e-12)
    # Legs of 0.1 mm and 0.1 m among them, too short to reach the speed limit: timed on
    # their own, the others still through the shared profile.
    pts[5] = pts[4] + [0.1, 0.0, 0.0]
    pts[9] = pts[8] + [0.0, 1e-4, 0.0]
    mixed, apart = stop_and_go(pts, lim), stop_and_go(pts, [lim] * 30)
    assert mixed.trajectory.n_pieces == apart.trajectory.n_pieces < 30 * phases
    np.testing.assert_allclose(mixed.arrivals, apart.arrivals, rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(mixed.trajectory.breaks, apart.trajectory.breaks, rtol=1e-13)
    np.testing.assert_allclose(mixed.trajectory.coeffs, apart.trajectory.coeffs, atol=1e-11)
    np.testing.assert_allclose(mixed.trajectory.evaluate(mixed.arrivals), pts, atol=1e-12)


def test_a_leg_that_reaches_the_acceleration_limit_exactly_is_timed() -> None:
    # 2 a^3 / j^2 long: Ruckig 0.19 finds no profile for it ("error in step 1"); the closed
    # form is the jerk-only profile, at a then, for 2 a / j.
    v, a, j = 2.0, 1.3, 10.4
    length = 2.0 * a**3 / j**2
    assert ruckig_move(length, v, a, j) is None
    flown = stop_and_go(np.array([[0.0, 0.0], [length, 0.0]]), LegLimits(v, a, j))
    assert flown.trajectory.duration == pytest.approx(4.0 * a / j, rel=1e-9)
    assert flown.trajectory.duration == pytest.approx(_rest_to_rest(length, v, a, j), rel=1e-9)
    assert flown.trajectory.n_pieces == 3


@pytest.mark.parametrize("first", [1.0, 0.01])
def test_a_leg_too_long_is_refused_alike_whether_or_not_the_legs_share_a_limit(
    first: float,
) -> None:
    # After a leg that cruises (all legs share one profile) or one too short to (0.05 m
    # to reach 0.15 m/s: it is timed on its own, the others share the profile), and with
    # a limit per leg (each timed on its own): the same leg named the same way.
    path = np.array([[0.0, 0.0], [first, 0.0], [first + 1499.0, 0.0]])
    lim = LegLimits(0.15, 1.0, 5.0)
    message = r"waypoints: got the leg from waypoint 1 to 2, 1499 m long, which takes 9,994 s"
    with pytest.raises(InputError, match=message):
        stop_and_go(path, lim)
    with pytest.raises(InputError, match=message):
        stop_and_go(path, [lim, lim])
    with pytest.raises(InputError, match=r"leg 1, 1499 m long"):
        legs_pieces(path[:-1], path[1:], lim)


def test_a_chain_copies_its_phase_durations_from_the_longest_chain_so_far() -> None:
    # One norm limit: each chain's phase durations are 0, then the shared profile's once a
    # leg with each leg's own cruise, from a copy of an array kept for the longest chain so
    # far, grown as longer ones come: a new array each time, whatever came before. Chains
    # longer than KEPT_LEGS tile their own.
    from skyquill.optimize.double_s import cruise
    from skyquill.optimize.legs import KEPT_LEGS, _Shared

    profile = cruise(2.0, 3.0, 10.0)
    assert profile is not None
    shared = _Shared(profile, 2.0, 3)
    handed = []
    for k in (3, 1, 10, 4, 25, 11, 60, 2, KEPT_LEGS, KEPT_LEGS + 1, 1000, KEPT_LEGS - 1, 7):
        lengths = np.random.default_rng(k).uniform(0.1, 20.0, k)
        durations = shared.durations(lengths)
        expected = np.tile(profile.durations, (k, 1))
        expected[:, profile.at_cruise] = lengths / 2.0 - profile.ramp_s
        np.testing.assert_array_equal(durations, np.r_[0.0, expected.ravel()])
        assert durations.flags.writeable and durations.flags.c_contiguous
        assert not any(np.shares_memory(durations, other) for other in handed)
        handed.append(durations)
        durations[:] = -1.0  # its owner writes the short legs' own: the next is not affected


# A chain's legs: cruising, too short to cruise, repeated points, and on the boundaries of
# the double-S profile's cases (just cruising or not, just reaching the acceleration limit).
_LEG_KINDS = st.sampled_from(["long", "short", "repeat", "cruise edge", "acceleration edge"])
_CHAIN = st.tuples(st.lists(_LEG_KINDS, min_size=1, max_size=25), st.integers(0, 2**32 - 1))


def _chain_points(kinds: list[str], seed: int, limits: tuple[float, float, float]) -> np.ndarray:
    """Waypoints (K + 1, 3) of legs of ``kinds`` in random directions under norm ``limits``."""
    v, a, j = limits
    t1 = min(a / j, np.sqrt(v / j))
    cruising_from = v * (2.0 * t1 + max(v / (j * t1) - t1, 0.0))  # vmax times the ramp
    rng = np.random.default_rng(seed)
    lengths = []
    for kind in kinds:
        if kind == "long":
            lengths.append(cruising_from * rng.uniform(1.01, 20.0))
        elif kind == "short":
            lengths.append(cruising_from * 10.0 ** rng.uniform(-7.0, -0.01))
        elif kind == "repeat":
            lengths.append(0.0)
        elif kind == "cruise edge":
            lengths.append(cruising_from * (1.0 + rng.choice([-1e-9, -1e-12, 0.0, 1e-12, 1e-9])))
        else:
            lengths.append(2.0 * a**3 / j**2 * (1.0 + rng.choice([-1e-9, 0.0, 1e-9])))
    directions = rng.normal(size=(len(kinds), 3))
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    start = rng.uniform(-10.0, 10.0, 3)
    steps = np.asarray(lengths)[:, None] * directions
    return np.vstack([start, start + np.cumsum(steps, axis=0)])


@settings(max_examples=40, deadline=None)
@given(
    st.lists(_CHAIN, min_size=1, max_size=4),
    st.tuples(st.floats(0.1, 10.0), st.floats(0.1, 10.0), st.floats(0.5, 100.0)),
    st.booleans(),
)
def test_chains_under_one_limit_are_their_legs_timed_one_by_one(
    chains: list[tuple[list[str], int]], limits: tuple[float, float, float], shared: bool
) -> None:
    # Chains of any lengths in turn under one LegLimits (the legs that cruise share one
    # profile, its phase durations kept for the longest chain so far) against the same
    # chains with a LegLimits per leg (every leg its own closed-form profile), and every
    # leg's duration against a fresh Ruckig call. With `shared`, a chain of any size with
    # legs too short to cruise takes the shared profile with their own phases written over
    # it (by default only from PARTLY_CRUISING_FROM legs).
    fewest = 1 if shared else legs_module.PARTLY_CRUISING_FROM
    with mock.patch.object(legs_module, "PARTLY_CRUISING_FROM", fewest):
        _check_chains(chains, limits)


def _check_chains(chains: list[tuple[list[str], int]], limits: tuple[float, float, float]) -> None:
    lim = LegLimits(*limits)
    for kinds, seed in chains:
        pts = _chain_points(kinds, seed, limits)
        lengths = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        scale = max(1.0, float(np.abs(pts).max()))
        if np.all(lengths <= REPEAT_TOLERANCE * scale):
            # (Repeats, or short legs within the repeat tolerance: 6.5e-9 m at 6.7 m.)
            with pytest.raises(InputError, match="coincident"):
                stop_and_go(pts, lim)
            continue
        if max(_rest_to_rest(float(x), *limits) for x in lengths) > RUCKIG_MAX_DURATION_S:
            # (An acceleration edge of 2 a^3 / j^2 = 1,000 m at 0.125 m/s: 8,001 s.)
            with pytest.raises(UntimeableLegError, match="the longest Ruckig times"):
                stop_and_go(pts, lim)
            continue
        shared, apart = stop_and_go(pts, lim), stop_and_go(pts, [lim] * len(kinds))
        np.testing.assert_allclose(shared.arrivals, apart.arrivals, rtol=1e-12, atol=1e-12)
        traj = shared.trajectory
        PiecewisePolynomial(traj.breaks, traj.coeffs)  # breaks increase, coefficients finite
        t = np.linspace(0.0, traj.duration, 2001)
        for n, size in enumerate((scale, *limits)):
            np.testing.assert_allclose(
                traj.evaluate(t, n), apart.trajectory.evaluate(t, n), rtol=0, atol=1e-9 * size
            )
        # A step within REPEAT_TOLERANCE of the scale is a repeat, skipped (5e-6 m, an
        # acceleration edge, beside a 7 km leg): the flight is that far from its point.
        repeats = REPEAT_TOLERANCE * scale * len(kinds)
        np.testing.assert_allclose(traj.evaluate(shared.arrivals), pts, atol=repeats)
        np.testing.assert_allclose(traj.evaluate(shared.arrivals, 1), 0.0, atol=1e-9 * limits[0])
        for length, took in zip(lengths, np.diff(shared.arrivals), strict=True):
            reference = ruckig_move(float(length), *limits) if took > 0.0 else None
            if reference is not None:
                assert took == pytest.approx(float(reference.duration), rel=1e-9)


def test_a_chain_longer_than_a_mixing_block_is_its_legs_timed_one_by_one() -> None:
    # Legs too short to cruise at the first and last legs of each block of MIX_BLOCK legs
    # (the pieces are mixed a block at a time, straight into the result) and at the chain's
    # ends, the rest long: the same flight as with a LegLimits per leg. (A chain that long:
    # shorter ones are timed leg by leg.)
    from skyquill.optimize.legs import MIX_BLOCK, PARTLY_CRUISING_FROM

    limits = (2.0, 3.0, 10.0)
    kinds = ["long"] * (PARTLY_CRUISING_FROM + 3)
    for k in (0, MIX_BLOCK - 1, MIX_BLOCK, 2 * MIX_BLOCK - 1, 2 * MIX_BLOCK, len(kinds) - 1):
        kinds[k] = "short"
    pts = _chain_points(kinds, 5, limits)
    lim = LegLimits(*limits)
    shared, apart = stop_and_go(pts, lim), stop_and_go(pts, [lim] * len(kinds))
    np.testing.assert_allclose(shared.arrivals, apart.arrivals, rtol=1e-12, atol=1e-12)
    t = np.linspace(0.0, shared.trajectory.duration, 20001)
    scale = float(np.abs(pts).max())
    for n, size in enumerate((scale, *limits)):
        np.testing.assert_allclose(
            shared.trajectory.evaluate(t, n),
            apart.trajectory.evaluate(t, n),
            rtol=0,
            atol=1e-9 * size,
        )


def test_waypoints_without_axes_or_finite_coordinates_are_refused_in_plain_words() -> None:
    lim = LegLimits(1.0, 1.0, 1.0)
    with pytest.raises(InputError, match=r"^waypoints: got coincident points"):
        stop_and_go(np.zeros((2, 0)), lim)  # (numpy's bare ValueError on an empty maximum)
    with pytest.raises(InputError, match=r"^waypoints: got 2 NaN or infinite value"):
        stop_and_go([[np.nan, 0.0], [1.0, np.inf]], lim)
    with pytest.raises(InputError, match=r"^waypoints: got 1 NaN or infinite value"):
        stop_and_go([[np.nan, 0.0]], lim)  # (before the count of points, as before)


@pytest.mark.filterwarnings("error")
def test_waypoints_too_far_apart_for_their_squares_are_refused_without_a_warning() -> None:
    # Squares of 1e156 m overflow: numpy warned, and the leg was "inf m long". Now its own
    # length and duration (not 157 digits), and a step past the largest float by name.
    lim = LegLimits(2.0, 1.0, 1.0)
    with pytest.raises(
        InputError, match=r"^waypoints: got the leg from waypoint 0 to 1, 1\.41421e\+200 m "
        r"long, which takes 7\.07e\+199 s at a speed limit of 2 m/s, expected moves of at "
        r"most 7,600 s",
    ):  # fmt: skip
        stop_and_go([[0.0, 0.0], [1e200, 1e200]], lim)
    with pytest.raises(InputError, match=r"^waypoints: got the leg from waypoint 1 to 2 longer "
                       r"than the largest number \(1\.8e308 m\)"):  # fmt: skip
        stop_and_go([[0.0, 0.0], [-1.7e308, 0.0], [1.7e308, 0.0]], lim)
    with pytest.raises(InputError, match=r"^waypoints: got 1 NaN or infinite value"):
        stop_and_go([[0.0, 0.0], [1e200, np.inf]], lim)


def test_a_repeat_is_a_step_within_1e_9_of_the_largest_coordinate_not_of_their_bound() -> None:
    # The threshold is REPEAT_TOLERANCE times the largest magnitude (2,990 m here); the
    # root of the sum of squares that stands in for it when no step is near (about 45 km)
    # would take the 5e-6 m step for a repeat: it is a leg, and the 5e-7 m one is skipped.
    far = np.tile([1000.0, -1000.0, 1000.0], (400, 1))
    far[1:, 0] -= np.arange(1, 400) * 10.0  # legs of 10 m
    for step, flown in ((5e-6, True), (5e-7, False)):
        pts = np.insert(far, 1, far[0] + [0.0, 0.0, step], axis=0)
        arrivals = stop_and_go(pts, LegLimits(2.0, 3.0, 10.0)).arrivals
        assert bool(arrivals[1] > 0.0) is flown
        assert arrivals.size == pts.shape[0]


def test_the_waypoints_array_is_neither_written_nor_held() -> None:
    # A float64 array is taken as it is (not copied, for the ten-leg chain's cost): the
    # flight must not change when the caller writes it afterwards, nor the array itself.
    # Every path: legs that all cruise, one too short to (1 mm), a limit per leg, a view.
    cruising = np.random.default_rng(3).uniform(0.0, 20.0, size=(11, 3))
    short = cruising.copy()
    short[1] = short[0] + 1e-3
    lim = LegLimits(2.0, 3.0, 10.0)
    cases = ((cruising, lim), (short, lim), (short, [lim] * 10), (np.repeat(short, 2, 0)[::2], lim))
    for waypoints, limits in cases:
        kept = waypoints.copy()
        flown = stop_and_go(waypoints, limits)
        np.testing.assert_array_equal(waypoints, kept)
        before = flown.trajectory.evaluate(flown.arrivals).copy()
        waypoints[...] = 0.0
        np.testing.assert_array_equal(flown.trajectory.evaluate(flown.arrivals), before)
        np.testing.assert_allclose(before, kept, atol=1e-12 * 20.0)
        waypoints[...] = kept
