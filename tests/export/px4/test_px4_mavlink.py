"""The PX4 sender against a vehicle that speaks real MAVLink.

A stand-in autopilot built on pymavlink (the reference MAVLink implementation
PX4's tools use) heartbeats as a PX4 quadrotor, acknowledges MAVSDK's mode
commands and records every ``SET_POSITION_TARGET_LOCAL_NED`` it receives. The
installed MAVSDK (the ``px4`` extra's requirement) sends through its real
stack, so the test sees the setpoints as PX4 would decode them: frame, units,
float32 rounding, order and rate.
"""

from __future__ import annotations

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
MAV_FRAME_LOCAL_NED = 1


def test_px4_extra_is_the_tested_mavsdk() -> None:
    """``pip install '.[px4]'`` asks for the MAVSDK this suite runs (the dev extra installs it)."""
    import mavsdk

    extras = tomllib.loads(PYPROJECT.read_text())["project"]["optional-dependencies"]
    assert extras["px4"] == [MAVSDK_REQUIREMENT]
    assert MAVSDK_REQUIREMENT in extras["dev"]
    assert Requirement(MAVSDK_REQUIREMENT).specifier.contains(mavsdk.__version__)


@dataclass
class FakePx4:
    """A PX4 stand-in on a UDP port: heartbeats, acks commands, records setpoints."""

    port: int
    received: list[tuple[float, Any]] = field(default_factory=list)
    commands: list[int] = field(default_factory=list)
    stop: threading.Event = field(default_factory=threading.Event)

    def run(self) -> None:
        link = mavutil.mavlink_connection(
            f"udpout:127.0.0.1:{self.port}", source_system=1, source_component=1
        )
        beat = 0.0
        while not self.stop.is_set():
            if time.monotonic() - beat > 0.2:
                link.mav.heartbeat_send(
                    mavutil.mavlink.MAV_TYPE_QUADROTOR, mavutil.mavlink.MAV_AUTOPILOT_PX4, 0, 0, 0
                )
                beat = time.monotonic()
            msg = link.recv_match(blocking=True, timeout=0.05)
            if msg is None:
                continue
            if msg.get_type() == "COMMAND_LONG":
                self.commands.append(msg.command)
                link.mav.command_ack_send(
                    msg.command, 0, 0, 0, msg.get_srcSystem(), msg.get_srcComponent()
                )
            elif msg.get_type() == "SET_POSITION_TARGET_LOCAL_NED":
                self.received.append((time.monotonic(), msg))
        link.close()


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


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
            setpoints, f"udpin://127.0.0.1:{vehicle.port}", dry_run=False, connect_timeout_s=10
        )
    finally:
        vehicle.stop.set()
        thread.join(5.0)
    assert sent == len(setpoints)
    assert MAV_CMD_DO_SET_MODE in vehicle.commands  # offboard asked for, and acknowledged
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
