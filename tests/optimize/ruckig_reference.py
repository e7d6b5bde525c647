"""Ruckig as the independent reference of the closed-form legs: one fresh call, its phases."""

from __future__ import annotations

import numpy as np
import ruckig
from ruckig import InputParameter, Ruckig, Trajectory


def ruckig_move(length: float, v: float, a: float, j: float) -> Trajectory | None:
    """A fresh one-degree-of-freedom Ruckig call from rest at 0 to rest at ``length``, or None
    where Ruckig finds no profile.

    (Ruckig 0.19 raises in its step 1 on some moves that reach the acceleration limit
    exactly, ``L = 2 a^3 / j^2``, about one in ten.)
    """
    inp = InputParameter(1)
    inp.current_position, inp.target_position = [0.0], [length]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [v], [a], [j]
    out = Trajectory(1)
    try:
        Ruckig(1).calculate(inp, out)
    except ruckig.RuckigError:
        return None
    return out


def merged_phases(t: np.ndarray, jerk: np.ndarray, tol: float) -> list[list[float]]:
    """Phases longer than ``tol`` as [duration, jerk], neighbours of one jerk (to 1e-12)
    merged: the profile itself, whichever way it is split into phases."""
    merged: list[list[float]] = []
    for duration, j in zip(t.tolist(), jerk.tolist(), strict=True):
        if duration <= tol:
            continue
        if merged and abs(merged[-1][1] - j) <= 1e-12 * abs(j):
            merged[-1][0] += duration
        else:
            merged.append([duration, j])
    return merged
