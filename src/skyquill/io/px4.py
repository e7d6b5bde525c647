"""PX4 offboard setpoints: the frame conversion happens here, at the boundary.

skyquill's world frame is ENU-like: x east, y north, z up (metres, seconds,
radians, yaw counter-clockwise from east). PX4's local frame is NED: x north,
y east, z down, and MAVSDK's offboard yaw is in degrees clockwise from north.
So, for position, velocity and acceleration::

    north = y,   east = x,   down = -z

and ``yaw_ned_deg = 90 - degrees(yaw_enu_rad)`` wrapped to ``(-180, 180]``.

The world origin maps to PX4's local origin (the EKF origin, usually where the
vehicle was armed): place the trajectory relative to it before streaming.

:func:`px4_setpoints` is pure; :func:`send_mavsdk` optionally streams the result
through MAVSDK (an optional dependency, imported only when really sending).
"""

from __future__ import annotations

import asyncio
import importlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from skyquill.errors import InputError
from skyquill.io.points import trajectory_table
from skyquill.io.table import read_table
from skyquill.trajectory import SampledTrajectory, Trajectory
from skyquill.validation import FloatArray, as_float

#: PX4 leaves offboard mode when setpoints arrive slower than 2 Hz.
MIN_RATE_HZ = 2.0
#: Faster than this is more than the MAVLink link or PX4 consumes.
MAX_RATE_HZ = 1000.0
#: Header of :meth:`Px4Setpoints.to_csv`.
PX4_COLUMNS = (
    "t",
    "north",
    "east",
    "down",
    "v_north",
    "v_east",
    "v_down",
    "a_north",
    "a_east",
    "a_down",
    "yaw_deg",
)


def enu_to_ned(x: FloatArray) -> FloatArray:
    """ENU (x east, y north, z up) vectors (N, 3) to NED (north, east, down) (N, 3)."""
    return np.column_stack([x[:, 1], x[:, 0], -x[:, 2]])


def yaw_enu_to_ned_deg(yaw_enu_rad: FloatArray | float) -> FloatArray:
    """Yaw counter-clockwise from east (rad) to clockwise from north (deg) in ``(-180, 180]``."""
    deg = 90.0 - np.degrees(np.asarray(yaw_enu_rad, dtype=float))
    return np.asarray(180.0 - np.mod(180.0 - deg, 360.0))


@dataclass(frozen=True)
class Px4Setpoints:
    """A PX4 offboard setpoint stream in NED.

    Attributes
    ----------
    t
        Times, shape (N,), s from the start.
    position_ned, velocity_ned, acceleration_ned
        Shape (N, 3) each, NED (north, east, down): m, m/s, m/s^2.
    yaw_deg
        Shape (N,), degrees clockwise from north, in ``(-180, 180]``.
    rate_hz
        Stream rate, Hz.
    """

    t: FloatArray
    position_ned: FloatArray
    velocity_ned: FloatArray
    acceleration_ned: FloatArray
    yaw_deg: FloatArray
    rate_hz: float

    def __len__(self) -> int:
        return int(self.t.shape[0])

    def table(self) -> FloatArray:
        """All columns of :data:`PX4_COLUMNS` as one array, shape (N, 11)."""
        return np.column_stack(
            [self.t, self.position_ned, self.velocity_ned, self.acceleration_ned, self.yaw_deg]
        )

    def to_csv(self, path: str | Path) -> int:
        """Write the stream as CSV with header :data:`PX4_COLUMNS`; returns the row count."""
        np.savetxt(
            path, self.table(), delimiter=",", header=",".join(PX4_COLUMNS), comments="", fmt="%.9g"
        )
        return len(self)


def px4_setpoints(
    traj: Trajectory, rate_hz: float = 50.0, yaw_enu_rad: float = 0.0
) -> Px4Setpoints:
    """Sample a z-up trajectory as a PX4 offboard setpoint stream in NED.

    Parameters
    ----------
    traj
        Trajectory in the world frame (x east, y north, z up), m; a 2-D
        trajectory is taken at ``z = 0``.
    rate_hz
        Setpoint rate, Hz, in ``[2, 1000]`` (PX4 drops out of offboard below
        2 Hz). Samples run from 0 to the duration inclusive.
    yaw_enu_rad
        Constant heading, rad counter-clockwise from east (0 = facing east).

    Returns
    -------
    Px4Setpoints
        Position, velocity, acceleration in NED and yaw in degrees clockwise
        from north.

    Raises
    ------
    InputError
        When ``rate_hz`` or ``yaw_enu_rad`` is not a finite number or the rate
        is outside ``[2, 1000]`` Hz.
    """
    rate_hz = as_float("rate_hz", rate_hz, positive=True)
    if not MIN_RATE_HZ <= rate_hz <= MAX_RATE_HZ:
        raise InputError(
            f"rate_hz: got {rate_hz:g}, expected a rate from {MIN_RATE_HZ:g} to "
            f"{MAX_RATE_HZ:g} Hz (PX4 leaves offboard below 2 Hz)"
        )
    yaw = as_float("yaw_enu_rad", yaw_enu_rad)
    table = trajectory_table(traj, rate_hz)
    t = np.ascontiguousarray(table[:, 0])
    return Px4Setpoints(
        t=t,
        position_ned=enu_to_ned(table[:, 1:4]),
        velocity_ned=enu_to_ned(table[:, 4:7]),
        acceleration_ned=enu_to_ned(table[:, 7:10]),
        yaw_deg=np.full(t.shape[0], float(yaw_enu_to_ned_deg(yaw))),
        rate_hz=rate_hz,
    )


def send_mavsdk(
    setpoints: Px4Setpoints, address: str = "udp://:14540", dry_run: bool = True
) -> int:
    """Stream ``setpoints`` to a PX4 vehicle in offboard mode through MAVSDK.

    The vehicle must already be armed and airborne at (or near) the first
    setpoint; this sends the first setpoint, starts offboard, streams every
    setpoint at ``setpoints.rate_hz`` and stops offboard.

    Parameters
    ----------
    setpoints
        From :func:`px4_setpoints`.
    address
        MAVSDK system address (default the PX4 SITL port).
    dry_run
        When True (default) nothing is imported or sent: returns the number of
        setpoint messages that would be sent.

    Returns
    -------
    int
        Number of setpoint messages sent (or that would be sent).

    Raises
    ------
    InputError
        When ``setpoints`` is not a :class:`Px4Setpoints`, or sending is asked
        for and the optional ``mavsdk`` package is not installed.
    """
    if not isinstance(setpoints, Px4Setpoints):
        raise InputError(
            f"setpoints: got {type(setpoints).__name__}, expected Px4Setpoints (from px4_setpoints)"
        )
    if dry_run:
        return len(setpoints)
    try:
        mavsdk = importlib.import_module("mavsdk")
        offboard = importlib.import_module("mavsdk.offboard")
    except ImportError:
        raise InputError(
            "dry_run: got False, but the optional package 'mavsdk' is not installed; "
            "expected it installed (pip install mavsdk) or dry_run=True"
        ) from None
    return asyncio.run(_stream(mavsdk, offboard, setpoints, address))


async def _stream(mavsdk: Any, offboard: Any, sp: Px4Setpoints, address: str) -> int:
    """Connect, start offboard, stream at the set rate, stop; untested without a vehicle."""
    drone = mavsdk.System()
    await drone.connect(system_address=address)
    async for state in drone.core.connection_state():
        if state.is_connected:
            break

    def message(i: int) -> tuple[Any, Any, Any]:
        p, v, a, yaw = sp.position_ned[i], sp.velocity_ned[i], sp.acceleration_ned[i], sp.yaw_deg[i]
        return (
            offboard.PositionNedYaw(float(p[0]), float(p[1]), float(p[2]), float(yaw)),
            offboard.VelocityNedYaw(float(v[0]), float(v[1]), float(v[2]), float(yaw)),
            offboard.AccelerationNed(float(a[0]), float(a[1]), float(a[2])),
        )

    await drone.offboard.set_position_velocity_acceleration_ned(*message(0))
    await drone.offboard.start()
    period = 1.0 / sp.rate_hz
    loop = asyncio.get_running_loop()
    start = loop.time()
    sent = 0
    try:
        for i in range(len(sp)):
            await drone.offboard.set_position_velocity_acceleration_ned(*message(i))
            sent += 1
            await asyncio.sleep(max(0.0, start + (i + 1) * period - loop.time()))
    finally:
        await drone.offboard.stop()
    return sent


def read_px4_csv(path: str | Path) -> SampledTrajectory:
    """Read a setpoint CSV of :meth:`Px4Setpoints.to_csv` back into the z-up world frame.

    The NED columns are turned back with the inverse of :func:`enu_to_ned`
    (the same swap: ``(n, e, d) -> (e, n, -d)``), as PX4's own NED setpoints
    would be read by a ground station working in ENU.
    """
    table = read_table(path, required=PX4_COLUMNS, min_rows=2, name="PX4 setpoint file")
    values = [table.select(PX4_COLUMNS[i : i + 3]) for i in (1, 4, 7)]
    t = table.column("t")
    return SampledTrajectory(t, *(enu_to_ned(v) for v in values))
