"""The keep-out check: closest approaches, the spraying margin, its verdict."""

from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import box

from skyquill.coverage.keepout import check_keepout
from skyquill.errors import InputError

HOLE = box(4, 4, 6, 6)


def test_a_flight_clear_of_the_hole_passes_and_reports_its_closest_approach() -> None:
    line = np.column_stack([np.linspace(0, 10, 11), np.full(11, 7.5), np.full(11, 2.0)])
    check = check_keepout(line, np.ones(11), [HOLE], 1.0)
    assert check.passed
    assert check.holes[0].closest_m == pytest.approx(1.5)
    assert check.holes[0].closest_spraying_m == pytest.approx(1.5)
    assert check.summary()["holes"][0]["closest_m"] == pytest.approx(1.5)


def test_spraying_within_the_margin_fails_but_not_with_the_spray_off() -> None:
    line = np.column_stack([np.linspace(0, 10, 11), np.full(11, 6.5)])
    assert not check_keepout(line, np.ones(11), [HOLE], 1.0).passed
    off = (line[:, 0] < 2.5) | (line[:, 0] > 7.5)
    check = check_keepout(line, off, [HOLE], 1.0)
    assert check.passed
    assert check.holes[0].closest_m == pytest.approx(0.5)
    assert check.holes[0].closest_spraying_m == pytest.approx(np.hypot(2.0, 0.5))


def test_crossing_a_hole_between_two_samples_fails() -> None:
    # Both samples are outside the hole; the leg between them is not.
    check = check_keepout(np.array([[0.0, 5.0], [10.0, 5.0]]), [False, False], [HOLE], 1.0)
    assert not check.passed
    assert check.holes[0].closest_m == 0.0
    assert check.holes[0].closest_spraying_m is None


def test_bad_arguments_are_named() -> None:
    with pytest.raises(InputError, match="spraying: got shape"):
        check_keepout(np.zeros((3, 2)), [True], [HOLE], 1.0)
    with pytest.raises(InputError, match="margin: got -1"):
        check_keepout(np.zeros((3, 2)), [True] * 3, [HOLE], -1.0)
    with pytest.raises(InputError, match="positions: got shape"):
        check_keepout(np.zeros((3, 4)), [True] * 3, [HOLE], 1.0)
