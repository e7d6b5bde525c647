"""A tuned spiral mission's pieces: the budget share of each spiral, the zigzag that replaces one.

Covers :func:`skyquill.coverage.plan.pieces.spiral_or_zigzag` and the tuned
zigzag fallback of :func:`skyquill.coverage.plan.plan_tuned`'s missions.
"""

from __future__ import annotations

import pytest
from shapely.geometry import Polygon, box

from skyquill.coverage.deadline import Deadline
from skyquill.coverage.plan import CoverageOptions, CoveragePlan, plan_tuned, tuning
from skyquill.coverage.plan.pieces import (
    MAX_SPIRAL_SHARE,
    SPIRAL_SHARE,
    spiral_or_zigzag,
    spiral_share,
)
from skyquill.coverage.plan.planner import zigzag_piece
from skyquill.coverage.regions import load_region
from skyquill.errors import InfeasibleError

#: An L with a square hole: spiral pieces of 40 to 96 m² at the default 2 m swath.
L_WITH_HOLE = (
    "POLYGON ((0 0, 20 0, 20 8, 8 8, 8 20, 0 20, 0 0), (12 2.5, 15 2.5, 15 5.5, 12 5.5, 12 2.5))"
)
GOAL = 0.99
PIECE_GOAL = 1.0 - tuning.MISSION_MISS_SHARE * (1.0 - GOAL)


def test_small_pieces_keep_a_quarter_and_large_ones_get_more_up_to_half() -> None:
    assert spiral_share(108.0, 94_696.0) == SPIRAL_SHARE
    # The 10 ha field's 2.2 ha part: twice its 23 % of the area.
    assert spiral_share(21_823.0, 94_696.0) == pytest.approx(2 * 21_823.0 / 94_696.0)
    assert spiral_share(9e4, 1e5) == MAX_SPIRAL_SHARE


def test_the_spiral_gets_its_share_of_the_remaining_budget() -> None:
    budgets: list[float] = []

    def spiral(piece: Polygon, deadline: Deadline) -> CoveragePlan:
        budgets.append(deadline.limit_s)
        raise InfeasibleError("spiral: cannot be timed", ("speed_lp",))

    def zigzag(piece: Polygon, deadline: Deadline) -> CoveragePlan:
        budgets.append(deadline.remaining())
        return None  # type: ignore[return-value]  # not looked at

    for area in (100.0, 2000.0):
        spiral_or_zigzag(box(0, 0, area / 10, 10), Deadline(100.0), spiral=spiral,
                         zigzag=zigzag, field_area=1e4)  # fmt: skip
    (small, small_zigzag), (large, large_zigzag) = budgets[:2], budgets[2:]
    assert small == pytest.approx(SPIRAL_SHARE * 100.0, rel=1e-3)
    assert large == pytest.approx(2 * 0.2 * 100.0, rel=1e-3)
    # The zigzag that replaces a spiral has the whole budget left.
    assert min(small_zigzag, large_zigzag) > 99.0


def test_the_fallback_zigzag_is_tuned_to_the_pieces_goal() -> None:
    piece = box(0, 0, 9, 7)
    options = CoverageOptions(time_limit=60.0)
    plain = zigzag_piece(piece, Deadline(60.0), options=options)
    tuned = tuning._tuned_zigzag_piece(piece, Deadline(60.0), options=options, goal=PIECE_GOAL)
    assert plain.coverage < PIECE_GOAL <= tuned.coverage
    assert tuned.options.pattern == "zigzag"


def test_a_piece_no_zigzag_covers_is_flown_by_the_plain_zigzag() -> None:
    # Its 45° corners are out of the swath's reach (the triangles an octagonal obstacle leaves).
    triangle = Polygon([(0, 0), (6, 0), (0, 6)])
    options = CoverageOptions(time_limit=60.0)
    with pytest.raises(InfeasibleError, match="min_coverage"):
        tuning._tuned(triangle, CoverageOptions(pattern="zigzag"), PIECE_GOAL, Deadline(60.0))
    flown = tuning._tuned_zigzag_piece(triangle, Deadline(60.0), options=options, goal=PIECE_GOAL)
    plain = zigzag_piece(triangle, Deadline(60.0), options=options)
    assert flown.duration == plain.duration and flown.coverage == plain.coverage


def test_a_mission_whose_spirals_all_fail_still_reaches_its_goal(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    def no_spiral(piece: Polygon, deadline: Deadline, **kwargs: object) -> CoveragePlan:
        raise InfeasibleError("spiral: cannot be timed", ("speed_lp",))

    monkeypatch.setattr(tuning, "_tuned_piece", no_spiral)
    region = load_region(L_WITH_HOLE)
    plan = plan_tuned(region, CoverageOptions(pattern="spiral", time_limit=60.0), GOAL)
    assert plan.coverage >= GOAL
    assert plan.summary()["keepout"]["passed"]
    # The plain zigzags it replaced miss the goal.
    monkeypatch.setattr(tuning, "_tuned_zigzag_piece", _plain_zigzag)
    with pytest.raises(InfeasibleError, match="min_coverage"):
        plan_tuned(region, CoverageOptions(pattern="spiral", time_limit=60.0), GOAL)


def _plain_zigzag(
    piece: Polygon, deadline: Deadline, *, options: CoverageOptions, goal: float
) -> CoveragePlan:
    """The fallback before session 36: the zigzag at the options' spacing, no perimeter lap."""
    return zigzag_piece(piece, deadline, options=options)
