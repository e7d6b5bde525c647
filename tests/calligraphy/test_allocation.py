"""The time allocation: looser limits never give a slower flight, and why."""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.mission import WritingOptions, plan_writing, tip_offset
from skyquill.calligraphy.route import build_route
from skyquill.calligraphy.timing import TimingBounds, route_times
from skyquill.errors import InfeasibleError
from skyquill.limits import VehicleLimits
from skyquill.strokes import hanzi_strokes

#: Where ``skyquill write`` puts one drone's home (calligraphy.show.layout), m.
HOME = np.array([0.25, -1.0, 0.0])
#: Bundled characters of few strokes: the property is the same, the test stays fast.
SMALL = "人八十口三大川山"
#: The issue's four nested limit sets (bench/timing_monotone.py measures ten characters).
ISSUE_SETS = ((1.0, 2.0, 10.0), (2.0, 4.0, 40.0), (5.0, 10.0, 100.0), (20.0, 50.0, 1000.0))


def _duration(char: str, bounds: tuple[float, float, float]) -> float:
    opts = dataclasses.replace(WritingOptions(), limits=VehicleLimits(*bounds))
    mission = plan_writing(hanzi_strokes(char), Board(), opts, home=HOME)
    assert mission.faithful and mission.verification.max_excess <= 1e-9
    return mission.trajectory.duration


limits = st.tuples(st.floats(0.5, 5.0), st.floats(1.0, 20.0), st.floats(5.0, 200.0))
looser = st.tuples(st.floats(1.0, 4.0), st.floats(1.0, 4.0), st.floats(1.0, 4.0))


@settings(max_examples=6, deadline=None)
@given(char=st.sampled_from(SMALL), tight=limits, factors=looser)
def test_looser_limits_never_give_a_slower_flight(
    char: str, tight: tuple[float, float, float], factors: tuple[float, float, float]
) -> None:
    """A bundled character at random limits and at a random looser set (every limit
    raised by up to 4x): the looser flight takes at most 1.01x the tighter one's time."""
    loose = tuple(t * f for t, f in zip(tight, factors, strict=True))
    try:
        tighter = _duration(char, tight)
    except InfeasibleError:
        return  # nothing to compare against (the looser set must still plan: below)
    assert _duration(char, loose) <= 1.01 * tighter  # type: ignore[arg-type]


#: Limits whose jerk is low for their acceleration (not of the pace's shape): the plan at
#: the probe's pace strays and steps down (bench/timing_strays.py draws the same).
straying = st.tuples(
    st.sampled_from([0.5, 1.0, 2.0]),
    st.sampled_from([1.0, 2.0, 4.0]),
    st.sampled_from([5.0, 8.0, 12.0]),
)


@settings(max_examples=6, deadline=None)
@given(char=st.sampled_from(SMALL), tight=straying, raised=st.integers(0, 2),
       factor=st.sampled_from([2.0, 3.0, 4.0]))  # fmt: skip
def test_looser_limits_never_give_a_slower_flight_where_plans_stray(
    char: str, tight: tuple[float, float, float], raised: int, factor: float
) -> None:
    """The property above where the flown plan strays from its probe: one limit of a set
    whose jerk is low for its acceleration raised 2-4x."""
    loose = tuple(t * factor if k == raised else t for k, t in enumerate(tight))
    try:
        tighter = _duration(char, tight)
    except InfeasibleError:
        return
    assert _duration(char, loose) <= 1.01 * tighter  # type: ignore[arg-type]


def test_a_plan_that_strays_at_its_probes_pace_is_flown_at_the_highest_faithful_one() -> None:
    # (1, 4, 5): the probe at the full pace (sqrt 2) is faithful, the plan there strays
    # (the timing accelerates at 4 m/s² where the jerk is held to 5 m/s³) and steps down,
    # in steps that double, to where it writes faithfully: it went past 0 (the timing of
    # (1, 2, 5), 15.2 s) to -0.42 (16.1 s); now the last step is halved back.
    assert _duration("人", (1.0, 4.0, 5.0)) <= 1.01 * _duration("人", (1.0, 2.0, 5.0))


@pytest.mark.parametrize("char", ["中", "永"])
def test_the_issues_limit_sets_give_non_increasing_durations(char: str) -> None:
    durations = [_duration(char, bounds) for bounds in ISSUE_SETS]
    for tighter, looser_one in itertools.pairwise(durations):
        assert looser_one <= 1.01 * tighter, durations


def test_below_both_vehicles_limits_a_pace_times_the_writing_alike() -> None:
    """The argument of the monotonicity: at a pace below two vehicles' limits the writing
    is timed the same (only the legs from home cruise at each one's speed limit)."""
    board, char = Board(), "永"
    base = WritingOptions()
    strokes = tuple(board.to_world(p) for p in hanzi_strokes(char).scaled(0.5).paths)
    samples = build_route(strokes, board, HOME - tip_offset(board, base), 0.001)
    slow, fast = VehicleLimits(1.0, 2.0, 10.0), VehicleLimits(4.0, 30.0, 700.0)
    pace = 0.8  # below both: 0.8 < 1 m/s, 2 * 0.64 < 2 m/s^2, 10 * 0.512 < 10 m/s^3
    times = [
        route_times(
            samples.points, samples.roles, board, dataclasses.replace(base, limits=lim), pace
        )
        for lim in (slow, fast)
    ]
    lifts = np.flatnonzero(samples.roles == -2)
    writing = slice(int(lifts[0]), int(lifts[-1]) + 1)
    np.testing.assert_allclose(np.diff(times[0][writing]), np.diff(times[1][writing]))
    assert times[1][-1] <= times[0][-1]  # the legs home cruise faster on the faster vehicle


@given(
    bounds=st.tuples(st.floats(0.1, 50.0), st.floats(0.1, 100.0), st.floats(0.1, 1e4)),
    pace=st.floats(0.01, 100.0),
    factor=st.floats(1.0, 10.0),
)
def test_timing_bounds_are_monotone_in_the_pace_and_the_limits(
    bounds: tuple[float, float, float], pace: float, factor: float
) -> None:
    full = TimingBounds(*bounds)
    capped = full.at_pace(pace)
    faster = full.at_pace(pace * factor)
    looser = TimingBounds(*(b * factor for b in bounds)).at_pace(pace)
    for a, b, c, limit in zip(
        (capped.vmax, capped.amax, capped.jmax),
        (faster.vmax, faster.amax, faster.jmax),
        (looser.vmax, looser.amax, looser.jmax),
        bounds,
        strict=True,
    ):
        assert a is not None and b is not None and c is not None
        assert a <= limit and a <= b and a <= c
    assert full.at_pace(full.full_pace) == full  # the full pace gives the limits back
    assert full.at_pace(0.5 * full.full_pace) != full  # and no slower pace does


def test_the_initial_flight_time_is_the_unstretched_plans_duration() -> None:
    """The studio's estimate (no solve) is what plan_writing starts from: equal when unstretched."""
    from skyquill.calligraphy.mission import initial_flight_time
    from skyquill.calligraphy.show import layout
    from skyquill.strokes import text_strokes

    strokes = text_strokes("L")
    board, home = layout(1, 0.5, 1.0)[0]
    opts = WritingOptions(resegment="off")
    mission = plan_writing(strokes, board, opts, home=home)
    assert mission.time_scale == 1.0
    estimate = initial_flight_time(strokes, board, opts, home)
    assert estimate == pytest.approx(mission.trajectory.duration, rel=1e-9)


@settings(max_examples=4, deadline=None)
@given(char=st.sampled_from(SMALL), tight=limits)
def test_the_initial_flight_time_bounds_the_planned_duration_from_below(
    char: str, tight: tuple[float, float, float]
) -> None:
    """A cheap lower bound for any limits: the search only slows the writing down."""
    from skyquill.calligraphy.mission import initial_flight_time

    opts = dataclasses.replace(WritingOptions(), limits=VehicleLimits(*tight))
    try:
        mission = plan_writing(hanzi_strokes(char), Board(), opts, home=HOME)
    except InfeasibleError:
        return
    bound = initial_flight_time(hanzi_strokes(char), Board(), opts, HOME)
    assert bound <= mission.trajectory.duration * (1.0 + 1e-9)
    assert mission.trajectory.duration == pytest.approx(bound * mission.time_scale, rel=1e-9)
