"""One more stroke appended to a planned flight: continuous to the jerk, within the limits,
faithful -- each checked on the appended flight itself, independently of how it was made."""

from __future__ import annotations

import dataclasses
import itertools
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.fidelity import planned_ink
from skyquill.calligraphy.incremental import JOIN_ORDERS, append_stroke
from skyquill.calligraphy.mission import Mission, WritingOptions, plan_writing
from skyquill.errors import InputError
from skyquill.strokes import Strokes, hanzi_strokes
from skyquill.targets import CRAZYFLIE
from skyquill.trajectory import PiecewisePolynomial

HOME = np.array([0.25, -1.0, 0.0])
OPTIONS = WritingOptions()


def _first_and_rest(char: str, first: int) -> tuple[Strokes, list[np.ndarray]]:
    """The character on the board: its first strokes to plan, the others to append (u, v)."""
    paths = hanzi_strokes(char).scaled(OPTIONS.size_m).paths
    return Strokes(paths[:first]), [np.asarray(p) for p in paths[first:]]


@pytest.fixture(scope="module", params=["home", "hover"])
def planned(request: pytest.FixtureRequest) -> tuple[Mission, list[np.ndarray]]:
    """永's first two strokes planned (from a home, or hovering), the other three to append."""
    head, rest = _first_and_rest("永", 2)
    home = HOME if request.param == "home" else None
    return plan_writing(head, Board(), OPTIONS, home=home), rest


@pytest.fixture(scope="module")
def flights(planned: tuple[Mission, list[np.ndarray]]) -> list[Mission]:
    """The planned flight, then with each remaining stroke appended in turn."""
    mission, rest = planned
    out = [mission]
    for stroke in rest:
        out.append(append_stroke(out[-1], stroke))
    return out


def test_the_flight_up_to_the_join_is_kept_and_continuous_to_the_jerk_there(
    flights: list[Mission],
) -> None:
    """Before the join the appended flight is the planned one; at the join position,
    velocity, acceleration and jerk agree from both sides (paper 003's boundary conditions)."""
    for before, after in itertools.pairwise(flights):
        join = before.join_s
        assert join is not None and isinstance(after.trajectory, PiecewisePolynomial)
        t = np.linspace(0.0, join, 400)
        np.testing.assert_allclose(
            after.trajectory.evaluate(t), before.trajectory.evaluate(t), rtol=0, atol=1e-9
        )
        for order in range(JOIN_ORDERS):
            left = before.trajectory.evaluate(np.array([join]), order)[0]
            right = after.trajectory.evaluate(np.array([join]), order)[0]  # the new part's
            scale = max(1.0, float(np.abs(left).max()))
            assert np.abs(right - left).max() <= 1e-6 * scale, (order, left, right)


def test_the_appended_flight_meets_the_limits_by_dense_check_and_ends_at_rest(
    flights: list[Mission],
) -> None:
    last = flights[-1]
    check = last.verification  # the dense check of the whole piecewise polynomial
    assert check.max_excess <= 1e-9, check.limits_report()
    end = np.array([last.trajectory.duration])
    for order in (1, 2):
        assert np.abs(last.trajectory.evaluate(end, order)).max() <= 1e-6
    if flights[0].home is not None:
        np.testing.assert_allclose(last.trajectory.evaluate(end)[0], flights[0].home, atol=1e-6)


def test_the_appended_flight_writes_every_stroke_within_the_tolerance(
    flights: list[Mission],
) -> None:
    """The ink the whole appended flight leaves, measured afresh over the whole flight:
    one ink stroke per stroke, each within 1 % of the size of its input."""
    last = flights[-1]
    deviation, contact = planned_ink(
        last.trajectory,
        last.pen_windows,
        last.strokes_world,
        last.board,
        brush=OPTIONS.brush,
        size_m=OPTIONS.size_m,
    )
    assert contact.holds, contact
    assert contact.strokes == len(flights) + 1  # two planned, one per append
    assert deviation.max_m <= OPTIONS.tolerance
    assert last.faithful
    # The appended flight's own account agrees with the fresh measurement.
    assert last.deviation.max_m == pytest.approx(deviation.max_m, rel=0.05, abs=2e-4)


def test_an_appended_stroke_equals_the_same_stroke_planned_in_one_go_in_ink() -> None:
    """Appending is not a worse way to write: the appended 人 leaves ink as close to its
    input as the character planned whole (both within the tolerance)."""
    head, rest = _first_and_rest("人", 1)
    whole = plan_writing(Strokes([*head.paths, *rest]), Board(), OPTIONS)
    appended = append_stroke(plan_writing(head, Board(), OPTIONS), rest[0])
    assert appended.faithful and whole.faithful
    assert len(appended.pen_windows) == len(whole.pen_windows) == 2


@settings(
    max_examples=8,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(
    points=st.lists(
        st.tuples(st.floats(0.05, 0.45), st.floats(0.05, 0.45)), min_size=2, max_size=6
    ).filter(lambda p: np.linalg.norm(np.diff(np.array(p), axis=0), axis=1).sum() > 0.02)
)
def test_random_strokes_append_faithfully_within_the_limits(
    planned: tuple[Mission, list[np.ndarray]], points: list[tuple[float, float]]
) -> None:
    """Any stroke on the board appends: continuous at the join, limits met densely,
    written within the tolerance (or refused with the measured deviation)."""
    mission = planned[0]
    appended = append_stroke(mission, np.array(points))
    join = mission.join_s
    assert join is not None
    for order in range(JOIN_ORDERS):
        left = mission.trajectory.evaluate(np.array([join]), order)[0]
        right = appended.trajectory.evaluate(np.array([join]), order)[0]
        assert np.abs(right - left).max() <= 1e-6 * max(1.0, float(np.abs(left).max()))
    assert appended.verification.max_excess <= 1e-9
    assert appended.faithful


@pytest.mark.parametrize(
    ("stroke", "expected"),
    [
        (np.zeros((3, 3)), "expected (K, 2)"),
        (np.zeros((1, 2)), "expected (K, 2) with 2 <= K"),
        (np.full((2, 2), 0.2), "non-zero length"),
        (np.array([[0.1, 0.1], [0.9, 0.1]]), "within the character's square"),
        (np.array([[0.1, np.nan], [0.2, 0.1]]), "stroke"),
        ("a stroke", "stroke"),
    ],
)
def test_bad_strokes_are_refused_naming_the_argument(stroke: object, expected: str) -> None:
    head, _ = _first_and_rest("人", 1)
    mission = plan_writing(head, Board(), OPTIONS)
    with pytest.raises(InputError, match=re.escape(expected)) as info:
        append_stroke(mission, stroke)  # type: ignore[arg-type]
    assert str(info.value).startswith("stroke: got")


def test_a_flight_split_into_uploads_is_refused() -> None:
    head, rest = _first_and_rest("人", 1)
    split = plan_writing(head, Board(), dataclasses.replace(OPTIONS, target=CRAZYFLIE))
    with pytest.raises(InputError, match="mission: got a flight split into uploads"):
        append_stroke(split, rest[0])


def test_a_join_rounded_past_the_flights_last_break_keeps_every_piece() -> None:
    """The join at a flight's end can round a few ulps past its last break (L / alpha):
    every piece of the flight is kept, the last one ending at the join (中 from a hover
    met it after a change of rounding elsewhere)."""
    from skyquill.calligraphy.incremental import _concatenated
    from skyquill.trajectory import SplineTrajectory

    rng = np.random.default_rng(4)
    before = SplineTrajectory(rng.normal(size=(12, 3)), 5, 1.3)
    after = SplineTrajectory(rng.normal(size=(9, 3)), 5, 0.7)
    last = float(before.breakpoints[-1])
    join = float(np.nextafter(np.nextafter(last, np.inf), np.inf))
    joined = _concatenated(before, join, after)
    assert joined.coeffs.shape[0] == 7 + 4  # every piece of both
    t = np.linspace(0.0, 0.999 * last, 50)
    np.testing.assert_allclose(joined.evaluate(t), before.evaluate(t), rtol=0, atol=1e-9)
