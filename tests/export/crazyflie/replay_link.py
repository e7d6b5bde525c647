"""A Crazyflie for a fly script to talk to: cflib's own commander and memory, the firmware's model.

The script's calls go through cflib's real ``HighLevelCommander`` (which packs the CRTP
packets) and ``TrajectoryMemory`` (which packs the ``Poly4D`` pieces); the packets and the
memory writes reach :class:`~skyquill.export.crazyflie.commander.HighLevelCommander`, the
model of crazyflie-firmware's high-level commander. Time is simulated: ``sleep`` advances it
in the firmware's 10 ms steps (``RATE_HL_COMMANDER``, 100 Hz) and records the setpoint of
each step.
"""

from __future__ import annotations

import types
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from cflib.crazyflie.high_level_commander import HighLevelCommander as CflibCommander
from cflib.crazyflie.mem import MemoryElement
from cflib.crazyflie.mem.trajectory_memory import TrajectoryMemory

from skyquill.export.crazyflie.commander import Goal, HighLevelCommander

#: The high-level commander's rate in the firmware, s.
TICK_S = 0.01
#: Time the trajectory memory write takes here, s.
WRITE_S = 0.4
#: The CRTP protocol version the simulated firmware reports (crazyflie-firmware 2025).
PROTOCOL_VERSION = 10


@dataclass
class ReplayLink:
    """The simulated Crazyflie: the model, the clock and what it commanded when."""

    pad: tuple[float, float, float]
    now: float = 0.0
    setpoints: list[tuple[float, Goal | None]] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.model = HighLevelCommander(np.array(self.pad, dtype=float))

    def clock(self) -> float:
        return self.now

    def sleep(self, seconds: float) -> None:
        end = self.now + seconds
        while self.now + TICK_S <= end + 1e-12:
            self.now += TICK_S
            self.setpoints.append((self.now, self.model.setpoint(self.now)))
        self.now = end

    @property
    def cf(self) -> Any:
        link = self

        class Packets:
            # a current firmware: cflib then sends GO_TO_2 and START_TRAJECTORY_2
            platform = types.SimpleNamespace(get_protocol_version=lambda: PROTOCOL_VERSION)

            def send_packet(self, pk: Any) -> None:
                link.model.handle(bytes(pk.data), link.now)

        class MemoryHandler:
            def write(self, mem: Any, addr: int, data: bytes, flush_queue: bool = False) -> bool:
                link.model.write_memory(addr, bytes(data))
                link.sleep(WRITE_S)
                mem.write_done(mem, addr)
                return True

        memory = TrajectoryMemory(0, MemoryElement.TYPE_TRAJ, 4096, MemoryHandler())

        def get_mems(kind: int) -> tuple[Any, ...]:
            assert kind == MemoryElement.TYPE_TRAJ
            return (memory,)

        return types.SimpleNamespace(
            high_level_commander=CflibCommander(Packets()),
            mem=types.SimpleNamespace(get_mems=get_mems),
        )

    def commanded(self, after: float, before: float) -> np.ndarray:
        """Positions commanded strictly between two times, shape (N, 3) (motors off: none)."""
        return np.array(
            [g.position for t, g in self.setpoints if after < t < before and g is not None]
        )

    def when(self, command: str) -> list[float]:
        """Times at which ``command`` was accepted (result 0)."""
        return [t for t, name, result in self.model.log if name == command and result == 0]
