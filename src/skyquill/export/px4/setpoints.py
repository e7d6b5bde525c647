"""PX4 offboard setpoints: the frame conversion happens here, at the boundary.

skyquill's world frame is ENU-like: x east, y north, z up (metres, seconds,
radians, yaw counter-clockwise from east). PX4's local frame is NED: x north,
y east, z down, and MAVSDK's offboard yaw is in degrees clockwise from north.
So, for position, velocity and acceleration::

    north = y,   east = x,   down = -z

and ``yaw_ned_deg = 90 - degrees(yaw_enu_rad)`` wrapped to ``(-180, 180]``.

The world origin maps to PX4's local origin (the EKF origin, usually where the
vehicle was armed): place the trajectory relative to it before streaming.

:func:`px4_setpoints` is pure; :func:`send_mavsdk` optionally flies the result through
MAVSDK 4.x (``mavsdk>=4.1,<5``, the optional ``px4`` extra, imported only when really
sending; tested with 4.1.0) or through any :class:`OffboardSystem`: arm, take off with
PX4's own take-off to the first setpoint's height, enter offboard at the first setpoint,
stream, leave offboard, land with PX4's own landing, each step within a time limit
(MAVSDK-Python ``action.arm``, ``set_takeoff_altitude``, ``takeoff``, ``land``;
``telemetry.in_air``, ``position_velocity_ned``, ``landed_state``; ``offboard.start``,
``stop``).
"""

from __future__ import annotations

import asyncio
import importlib
from collections.abc import Awaitable, Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol, TypeVar

import numpy as np

from skyquill.errors import InputError, SolverError
from skyquill.io.points import trajectory_table
from skyquill.io.table import read_table
from skyquill.trajectory import SampledTrajectory, Trajectory
from skyquill.validation import FloatArray, as_float

#: PX4 leaves offboard mode when setpoints arrive slower than 2 Hz.
MIN_RATE_HZ = 2.0
#: Faster than this is more than the MAVLink link or PX4 consumes.
MAX_RATE_HZ = 1000.0
#: The MAVSDK versions :class:`MavsdkSystem` works with (4.1.0 tested).
MAVSDK_REQUIREMENT = "mavsdk>=4.1,<5"
#: PX4 SITL's offboard port, in MAVSDK >= 2 URL syntax (listen for UDP).
DEFAULT_ADDRESS = "udpin://0.0.0.0:14540"
#: How often the vehicle's state is polled while waiting for a take-off or a landing, s.
POLL_S = 0.1
#: How close to the take-off height counts as there, m.
TAKEOFF_TOLERANCE_M = 0.15
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

T = TypeVar("T")


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
        Setpoint rate, Hz, above 2 and at most 1000 (PX4 drops out of
        offboard below 2 Hz). Samples run from 0 to the duration inclusive.
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
        is not in ``(2, 1000]`` Hz.
    """
    rate_hz = check_stream_rate(rate_hz)
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


class OffboardSystem(Protocol):
    """What :func:`send_mavsdk` needs from a vehicle link (MAVSDK, or a test fake).

    The real one is :class:`MavsdkSystem`; a fake with these methods, returned
    by the ``system_factory`` of :func:`send_mavsdk`, stands in for a vehicle.
    """

    async def connect(self, system_address: str) -> None:
        """Open the MAVLink connection (returns before a vehicle answers)."""

    async def wait_connected(self) -> None:
        """Return once an autopilot is discovered on the connection."""

    def setpoint(
        self, position_ned: FloatArray, velocity_ned: FloatArray, accel_ned: FloatArray, yaw: float
    ) -> tuple[Any, Any, Any]:
        """One setpoint as the offboard message types (position+yaw, velocity+yaw, accel)."""

    async def set_position_velocity_acceleration_ned(self, p: Any, v: Any, a: Any) -> None:
        """Send one setpoint built by :meth:`setpoint`."""

    async def start_offboard(self) -> None:
        """Switch the vehicle to offboard mode (needs a setpoint sent before)."""

    async def stop_offboard(self) -> None:
        """Leave offboard mode (PX4 goes to Hold)."""

    async def set_parameter(self, name: str, value: float) -> None:
        """Set one of PX4's float parameters (``MPC_TKO_SPEED``...)."""

    async def arm(self) -> None:
        """Arm the vehicle (motors at idle)."""

    async def takeoff(self, altitude_m: float) -> None:
        """PX4's own take-off to ``altitude_m`` above home (returns once commanded)."""

    async def height(self) -> tuple[bool, float]:
        """Whether it is in the air, and its height above home, m (polled)."""

    async def land(self) -> None:
        """PX4's own landing where it is (returns once commanded)."""

    async def landed(self) -> bool:
        """Whether it is on the ground (polled)."""

    def close(self) -> None:
        """Release the link; called once, also after errors."""


def _mavsdk_module() -> Any:
    """The ``mavsdk`` package, checked to be the native binding (MAVSDK >= 4).

    Up to 3.x ``mavsdk`` was the gRPC wrapper with another API; 4.x has
    ``mavsdk.asyncio``. An InputError names the fix for a missing or old one.
    """
    try:
        mavsdk = importlib.import_module("mavsdk")
    except ImportError:
        raise InputError(
            "dry_run: got False, but the optional package 'mavsdk' is not installed; "
            f"expected it installed (pip install 'skyquill[px4]', i.e. {MAVSDK_REQUIREMENT}) "
            "or dry_run=True"
        ) from None
    try:
        importlib.import_module("mavsdk.asyncio")
    except ImportError:
        version = getattr(mavsdk, "__version__", "unknown")
        raise InputError(
            f"dry_run: got False with mavsdk {version} installed, which has the old gRPC API; "
            f"expected {MAVSDK_REQUIREMENT} (pip install 'skyquill[px4]') or dry_run=True"
        ) from None
    return mavsdk


class MavsdkSystem:
    """:class:`OffboardSystem` on MAVSDK >= 4 (the native ``mavsdk.asyncio`` binding).

    Tested with mavsdk 4.1.0 (message types and connection without a vehicle);
    the gRPC ``mavsdk < 4`` has a different API and is refused.
    """

    def __init__(self) -> None:
        _mavsdk_module()
        self._aio = importlib.import_module("mavsdk.asyncio")
        self._off = importlib.import_module("mavsdk.asyncio.plugins.offboard")
        config = self._aio.Configuration.create_with_component_type(
            self._aio.ComponentType.GROUND_STATION
        )
        self._mavsdk = self._aio.Mavsdk(config)
        self._offboard: Any = None
        self._action: Any = None
        self._telemetry: Any = None
        self._param: Any = None

    async def connect(self, system_address: str) -> None:
        """Add the connection URL (e.g. ``udpin://0.0.0.0:14540``)."""
        try:
            await self._mavsdk.add_any_connection(system_address)
        except self._aio.MavsdkConnectionError as exc:
            raise InputError(
                f"address: got {system_address!r}, which MAVSDK cannot open ({exc}); "
                "expected a MAVSDK connection URL such as 'udpin://0.0.0.0:14540'"
            ) from None

    async def wait_connected(self) -> None:
        """Wait for the first autopilot; the caller bounds the wait with a timeout."""
        # A negative timeout waits until cancelled: send_mavsdk owns the time limit.
        system = await self._mavsdk.first_autopilot(timeout_s=-1.0)
        if system is None:  # only when the instance was destroyed meanwhile
            raise SolverError("address: got no autopilot, expected one (MAVSDK was closed)")
        self._offboard = self._off.OffboardAsync(system)
        action = importlib.import_module("mavsdk.asyncio.plugins.action")
        telemetry = importlib.import_module("mavsdk.asyncio.plugins.telemetry")
        self._action = action.ActionAsync(system)
        self._param = importlib.import_module("mavsdk.asyncio.plugins.param").ParamAsync(system)
        self._telemetry = telemetry.TelemetryAsync(system)
        self._errors = (action.ActionError, telemetry.TelemetryError)
        self._on_ground = telemetry.LandedState.ON_GROUND

    def setpoint(
        self, position_ned: FloatArray, velocity_ned: FloatArray, accel_ned: FloatArray, yaw: float
    ) -> tuple[Any, Any, Any]:
        """The MAVSDK ``PositionNedYaw``, ``VelocityNedYaw``, ``AccelerationNed``."""
        p, v, a = (
            np.asarray(x, dtype=float).tolist() for x in (position_ned, velocity_ned, accel_ned)
        )
        return (
            self._off.PositionNedYaw(p[0], p[1], p[2], float(yaw)),
            self._off.VelocityNedYaw(v[0], v[1], v[2], float(yaw)),
            self._off.AccelerationNed(a[0], a[1], a[2]),
        )

    async def set_position_velocity_acceleration_ned(self, p: Any, v: Any, a: Any) -> None:
        """Send one setpoint (MAVSDK keeps re-sending the last one at 20 Hz)."""
        await self._offboard.set_position_velocity_acceleration_ned(p, v, a)

    async def start_offboard(self) -> None:
        """Start offboard; a SolverError carries PX4's reason when it refuses."""
        try:
            await self._offboard.start()
        except self._off.OffboardError as exc:
            raise SolverError(
                f"offboard start: got {exc}, expected PX4 to accept offboard "
                "(armed, airborne, a position estimate)"
            ) from None

    async def stop_offboard(self) -> None:
        """Stop offboard (PX4 holds position)."""
        await self._offboard.stop()

    async def set_parameter(self, name: str, value: float) -> None:
        """``param.set_param_float``; a SolverError carries PX4's reason when it refuses."""
        param = importlib.import_module("mavsdk.asyncio.plugins.param")
        try:
            await self._param.set_param_float(name, float(value))
        except param.ParamError as exc:
            raise SolverError(
                f"parameters: got {exc} from PX4 for {name} = {value:g}, expected PX4 to accept "
                "it (a parameter of this PX4 version, within its range)"
            ) from None

    async def arm(self) -> None:
        """``action.arm``; a SolverError carries PX4's reason when it refuses."""
        await self._act("arm", self._action.arm())

    async def takeoff(self, altitude_m: float) -> None:
        """``action.set_takeoff_altitude`` then ``action.takeoff``."""
        await self._act("takeoff", self._action.set_takeoff_altitude(float(altitude_m)))
        await self._act("takeoff", self._action.takeoff())

    async def height(self) -> tuple[bool, float]:
        """``telemetry.in_air`` and ``position_velocity_ned`` (height = -down)."""
        in_air = await self._telemetry.in_air()
        state = await self._telemetry.position_velocity_ned()
        return bool(in_air), -float(state.position.down_m)

    async def land(self) -> None:
        """``action.land``."""
        await self._act("land", self._action.land())

    async def landed(self) -> bool:
        """``telemetry.landed_state`` is ``ON_GROUND``."""
        return bool(await self._telemetry.landed_state() == self._on_ground)

    async def _act(self, step: str, call: Awaitable[Any]) -> None:
        try:
            await call
        except self._errors as exc:
            raise SolverError(
                f"{step}: got {exc} from PX4, expected it to {step} (armable, a position "
                "estimate, pre-flight checks passed)"
            ) from None

    def close(self) -> None:
        """Destroy the MAVSDK instance (this also ends a pending discovery)."""
        for plugin in (self._offboard, self._action, self._telemetry, self._param):
            if plugin is not None:
                plugin.destroy()
        self._mavsdk.destroy()


def check_stream_rate(rate_hz: float) -> float:
    """The setpoint rate, Hz, checked to be above 2 Hz and at most 1000 Hz.

    PX4 leaves offboard when setpoints come slower than 2 Hz, so exactly 2 Hz
    (with any jitter) is refused too.
    """
    rate_hz = as_float("rate_hz", rate_hz, positive=True)
    if not MIN_RATE_HZ < rate_hz <= MAX_RATE_HZ:
        raise InputError(
            f"rate_hz: got {rate_hz:g}, expected a rate above {MIN_RATE_HZ:g} and up to "
            f"{MAX_RATE_HZ:g} Hz (PX4 leaves offboard below 2 Hz)"
        )
    return rate_hz


def send_mavsdk(
    setpoints: Px4Setpoints,
    address: str = DEFAULT_ADDRESS,
    dry_run: bool = True,
    *,
    connect_timeout_s: float = 10.0,
    send_timeout_s: float = 1.0,
    step_timeout_s: float = 30.0,
    system_factory: Callable[[], OffboardSystem] | None = None,
    parameters: dict[str, float] | None = None,
) -> int:
    """Fly ``setpoints`` on a PX4 vehicle: take off, offboard, land, through MAVSDK.

    The vehicle stands on the ground below the first setpoint (PX4's local origin, the
    EKF origin, is where it was armed). The sequence: connect and wait for an autopilot;
    set ``parameters`` (the export summary's ``px4_parameters``, which keep PX4's own
    take-off and landing inside the plan's limits:
    :mod:`skyquill.export.px4.flight_parameters`); arm; PX4's own take-off to the first
    setpoint's height and wait until it is there;
    send the first setpoint (PX4 refuses offboard without one), start offboard (at the
    first airborne setpoint), stream every setpoint at ``setpoints.rate_hz``, stop
    offboard (also after an error); PX4's own landing and wait until it is on the ground.
    Arming, the take-off and the landing each have ``step_timeout_s``.

    Works with ``mavsdk`` 4.x (the native binding, tested with 4.1.0; install
    with ``pip install 'skyquill[px4]'``); the gRPC ``mavsdk < 4`` is refused.

    Parameters
    ----------
    setpoints
        From :func:`px4_setpoints`; its ``rate_hz`` must be above 2 Hz.
    address
        MAVSDK connection URL (default the PX4 SITL port, ``udpin://0.0.0.0:14540``).
    dry_run
        When True (default) nothing is imported or sent: returns the number of
        setpoint messages that would be sent.
    connect_timeout_s
        Longest wait, s, for the connection and the vehicle's discovery.
    send_timeout_s
        Longest wait, s, for each send, offboard start and offboard stop.
    step_timeout_s
        Longest wait, s, to arm, to reach the take-off height, to land.
    system_factory
        Makes the :class:`OffboardSystem` to talk to; default
        :class:`MavsdkSystem` (tests pass a fake vehicle here).
    parameters
        PX4 float parameters set before arming, each within ``step_timeout_s``.

    Returns
    -------
    int
        Number of setpoint messages streamed (or that would be), the first
        one sent before offboard starts not counted.

    Raises
    ------
    InputError
        When ``setpoints`` is not a :class:`Px4Setpoints`, its rate is not above
        2 Hz, a timeout is not a positive number, or sending is asked for and
        ``mavsdk >= 4`` is not installed.
    SolverError
        When no vehicle is discovered within ``connect_timeout_s`` or a send
        takes longer than ``send_timeout_s`` (the link, not the input, failed).
    """
    if not isinstance(setpoints, Px4Setpoints):
        raise InputError(
            f"setpoints: got {type(setpoints).__name__}, expected Px4Setpoints (from px4_setpoints)"
        )
    check_stream_rate(setpoints.rate_hz)
    parameters = dict(parameters or {})
    for key, value in parameters.items():
        as_float(f"parameters[{key!r}]", value, positive=True)
    limits = _Timeouts(
        as_float("connect_timeout_s", connect_timeout_s, positive=True),
        as_float("send_timeout_s", send_timeout_s, positive=True),
        as_float("step_timeout_s", step_timeout_s, positive=True),
    )
    if -float(setpoints.position_ned[0, 2]) <= 0.0:
        raise InputError(
            f"setpoints: got a first setpoint {-float(setpoints.position_ned[0, 2]):.3f} m above "
            "home, expected the mission's first airborne point (PX4 takes off to its height)"
        )
    if dry_run:
        return len(setpoints)
    system = (system_factory or MavsdkSystem)()
    try:
        return asyncio.run(_stream(system, setpoints, address, limits, parameters))
    finally:
        system.close()


@dataclass(frozen=True)
class _Timeouts:
    """Time limits of :func:`send_mavsdk`, s."""

    connect: float
    send: float
    step: float


async def _bounded(step: Awaitable[T], limit: float, what: str, name: str) -> T:
    """Await ``step`` at most ``limit`` s; a SolverError names the timeout argument."""
    try:
        return await asyncio.wait_for(step, limit)
    except TimeoutError:
        raise SolverError(
            f"{name}: got {limit:g} s, which passed before {what}; expected a PX4 vehicle "
            "answering on the address (is it powered, on the link, the URL right?) or a "
            "larger timeout"
        ) from None


async def _stream(
    system: OffboardSystem,
    sp: Px4Setpoints,
    address: str,
    lim: _Timeouts,
    parameters: dict[str, float],
) -> int:
    """Connect, set the parameters, arm, take off, offboard at the rate, land."""

    async def connect() -> None:
        await system.connect(system_address=address)
        await system.wait_connected()

    await _bounded(
        connect(), lim.connect, f"a vehicle was discovered at {address!r}", "connect_timeout_s"
    )
    for name, value in parameters.items():
        await _bounded(system.set_parameter(name, value), lim.step, f"PX4 set {name}",
                       "step_timeout_s")  # fmt: skip
    await _bounded(system.arm(), lim.step, "the vehicle armed", "step_timeout_s")
    height = -float(sp.position_ned[0, 2])
    await _bounded(_take_off(system, height), lim.step, f"it took off to {height:.2f} m",
                   "step_timeout_s")  # fmt: skip
    sent = await _offboard(system, sp, lim)
    await _bounded(_land(system), lim.step, "it landed", "step_timeout_s")
    return sent


async def _take_off(system: OffboardSystem, height: float) -> None:
    """PX4's take-off, then wait until it is in the air at ``height`` (polled)."""
    await system.takeoff(height)
    while True:
        in_air, now = await system.height()
        if in_air and abs(now - height) <= TAKEOFF_TOLERANCE_M:
            return
        await asyncio.sleep(POLL_S)


async def _land(system: OffboardSystem) -> None:
    """PX4's landing, then wait until it is on the ground (polled)."""
    await system.land()
    while not await system.landed():
        await asyncio.sleep(POLL_S)


async def _offboard(system: OffboardSystem, sp: Px4Setpoints, lim: _Timeouts) -> int:
    """The first setpoint, offboard, every setpoint at the rate, offboard stopped."""

    def send(i: int) -> Awaitable[None]:
        msg = system.setpoint(
            sp.position_ned[i], sp.velocity_ned[i], sp.acceleration_ned[i], float(sp.yaw_deg[i])
        )
        return _bounded(
            system.set_position_velocity_acceleration_ned(*msg),
            lim.send,
            f"setpoint {i} was sent",
            "send_timeout_s",
        )

    await send(0)
    await _bounded(system.start_offboard(), lim.send, "offboard started", "send_timeout_s")
    period = 1.0 / sp.rate_hz
    loop = asyncio.get_running_loop()
    start = loop.time()
    sent = 0
    try:
        for i in range(len(sp)):
            await send(i)
            sent += 1
            # Sleep to the absolute tick so send latency does not slow the rate down.
            await asyncio.sleep(max(0.0, start + (i + 1) * period - loop.time()))
    finally:
        await _bounded(system.stop_offboard(), lim.send, "offboard stopped", "send_timeout_s")
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
