"""The PX4 sender against a vehicle that speaks real MAVLink.

A stand-in autopilot built on pymavlink (the reference MAVLink implementation
PX4's tools use) heartbeats as a PX4 quadrotor, acknowledges MAVSDK's commands,
answers its parameter writes, reports its landed state and local position (taking
off to ``MIS_TAKEOFF_ALT`` when told, coming down when told to land) and records every
``SET_POSITION_TARGET_LOCAL_NED`` it receives. The installed MAVSDK (the ``px4``
extra's requirement) sends through its real stack, so the test sees the flight as
PX4 would: arm, take-off, setpoints (frame, units, float32 rounding, order and
rate), landing.
"""

from __future__ import annotations

import math
import socket
import threading
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from packaging.requirements import Requirement

from skyquill.export.px4.setpoints import MAVSDK_REQUIREMENT, px4_setpoints, send_mavsdk
from skyquill.trajectory import SplineTrajectory

mavutil = pytest.importorskip("pymavlink.mavutil")
pytest.importorskip("mavsdk.asyncio")

PYPROJECT = Path(__file__).parents[3] / "pyproject.toml"
MAV_CMD_DO_SET_MODE = 176
MAV_CMD_COMPONENT_ARM_DISARM = 400
MAV_CMD_NAV_TAKEOFF = 22
MAV_CMD_NAV_LAND = 21
MAV_FRAME_LOCAL_NED = 1
#: PX4's custom modes as DO_SET_MODE carries them (main mode, sub mode): auto take-off, land.
PX4_TAKEOFF, PX4_LAND = (4, 2), (4, 6)
MAV_LANDED_STATE_ON_GROUND, MAV_LANDED_STATE_IN_AIR = 1, 2


def test_px4_extra_is_the_tested_mavsdk() -> None:
    """``pip install '.[px4]'`` asks for the MAVSDK this suite runs (the dev extra installs it)."""
    import mavsdk

    extras = tomllib.loads(PYPROJECT.read_text())["project"]["optional-dependencies"]
    assert extras["px4"] == [MAVSDK_REQUIREMENT]
    assert MAVSDK_REQUIREMENT in extras["dev"]
    assert Requirement(MAVSDK_REQUIREMENT).specifier.contains(mavsdk.__version__)


@dataclass
class FakePx4:
    """A PX4 stand-in on a UDP port (module docstring); records commands and setpoints."""

    port: int
    received: list[tuple[float, Any]] = field(default_factory=list)
    commands: list[int] = field(default_factory=list)
    events: list[tuple[float, str]] = field(default_factory=list)
    stop: threading.Event = field(default_factory=threading.Event)
    takeoff_alt: float = 2.5
    down: float = 0.0
    landed_state: int = MAV_LANDED_STATE_ON_GROUND

    def run(self) -> None:
        link = mavutil.mavlink_connection(
            f"udpout:127.0.0.1:{self.port}", source_system=1, source_component=1
        )
        beat = 0.0
        while not self.stop.is_set():
            if time.monotonic() - beat > 0.1:
                self._report(link)
                beat = time.monotonic()
            msg = link.recv_match(blocking=True, timeout=0.05)
            if msg is None:
                continue
            kind = msg.get_type()
            if kind == "COMMAND_LONG":
                self.commands.append(msg.command)
                self._command(msg)
                link.mav.command_ack_send(
                    msg.command, 0, 0, 0, msg.get_srcSystem(), msg.get_srcComponent()
                )
            elif kind == "PARAM_SET":
                name = msg.param_id if isinstance(msg.param_id, str) else msg.param_id.decode()
                name = name.rstrip("\x00")
                if name == "MIS_TAKEOFF_ALT":
                    self.takeoff_alt = float(msg.param_value)
                else:
                    self.events.append((time.monotonic(), f"{name}={msg.param_value:.3g}"))
                link.mav.param_value_send(name.encode(), msg.param_value, msg.param_type, 1, 0)
            elif kind == "SET_POSITION_TARGET_LOCAL_NED":
                self.received.append((time.monotonic(), msg))
        link.close()

    def _command(self, msg: Any) -> None:
        finite = [v if math.isfinite(v) else -1.0 for v in (msg.param2, msg.param3)]
        mode = (int(finite[0]), int(finite[1]))
        if msg.command == MAV_CMD_COMPONENT_ARM_DISARM:
            self.events.append((time.monotonic(), "arm" if msg.param1 == 1 else "disarm"))
        elif msg.command == MAV_CMD_NAV_TAKEOFF or (
            msg.command == MAV_CMD_DO_SET_MODE and mode == PX4_TAKEOFF
        ):
            self.events.append((time.monotonic(), "takeoff"))
            self.down, self.landed_state = -self.takeoff_alt, MAV_LANDED_STATE_IN_AIR
        elif msg.command == MAV_CMD_NAV_LAND or (
            msg.command == MAV_CMD_DO_SET_MODE and mode == PX4_LAND
        ):
            self.events.append((time.monotonic(), "land"))
            self.down, self.landed_state = 0.0, MAV_LANDED_STATE_ON_GROUND

    def _report(self, link: Any) -> None:
        """Heartbeat, landed state and local position, as PX4 streams them."""
        link.mav.heartbeat_send(
            mavutil.mavlink.MAV_TYPE_QUADROTOR, mavutil.mavlink.MAV_AUTOPILOT_PX4, 1, 0, 0
        )
        link.mav.extended_sys_state_send(0, self.landed_state)
        ms = int(time.monotonic() * 1000) % 2**32
        link.mav.local_position_ned_send(ms, 0.0, 0.0, self.down, 0.0, 0.0, 0.0)


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


#: Parameters :func:`~skyquill.export.px4.flight_parameters.px4_flight_parameters` gives.
PARAMETERS = {"MPC_TKO_SPEED": 0.5, "MPC_JERK_AUTO": 2.0}


@pytest.mark.timeout(60)
def test_px4_receives_every_setpoint_in_ned_in_order_above_2_hz() -> None:
    points = np.array([[0, 0, 1], [0, 0, 1], [0.5, 0.2, 1.5], [1, 0.5, 1.5], [1, 0.5, 1.5]])
    control = np.vstack([points[:1]] * 3 + [points] + [points[-1:]] * 2).astype(float)
    setpoints = px4_setpoints(SplineTrajectory(control, 3, 2.0), rate_hz=20.0)
    vehicle = FakePx4(_free_port())
    thread = threading.Thread(target=vehicle.run, daemon=True)
    thread.start()
    try:
        sent = send_mavsdk(
            setpoints,
            f"udpin://127.0.0.1:{vehicle.port}",
            dry_run=False,
            connect_timeout_s=10,
            parameters=PARAMETERS,
        )
    finally:
        vehicle.stop.set()
        thread.join(5.0)
    assert sent == len(setpoints)
    assert MAV_CMD_DO_SET_MODE in vehicle.commands  # offboard asked for, and acknowledged
    # the take-off and landing parameters set, armed, took off to the first setpoint's height,
    # streamed, landed: in that order
    assert [e for _, e in vehicle.events] == [
        "MPC_TKO_SPEED=0.5",
        "MPC_JERK_AUTO=2",
        "arm",
        "takeoff",
        "land",
    ]
    assert vehicle.takeoff_alt == pytest.approx(-setpoints.position_ned[0, 2], abs=1e-6)
    times = {e: t for t, e in vehicle.events}
    first, last = vehicle.received[0][0], vehicle.received[-1][0]
    assert times["takeoff"] < first and last <= times["land"]
    msgs = [m for _, m in vehicle.received]
    assert {m.coordinate_frame for m in msgs} == {MAV_FRAME_LOCAL_NED}
    got = np.array([[m.x, m.y, m.z, m.vx, m.vy, m.vz, m.afx, m.afy, m.afz] for m in msgs])
    want = np.hstack([setpoints.position_ned, setpoints.velocity_ned, setpoints.acceleration_ned])
    # every setpoint arrives, in order (MAVSDK also re-sends the latest one): float32 on the wire
    i = 0
    for row in got:
        if i < len(want) and np.allclose(row, want[i], atol=1e-6):
            i += 1
    assert i == len(want)
    # PX4 leaves offboard when setpoints come slower than 2 Hz
    times = np.array([t for t, _ in vehicle.received])
    assert np.diff(times).max() < 0.5
