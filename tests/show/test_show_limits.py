"""Per-drone limits: each found at its first time with its margin; defaults are Skybrush's."""

from __future__ import annotations

import pytest
from shapely.geometry import Polygon
from show_cases import line, move

from skyquill.errors import InputError
from skyquill.show import Geofence, ShowDrone, ShowLimits
from skyquill.show.limits import check_limits, check_start


def test_defaults_are_skybrush_studio_fallbacks() -> None:
    limits = ShowLimits()
    assert (limits.max_speed_xy, limits.max_speed_up, limits.max_speed_down) == (8.0, 2.0, 2.0)
    assert (limits.max_acceleration, limits.max_altitude, limits.min_altitude) == (4.0, 150.0, None)


def test_each_limit_is_found_with_first_time_and_margin() -> None:
    fast = ShowDrone(line([0, 0, 10], [9, 0, -3], 2.0), "fast", start_s=1.0)
    violations, measured = check_limits([fast], ShowLimits(min_altitude=5.0))
    found = {v.check: v for v in violations}
    assert set(found) == {"speed_xy", "speed_down", "min_altitude"}
    assert found["speed_xy"].first_time_s == 1.0
    assert found["speed_xy"].margin == pytest.approx(-1.0)
    assert found["speed_down"].margin == pytest.approx(-1.0)
    # z = 10 - 3 t falls below 5 m after 5/3 s of its own clock
    assert found["min_altitude"].first_time_s == pytest.approx(1.0 + 5.0 / 3.0, abs=1e-3)
    assert found["min_altitude"].worst == pytest.approx(4.0)
    assert found["min_altitude"].margin == pytest.approx(-1.0)
    assert {m.check for m in measured} >= {"speed_xy", "acceleration", "max_altitude"}


def test_a_gentle_move_passes() -> None:
    violations, _ = check_limits([ShowDrone(move([0, 0, 1], [3, 0, 2], 6.0), "m")], ShowLimits())
    assert violations == ()


def test_geofence_breach_and_ceiling() -> None:
    fence = Geofence(Polygon([(-1, -1), (2, -1), (2, 1), (-1, 1)]), ceiling_m=1.5)
    drone = ShowDrone(line([0, 0, 1], [1, 0, 0.25], 4.0), "d")
    violations, _ = check_limits([drone], ShowLimits(geofence=fence))
    found = {v.check: v for v in violations}
    assert found["geofence"].first_time_s == pytest.approx(2.0, abs=1e-3)
    assert found["geofence"].margin == pytest.approx(-2.0)
    assert found["geofence_ceiling"].first_time_s == pytest.approx(2.0, abs=1e-3)


def test_a_geofence_that_excludes_the_start_is_an_input_error() -> None:
    fence = Geofence(Polygon([(1, 1), (2, 1), (2, 2), (1, 2)]))
    drone = ShowDrone(line([0, 0, 1], [1, 1, 0], 4.0), "d0")
    with pytest.raises(InputError, match=r"--geofence: got a fence that excludes d0's start"):
        check_start([drone], fence)


def test_bad_limits_are_refused() -> None:
    with pytest.raises(InputError, match=r"max_speed_xy: got -1"):
        ShowLimits(max_speed_xy=-1.0)
    with pytest.raises(InputError, match=r"min_altitude: got 5 m above max_altitude 2 m"):
        ShowLimits(min_altitude=5.0, max_altitude=2.0)
