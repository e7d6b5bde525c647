"""The Crazyflie firmware's high-level commander, as a model: what a fly script really commands.

A copy of the semantics of crazyflie-firmware ``src/modules/src/crtp_commander_high_level.c``
(the CRTP packets, the last setpoint, the trajectory memory) and ``planner.c`` (the
planner's states and plans), with the float32 polynomials of ``pptraj.c``
(:mod:`skyquill.export.crazyflie.memory`), so that the packets cflib sends for a fly script
can be replayed and the position the firmware commands read off at any time.

What it models, function by function:

* ``crtpCommanderHighLevelGetSetpoint`` (:meth:`HighLevelCommander.setpoint`): while the
  planner is stopped or disabled the last setpoint ``pos``, ``vel``, ``yaw`` follow the
  state estimate (the vehicle where it stands) and a stopped planner commands the motors
  off; otherwise the goal of ``plan_current_goal`` is the setpoint, and becomes the last
  setpoint;
* ``takeoff2`` / ``plan_takeoff``: refused unless the planner is idle; a 7th-order
  no-jerk polynomial (``piecewise_plan_7th_order_no_jerk``, ``poly7_nojerk``) from the
  last setpoint straight up to ``height`` in ``duration``, at rest at both ends;
* ``land2`` / ``plan_land``: the same down to ``height`` from the last setpoint, refused
  while landing; when it ends the planner is idle (``plan_current_goal``), motors off;
* ``go_to2`` / ``plan_go_to``: from the current goal (position, velocity, acceleration),
  or from the last setpoint with zero acceleration when stopped, to the point (relative to
  the current goal's if asked) in ``duration``, at rest there;
* ``define_trajectory`` and ``start_trajectory2`` / ``plan_start_trajectory``: the pieces
  at ``offset`` in the trajectory memory, flown from the command's time (``timescale``
  1 only, not reversed); with ``relativePosition`` shifted so that it starts at the last
  setpoint; after its end the last piece's end is held (``piecewise_eval``);
* ``stop``: the planner idle (motors off).

Not modelled: groups (every command applies), yaw beyond what the polynomials carry,
``spiral``, ``*_with_velocity``, compressed trajectories, the scheduler's 100 Hz ticks (the
model is exact at any time asked), and the controller: the vehicle is assumed to be where it
is commanded.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field
from enum import Enum

import numpy as np

from skyquill.export.crazyflie.memory import MEMORY_BYTES, N_AXES, PP_SIZE, FirmwareTrajectory
from skyquill.validation import FloatArray

#: ``enum TrajectoryCommand_e`` (crtp_commander_high_level.c) as cflib sends them.
STOP, GO_TO, START_TRAJECTORY, DEFINE_TRAJECTORY, TAKEOFF_2, LAND_2 = 3, 4, 5, 6, 7, 8
GO_TO_2, START_TRAJECTORY_2 = 12, 13
#: ``struct data_*`` layouts, packed little-endian, after the command byte.
LAYOUTS = {
    STOP: "<B",
    GO_TO: "<BBfffff",
    GO_TO_2: "<BBBfffff",
    START_TRAJECTORY: "<BBBBf",
    START_TRAJECTORY_2: "<BBBBBf",
    DEFINE_TRAJECTORY: "<BBBIB",
    TAKEOFF_2: "<Bff?f",
    LAND_2: "<Bff?f",
}
#: What ``handleCommand`` answers for a command it does not know (``ENOEXEC``).
ENOEXEC = 8
#: Trajectory definitions the firmware holds (``NUM_TRAJECTORY_DEFINITIONS``).
NUM_TRAJECTORY_DEFINITIONS = 10
F32 = np.float32


class State(Enum):
    """``enum trajectory_state`` (planner.h)."""

    IDLE = 0
    FLYING = 1
    LANDING = 2
    DISABLED = 3


@dataclass(frozen=True)
class Goal:
    """What the commander commands at one instant (``struct traj_eval``): m, m/s, m/s^2."""

    position: FloatArray
    velocity: FloatArray
    acceleration: FloatArray


@dataclass
class _Plan:
    """The planner's current trajectory: pieces, when they began, the shift."""

    pieces: FirmwareTrajectory
    t_begin: float
    shift: FloatArray = field(default_factory=lambda: np.zeros(3))

    def finished(self, t: float) -> bool:
        """``piecewise_is_finished``: past the sum of the pieces' durations."""
        return bool(np.float32(t - self.t_begin) > np.float32(self.pieces.duration))

    def goal(self, t: float) -> Goal:
        """``piecewise_eval`` at ``t``, shifted (past the end: the end, at rest)."""
        local = np.array([min(max(t - self.t_begin, 0.0), self.pieces.duration)])
        p, v, a = (self.pieces.evaluate(local, k)[0] for k in range(3))
        return Goal(p + self.shift, v, a)


def poly7_nojerk(
    duration: float, start: tuple[float, float, float], end: tuple[float, float, float]
) -> np.ndarray:
    """pptraj.c ``poly7_nojerk``: the 8 float32 coefficients of one axis, lowest first.

    ``start`` and ``end`` are (position, velocity, acceleration); the jerk is 0 at both.
    """
    T = F32(duration)
    x0, dx0, ddx0 = (F32(v) for v in start)
    xf, dxf, ddxf = (F32(v) for v in end)
    p = np.zeros(PP_SIZE, dtype=np.float32)
    if T <= 0:
        p[0], p[1], p[2] = xf, dxf, ddxf / F32(2)
        return p
    T2 = T * T
    T4 = T2 * T * T  # the C computes T3 = T2 * T, then T4 = T3 * T: the same roundings
    T5 = T4 * T
    T6 = T5 * T
    T7 = T6 * T
    p[0], p[1], p[2], p[3] = x0, dx0, ddx0 / F32(2), 0
    p[4] = -(F32(5) * (F32(14) * x0 - F32(14) * xf + F32(8) * T * dx0 + F32(6) * T * dxf
                       + F32(2) * T2 * ddx0 - T2 * ddxf)) / (F32(2) * T4)  # fmt: skip
    p[5] = (F32(84) * x0 - F32(84) * xf + F32(45) * T * dx0 + F32(39) * T * dxf
            + F32(10) * T2 * ddx0 - F32(7) * T2 * ddxf) / T5  # fmt: skip
    p[6] = -(F32(140) * x0 - F32(140) * xf + F32(72) * T * dx0 + F32(68) * T * dxf
             + F32(15) * T2 * ddx0 - F32(13) * T2 * ddxf) / (F32(2) * T6)  # fmt: skip
    p[7] = (F32(2) * (F32(10) * x0 - F32(10) * xf + F32(5) * T * dx0 + F32(5) * T * dxf
                      + T2 * ddx0 - T2 * ddxf)) / T7  # fmt: skip
    return p


def rest_to_rest(
    duration: float, start: Goal, end: FloatArray, yaw: float = 0.0
) -> FirmwareTrajectory:
    """``piecewise_plan_7th_order_no_jerk`` from ``start`` to rest at ``end`` (3,), float32."""
    coeffs = np.zeros((1, N_AXES, PP_SIZE), dtype=np.float32)
    for ax in range(3):
        coeffs[0, ax] = poly7_nojerk(
            duration,
            (start.position[ax], start.velocity[ax], start.acceleration[ax]),
            (end[ax], 0.0, 0.0),
        )
    coeffs[0, 3, 0] = yaw
    return FirmwareTrajectory(np.array([max(duration, 1e-9)], dtype=np.float32), coeffs)


class HighLevelCommander:
    """One Crazyflie's high-level commander (module docstring).

    Parameters
    ----------
    position
        Where the vehicle stands (its state estimate while the planner is idle), m.
    """

    def __init__(self, position: FloatArray) -> None:
        self.state = State.IDLE
        self.here = np.asarray(position, dtype=float)  # the vehicle (the estimate)
        self.pos = self.here.copy()  # the last setpoint
        self.vel = np.zeros(3)
        self.plan: _Plan | None = None
        self.memory = bytearray(MEMORY_BYTES)
        self.definitions: dict[int, tuple[int, int]] = {}  # id: (offset, pieces)
        self.log: list[tuple[float, str, int]] = []  # (time, command, result)

    def write_memory(self, address: int, data: bytes) -> None:
        """A write into the trajectory memory (cflib ``TrajectoryMemory.write_data``)."""
        if address < 0 or address + len(data) > MEMORY_BYTES:
            raise ValueError(f"memory write: {len(data)} B at {address}, beyond {MEMORY_BYTES}")
        self.memory[address : address + len(data)] = data

    def setpoint(self, t: float) -> Goal | None:
        """``crtpCommanderHighLevelGetSetpoint`` at ``t``: the goal, ``None`` for motors off."""
        goal = self._current_goal(t)
        if self.state in (State.IDLE, State.DISABLED) or goal is None:
            self.pos, self.vel = self.here.copy(), np.zeros(3)
            return None
        self.pos, self.vel = goal.position.copy(), goal.velocity.copy()
        self.here = goal.position.copy()  # tracked perfectly
        return goal

    def handle(self, payload: bytes, t: float) -> int:
        """One packet of the high-level commander's port: ``handleCommand`` at time ``t``."""
        command = payload[0]
        layout = LAYOUTS.get(command)
        if layout is None:
            result = ENOEXEC
        else:
            fields = struct.unpack(layout, bytes(payload[1 : 1 + struct.calcsize(layout)]))
            result = self._command(command, fields, t)
        self.log.append((t, _NAMES.get(command, str(command)), result))
        return result

    def _command(self, command: int, f: tuple[object, ...], t: float) -> int:
        if command == STOP:
            self.state = State.IDLE
            return 0
        if command in (TAKEOFF_2, LAND_2):
            height, duration = float(f[1]), float(f[4])  # type: ignore[arg-type]
            return self._vertical(command == TAKEOFF_2, height, duration, t)
        if command in (GO_TO, GO_TO_2):
            relative = bool(f[1])
            x, y, z, _, duration = (float(v) for v in f[-5:])  # type: ignore[arg-type]
            return self._go_to(np.array([x, y, z]), duration, relative, t)
        if command == DEFINE_TRAJECTORY:
            trajectory_id, _, _, offset, pieces = (int(v) for v in f)  # type: ignore[call-overload]
            if trajectory_id >= NUM_TRAJECTORY_DEFINITIONS:
                return 0
            self.definitions[trajectory_id] = (offset, pieces)
            return 0
        relative, trajectory_id = bool(f[1]), int(f[-2])  # type: ignore[call-overload]
        reversed_, timescale = bool(f[-3]), float(f[-1])  # type: ignore[arg-type]
        return self._start(trajectory_id, relative, reversed_ or timescale != 1.0, t)

    def _current_goal(self, t: float) -> Goal | None:
        """``plan_current_goal``: a landing that has ended leaves the planner idle."""
        if self.plan is None or self.state not in (State.FLYING, State.LANDING):
            return None
        if self.state == State.LANDING and self.plan.finished(t):
            self.state = State.IDLE
        return self.plan.goal(t)

    def _vertical(self, takeoff: bool, height: float, duration: float, t: float) -> int:
        """``plan_takeoff`` (only when idle) and ``plan_land`` (not while landing)."""
        if takeoff and self.state != State.IDLE:
            return 1
        if not takeoff and self.state == State.LANDING:
            return 1
        if self.state in (State.IDLE, State.DISABLED):  # the last setpoint is the estimate
            self.pos = self.here.copy()
        start = Goal(self.pos.copy(), np.zeros(3), np.zeros(3))
        target = np.array([self.pos[0], self.pos[1], height])
        self.plan = _Plan(rest_to_rest(duration, start, target), t)
        self.state = State.FLYING if takeoff else State.LANDING
        return 0

    def _go_to(self, point: FloatArray, duration: float, relative: bool, t: float) -> int:
        """``go_to2``: from the current goal, or from the last setpoint when stopped."""
        if self.state in (State.IDLE, State.DISABLED):
            start = Goal(self.here.copy(), self.vel.copy(), np.zeros(3))
        else:
            goal = self._current_goal(t)
            assert goal is not None
            start = goal
        target = point + start.position if relative else point
        self.plan = _Plan(rest_to_rest(duration, start, target), t)
        self.state = State.FLYING
        return 0

    def _start(self, trajectory_id: int, relative: bool, unsupported: bool, t: float) -> int:
        """``start_trajectory2`` of a defined trajectory in memory (timescale 1, forwards)."""
        if trajectory_id not in self.definitions:
            return 0  # the firmware ignores an undefined id
        if unsupported:
            raise NotImplementedError("the model flies trajectories forwards at timescale 1")
        offset, pieces = self.definitions[trajectory_id]
        size = pieces * (N_AXES * PP_SIZE + 1) * 4
        trajectory = FirmwareTrajectory.from_bytes(bytes(self.memory[offset : offset + size]))
        plan = _Plan(trajectory, t)
        if relative:
            plan.shift = self.pos - plan.goal(t).position
        self.plan = plan
        self.state = State.FLYING
        return 0


_NAMES = {
    STOP: "stop",
    GO_TO: "go_to",
    GO_TO_2: "go_to",
    START_TRAJECTORY: "start_trajectory",
    START_TRAJECTORY_2: "start_trajectory",
    DEFINE_TRAJECTORY: "define_trajectory",
    TAKEOFF_2: "takeoff",
    LAND_2: "land",
}
