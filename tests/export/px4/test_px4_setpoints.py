"""PX4 offboard setpoints: ENU z-up world to NED at the boundary."""

from __future__ import annotations

import asyncio
import dataclasses
import socket
import sys
import time
import types
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from skyquill.errors import InputError, SolverError
from skyquill.export.px4.setpoints import (
    PX4_COLUMNS,
    MavsdkSystem,
    Px4Setpoints,
    px4_setpoints,
    send_mavsdk,
    yaw_enu_to_ned_deg,
)
from skyquill.trajectory import SplineTrajectory
from skyquill.validation import FloatArray


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
        (1.0, "rate_hz: got 1, expected a rate above 2 and up to 1000 Hz"),
        (2.0, "rate_hz: got 2, expected a rate above 2"),
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
    with pytest.raises(InputError, match=r"not installed; expected it installed \(pip install"):
        send_mavsdk(sp, dry_run=False)


def test_send_with_grpc_mavsdk_is_input_error(monkeypatch: pytest.MonkeyPatch) -> None:
    # mavsdk < 4 (the gRPC wrapper) has no mavsdk.asyncio
    old = types.ModuleType("mavsdk")
    old.__version__ = "3.0.0"  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "mavsdk", old)
    monkeypatch.setitem(sys.modules, "mavsdk.asyncio", None)
    sp = px4_setpoints(line((1.0, 0.0, 0.0)), rate_hz=25.0)
    with pytest.raises(InputError, match=r"mavsdk 3.0.0 installed, .*expected mavsdk>=4.1,<5"):
        send_mavsdk(sp, dry_run=False)


class FakeSystem:
    """A PX4 stand-in with the async methods send_mavsdk calls; records every call.

    Its take-off climbs to the asked height in three polls (never, with ``climbs=False``);
    its landing reaches the ground in two.
    """

    def __init__(self, connects: bool = True, climbs: bool = True) -> None:
        self.connects = connects
        self.climbs = climbs
        self.calls: list[str] = []
        self.sent: list[tuple[float, tuple[float, ...]]] = []  # (loop time, setpoint row)
        self.offboard_active = False
        self.closed = False
        self.target = 0.0
        self.z = 0.0
        self.polls = 0

    async def set_parameter(self, name: str, value: float) -> None:
        self.calls.append(f"{name} {value:g}")

    async def arm(self) -> None:
        self.calls.append("arm")

    async def takeoff(self, altitude_m: float) -> None:
        self.calls.append(f"takeoff {altitude_m:g}")
        self.target = altitude_m

    async def height(self) -> tuple[bool, float]:
        self.polls += 1
        if self.climbs:
            self.z = min(self.target, self.z + self.target / 3)
        return self.z > 0.0, self.z

    async def land(self) -> None:
        self.calls.append("land")

    async def landed(self) -> bool:
        self.z = max(0.0, self.z - self.target / 2)
        return self.z == 0.0

    async def connect(self, system_address: str) -> None:
        self.calls.append(f"connect {system_address}")

    async def wait_connected(self) -> None:
        self.calls.append("wait_connected")
        if not self.connects:
            await asyncio.Event().wait()  # a vehicle that never answers

    def setpoint(
        self, position_ned: FloatArray, velocity_ned: FloatArray, accel_ned: FloatArray, yaw: float
    ) -> tuple[Any, Any, Any]:
        return ((*position_ned, yaw), (*velocity_ned, yaw), tuple(accel_ned))

    async def set_position_velocity_acceleration_ned(self, p: Any, v: Any, a: Any) -> None:
        self.calls.append("setpoint")
        self.sent.append((asyncio.get_running_loop().time(), (*p, *v, *a)))

    async def start_offboard(self) -> None:
        # PX4 refuses offboard unless a setpoint came first
        assert self.sent, "offboard started before any setpoint"
        self.calls.append("start")
        self.offboard_active = True

    async def stop_offboard(self) -> None:
        self.calls.append("stop")
        self.offboard_active = False

    def close(self) -> None:
        self.closed = True


def test_fake_system_sees_the_offboard_sequence() -> None:
    sp = px4_setpoints(line((1.0, 0.0, 0.0), duration=0.4), rate_hz=50.0, yaw_enu_rad=np.pi / 2)
    fake = FakeSystem()
    n = send_mavsdk(sp, "udpin://0.0.0.0:14540", dry_run=False, system_factory=lambda: fake)
    assert n == len(sp) == 21
    assert fake.calls == (
        ["connect udpin://0.0.0.0:14540", "wait_connected", "arm", "takeoff 3"]
        + ["setpoint", "start"]
        + ["setpoint"] * len(sp)
        + ["stop", "land"]
    )
    assert fake.z == 0.0  # landed: waited for
    assert fake.closed and not fake.offboard_active
    # every row arrives, in order, as the NED setpoint (yaw 0 = north)
    rows = np.array([row for _, row in fake.sent[1:]])
    np.testing.assert_allclose(rows[:, 0:3], sp.position_ned)
    np.testing.assert_allclose(rows[:, 3], 0.0, atol=1e-12)
    np.testing.assert_allclose(rows[:, 4:7], sp.velocity_ned)
    np.testing.assert_allclose(rows[:, 8:11], sp.acceleration_ned)
    np.testing.assert_allclose(fake.sent[0][1], fake.sent[1][1])  # the pre-start setpoint is row 0
    # streamed at the requested rate: 20 periods of 20 ms, by the absolute schedule
    times = np.array([t for t, _ in fake.sent[1:]])
    assert times[-1] - times[0] == pytest.approx(20 * 0.02, abs=0.1)
    assert np.median(np.diff(times)) == pytest.approx(0.02, abs=0.005)


def test_stop_runs_after_a_failed_send() -> None:
    class Failing(FakeSystem):
        async def set_position_velocity_acceleration_ned(self, p: Any, v: Any, a: Any) -> None:
            await super().set_position_velocity_acceleration_ned(p, v, a)
            if len(self.sent) == 3:
                await asyncio.Event().wait()  # the link stalls

    fake = Failing()
    sp = px4_setpoints(line((1.0, 0.0, 0.0), duration=0.2), rate_hz=50.0)
    with pytest.raises(
        SolverError, match=r"send_timeout_s: got 0.05 s, which passed before setpoint 1"
    ):
        send_mavsdk(sp, dry_run=False, send_timeout_s=0.05, system_factory=lambda: fake)
    assert fake.calls[-1] == "stop" and fake.closed


def test_a_take_off_that_does_not_climb_hits_the_step_timeout() -> None:
    sp = px4_setpoints(line((1.0, 0.0, 0.0)), rate_hz=25.0)
    fake = FakeSystem(climbs=False)
    with pytest.raises(SolverError, match=r"step_timeout_s: got 0.3 s, which passed before it "
                       r"took off to 3.00 m"):  # fmt: skip
        send_mavsdk(sp, dry_run=False, step_timeout_s=0.3, system_factory=lambda: fake)
    assert "setpoint" not in fake.calls and fake.closed  # never in offboard


def test_a_first_setpoint_on_the_ground_is_refused() -> None:
    ground = SplineTrajectory(np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]), 1, 2.0)
    sp = px4_setpoints(ground, rate_hz=25.0)
    with pytest.raises(InputError, match=r"setpoints: got a first setpoint 0.000 m above home"):
        send_mavsdk(sp, dry_run=False, system_factory=FakeSystem)


def test_never_connecting_hits_the_connect_timeout() -> None:
    sp = px4_setpoints(line((1.0, 0.0, 0.0)), rate_hz=25.0)
    fake = FakeSystem(connects=False)
    begin = time.monotonic()
    with pytest.raises(
        SolverError, match=r"connect_timeout_s: got 0.05 s, which passed before a vehicle"
    ):
        send_mavsdk(sp, dry_run=False, connect_timeout_s=0.05, system_factory=lambda: fake)
    assert time.monotonic() - begin < 2.0
    assert fake.calls == ["connect udpin://0.0.0.0:14540", "wait_connected"]
    assert fake.closed and not fake.sent


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"connect_timeout_s": 0.0}, "connect_timeout_s: got 0, expected a number > 0"),
        ({"send_timeout_s": float("nan")}, "send_timeout_s: got nan"),
    ],
)
def test_bad_timeouts(kwargs: dict[str, float], match: str) -> None:
    sp = px4_setpoints(line((1.0, 0.0, 0.0)), rate_hz=25.0)
    with pytest.raises(InputError, match=match):
        send_mavsdk(sp, **kwargs)  # type: ignore[arg-type]


@pytest.mark.parametrize("rate", [2.0, 1.0])
def test_send_refuses_a_rate_of_2_hz_or_less(rate: float) -> None:
    sp = px4_setpoints(line((1.0, 0.0, 0.0)), rate_hz=10.0)
    slow = dataclasses.replace(sp, rate_hz=rate)
    with pytest.raises(InputError, match=f"rate_hz: got {rate:g}, expected a rate above 2"):
        send_mavsdk(slow, dry_run=False, system_factory=FakeSystem)


def test_real_mavsdk_types_and_no_vehicle() -> None:
    """The installed mavsdk (4.x) builds the real setpoint types and times out without PX4."""
    pytest.importorskip("mavsdk.asyncio")
    from mavsdk.asyncio.plugins.offboard import AccelerationNed, PositionNedYaw, VelocityNedYaw

    system = MavsdkSystem()
    try:
        p, v, a = system.setpoint(
            np.array([1.0, 2.0, -3.0]), np.array([0.5, 0.0, 0.0]), np.zeros(3), 90.0
        )
    finally:
        system.close()
    assert isinstance(p, PositionNedYaw) and isinstance(v, VelocityNedYaw)
    assert isinstance(a, AccelerationNed)
    assert (p.north_m, p.east_m, p.down_m, p.yaw_deg) == (1.0, 2.0, -3.0, 90.0)
    assert (v.north_m_s, v.yaw_deg) == (0.5, 90.0)
    # a real MAVSDK listening on a free local port: nobody answers, the timeout ends it
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    sp = px4_setpoints(line((1.0, 0.0, 0.0)), rate_hz=25.0)
    begin = time.monotonic()
    with pytest.raises(SolverError, match=r"connect_timeout_s: got 0\.3 s"):
        send_mavsdk(sp, f"udpin://127.0.0.1:{port}", dry_run=False, connect_timeout_s=0.3)
    assert time.monotonic() - begin < 5.0
    with pytest.raises(InputError, match="address: got 'nonsense://x', which MAVSDK cannot open"):
        send_mavsdk(sp, "nonsense://x", dry_run=False, connect_timeout_s=0.3)


def test_send_needs_setpoints() -> None:
    with pytest.raises(InputError, match="setpoints: got list, expected Px4Setpoints"):
        send_mavsdk([], dry_run=True)  # type: ignore[arg-type]


def test_setpoints_is_frozen() -> None:
    sp = px4_setpoints(line((1.0, 0.0, 0.0)), rate_hz=10.0)
    assert isinstance(sp, Px4Setpoints)
    with pytest.raises(AttributeError):
        sp.rate_hz = 5.0  # type: ignore[misc]


def test_px4_parameters_keep_its_take_off_and_landing_inside_the_plan() -> None:
    """Each parameter is PX4's default or the plan's bound for its order, whichever is
    smaller; they are set before arming."""
    from skyquill.export.px4.flight_parameters import PX4_DEFAULTS, px4_flight_parameters
    from skyquill.limits import VehicleLimits

    slow = px4_flight_parameters(VehicleLimits(0.5, 1.0, 2.0).derivative_limits(3))
    assert slow["MPC_TKO_SPEED"] == slow["MPC_LAND_SPEED"] == 0.5
    assert slow["MPC_ACC_UP_MAX"] == slow["MPC_ACC_DOWN_MAX"] == 1.0
    assert slow["MPC_JERK_AUTO"] == 2.0
    fast = px4_flight_parameters(VehicleLimits(10.0, 20.0, 100.0).derivative_limits(3))
    assert fast == {name: value for name, (_, value) in PX4_DEFAULTS.items()}
    system = FakeSystem()
    sp = px4_setpoints(line((1.0, 0.0, 0.0), duration=0.4), rate_hz=50.0)
    send_mavsdk(sp, dry_run=False, system_factory=lambda: system, parameters=slow,
                step_timeout_s=5.0)  # fmt: skip
    assert system.calls[2 : len(slow) + 3] == [f"{k} {v:g}" for k, v in slow.items()] + ["arm"]
