"""The typed result of a simulated flight, whichever simulator flew it."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from skyquill.validation import FloatArray


@dataclass(frozen=True)
class Flight:
    """Time series of a closed-loop flight, world frame z up, SI units.

    Attributes
    ----------
    t
        Times, shape (N,), s.
    p_ref, v_ref
        Reference position and velocity, shape (N, 3).
    p, v
        Flown (true) position and velocity, shape (N, 3).
    a_cmd
        The outer loop's acceleration command, gravity excluded, shape (N, 3).
    thrust
        Collective thrust commanded, shape (N,), N.
    tilt
        Commanded tilt from vertical, shape (N,), rad.
    saturations
        Count of control steps at which a limit cut the command, per limit
        (``"thrust_max"``, ``"thrust_min"``, ``"tilt"``): reported, not hidden.
    controller, sim
        Names of the outer loop and of the simulator.
    wall_time_s
        Wall-clock time of the simulation.
    ink
        Brush-tip polylines drawn while in contact with the board, each (K, 3).
    """

    t: FloatArray
    p_ref: FloatArray
    v_ref: FloatArray
    p: FloatArray
    v: FloatArray
    a_cmd: FloatArray
    thrust: FloatArray
    tilt: FloatArray
    saturations: dict[str, int]
    controller: str
    sim: str
    wall_time_s: float
    ink: tuple[FloatArray, ...] = field(default=())

    @property
    def position_error(self) -> FloatArray:
        """``|p - p_ref|`` per sample, (N,), m."""
        return np.asarray(np.linalg.norm(self.p - self.p_ref, axis=1))

    @property
    def rmse_m(self) -> float:
        """Root-mean-square position error, m."""
        return float(np.sqrt(np.mean(self.position_error**2)))

    @property
    def max_error_m(self) -> float:
        """Largest position error, m."""
        return float(self.position_error.max())

    @property
    def vel_rmse_mps(self) -> float:
        """Root-mean-square velocity error, m/s."""
        return float(np.sqrt(np.mean(np.sum((self.v - self.v_ref) ** 2, axis=1))))

    def summary(self) -> dict[str, Any]:
        """The ``summary.json`` numbers of ``skyquill fly``."""
        return {
            "rmse_m": self.rmse_m,
            "max_error_m": self.max_error_m,
            "vel_rmse_mps": self.vel_rmse_mps,
            "saturations": dict(self.saturations),
            "sim_time_s": float(self.t[-1] - self.t[0]),
            "wall_time_s": self.wall_time_s,
            "controller": self.controller,
            "sim": self.sim,
            "ink_strokes": len(self.ink),
        }
