"""PX4 offboard setpoints: ENU z-up world to NED at the boundary."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from skyquill.errors import InputError
from skyquill.io.px4 import (
    PX4_COLUMNS,
    Px4Setpoints,
    px4_setpoints,
    send_mavsdk,
    yaw_enu_to_ned_deg,
)
from skyquill.trajectory import SplineTrajectory


def line(velocity_enu: tuple[float, float, float], duration: float = 2.0) -> SplineTrajectory:
    """Straight line from (1, 2, 3) at constant ``velocity_enu`` (m/s), degree 1."""
    start = np.array([1.0, 2.0, 3.0])
    ctrl = np.stack([start, start + duration * np.asarray(velocity_enu)])
    return SplineTrajectory(ctrl, 1, duration)


def test_moving_east_is_ned_east() -> None:
    sp = px4_setpoints(line((1.0, 0.0, 0.0)), rate_hz=10.0)
    np.testing.assert_allclose(sp.velocity_ned, np.tile([0.0, 1.0, 0.0], (len(sp), 1)), atol=1e-12)
    np.testing.assert_allclose(sp.position_ned[0], [2.0, 1.0, -3.0], atol=1e-12)
    np.testing.assert_allclose(sp.position_ned[-1], [2.0, 3.0, -3.0], atol=1e-12)


def test_moving_north_and_climbing() -> None:
    sp = px4_setpoints(line((0.0, 1.0, 0.5)), rate_hz=10.0)
    np.testing.assert_allclose(sp.velocity_ned[:, 0], 1.0, atol=1e-12)  # north
    np.testing.assert_allclose(sp.velocity_ned[:, 1], 0.0, atol=1e-12)
    np.testing.assert_allclose(sp.velocity_ned[:, 2], -0.5, atol=1e-12)  # climbing: down < 0
    assert np.all(np.diff(sp.position_ned[:, 2]) < 0)


def test_acceleration_maps_like_position() -> None:
    # z(t) = t^2 (m) in ENU: acceleration up 2 m/s^2, i.e. down -2 in NED
    traj = SplineTrajectory(np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]]), 2, 1.0)
    sp = px4_setpoints(traj, rate_hz=20.0)
    np.testing.assert_allclose(sp.acceleration_ned, np.tile([0.0, 0.0, -2.0], (len(sp), 1)))


@pytest.mark.parametrize(
    ("yaw_enu", "yaw_ned"),
    [
        (0.0, 90.0),  # facing east
        (np.pi / 2, 0.0),  # facing north
        (np.pi, -90.0),  # facing west
        (-np.pi / 2, 180.0),  # facing south: the wrap keeps +180
        (3 * np.pi / 2, 180.0),
        (np.pi / 4, 45.0),  # north-east
    ],
)
def test_yaw_mapping(yaw_enu: float, yaw_ned: float) -> None:
    assert float(yaw_enu_to_ned_deg(yaw_enu)) == pytest.approx(yaw_ned, abs=1e-9)
    sp = px4_setpoints(line((1.0, 0.0, 0.0)), rate_hz=5.0, yaw_enu_rad=yaw_enu)
    np.testing.assert_allclose(sp.yaw_deg, yaw_ned, atol=1e-9)


def test_yaw_range_is_half_open() -> None:
    yaw = yaw_enu_to_ned_deg(np.linspace(-10.0, 10.0, 1001))
    assert np.all(yaw > -180.0) and np.all(yaw <= 180.0)


def test_rate_and_count() -> None:
    sp = px4_setpoints(line((1.0, 0.0, 0.0), duration=2.0), rate_hz=50.0)
    assert len(sp) == 101 and sp.t.shape == (101,)
    assert sp.position_ned.shape == sp.velocity_ned.shape == sp.acceleration_ned.shape == (101, 3)
    np.testing.assert_allclose(np.diff(sp.t), 0.02)
    assert sp.t[-1] == pytest.approx(2.0)
    assert sp.rate_hz == 50.0


@pytest.mark.parametrize(
    ("rate", "match"),
    [
        (0.0, "rate_hz: got 0, expected a number > 0"),
        (1.0, "rate_hz: got 1, expected a rate from 2 to 1000 Hz"),
        (5000.0, "rate_hz: got 5000"),
        (float("nan"), "rate_hz: got nan"),
        ("50", "rate_hz: got '50', expected a number"),
    ],
)
def test_bad_rate(rate: object, match: str) -> None:
    with pytest.raises(InputError, match=match):
        px4_setpoints(line((1.0, 0.0, 0.0)), rate_hz=rate)  # type: ignore[arg-type]


def test_bad_yaw() -> None:
    with pytest.raises(InputError, match="yaw_enu_rad: got inf"):
        px4_setpoints(line((1.0, 0.0, 0.0)), yaw_enu_rad=float("inf"))


def test_to_csv(tmp_path: Path) -> None:
    sp = px4_setpoints(line((1.0, 0.0, 0.0)), rate_hz=10.0, yaw_enu_rad=np.pi / 2)
    n = sp.to_csv(tmp_path / "px4.csv")
    text = (tmp_path / "px4.csv").read_text(encoding="utf-8").splitlines()
    assert text[0] == ",".join(PX4_COLUMNS)
    assert n == len(sp) == len(text) - 1
    table = np.loadtxt(tmp_path / "px4.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(table, sp.table(), atol=1e-8)


def test_dry_run_counts_and_does_not_import_mavsdk(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "mavsdk", None)  # any import would fail
    sp = px4_setpoints(line((1.0, 0.0, 0.0)), rate_hz=25.0)
    assert send_mavsdk(sp) == len(sp) == 51


def test_send_without_mavsdk_is_input_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "mavsdk", None)
    sp = px4_setpoints(line((1.0, 0.0, 0.0)), rate_hz=25.0)
    with pytest.raises(InputError, match="pip install mavsdk"):
        send_mavsdk(sp, dry_run=False)


def test_send_needs_setpoints() -> None:
    with pytest.raises(InputError, match="setpoints: got list, expected Px4Setpoints"):
        send_mavsdk([], dry_run=True)  # type: ignore[arg-type]


def test_setpoints_is_frozen() -> None:
    sp = px4_setpoints(line((1.0, 0.0, 0.0)), rate_hz=10.0)
    assert isinstance(sp, Px4Setpoints)
    with pytest.raises(AttributeError):
        sp.rate_hz = 5.0  # type: ignore[misc]
