"""A whole show checked: the planted violation, a safe show, several paths, the geofence start."""

from __future__ import annotations

from pathlib import Path

import pytest
from shapely.geometry import Polygon
from show_cases import plan, planted, row

from skyquill.errors import InputError
from skyquill.show import Geofence, ShowDrone, ShowLimits, check_show, load_show

FAST = ShowLimits(max_speed_xy=25.0)  # the planted flyer passes at 20 m/s


def test_planted_violation_fails_the_show() -> None:
    hover, flyer, start = planted()
    report = check_show([ShowDrone(hover, "hover"), ShowDrone(flyer, "flyer")], 3.0, FAST)
    assert not report.passed
    (v,) = report.violations
    assert (v.check, v.drones) == ("separation", ("hover", "flyer"))
    assert v.first_time_s == pytest.approx(start, abs=1e-5)
    assert v.margin < 0
    summary = report.as_dict()
    assert summary["passed"] is False
    assert summary["violations"][0]["drones"] == ["hover", "flyer"]


def test_several_paths_checked_as_one_show(tmp_path: Path) -> None:
    a = plan(tmp_path / "a", row(0.0))
    b = plan(tmp_path / "b", row(12.0))
    report = check_show(load_show([a, b]))
    assert report.passed and len(report.drones) == 6
    assert report.separation.pairs == 15
    assert 3.0 <= report.separation.lower_bound_m <= report.separation.attained_m
    # The same second plan moved onto the first one's drones fails as one show.
    c = plan(tmp_path / "c", row(1.0))
    assert not check_show(load_show([a, c])).passed


def test_a_geofence_that_excludes_the_start_is_refused(tmp_path: Path) -> None:
    drones = load_show([plan(tmp_path / "a", row(0.0))])
    fence = Geofence(Polygon([(1, -1), (5, -1), (5, 20), (1, 20)]))
    with pytest.raises(InputError, match=r"^--geofence: got a fence that excludes a/trajectory_0"):
        check_show(drones, limits=ShowLimits(geofence=fence))
