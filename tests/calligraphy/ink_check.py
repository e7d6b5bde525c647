"""An independent reading of the ink a writing plan leaves: the hanging brush's tip, densely.

Written apart from the planner: the tip of a rigid brush of length ``L`` along the
thrust axis is ``P + L (e_z - (a + g e_z) / |a + g e_z|)`` for the planned untilted
tip ``P``; it inks where it is below the board's surface (over the board).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from skyquill.calligraphy.mission import Mission
from skyquill.geometry import polyline_distance

Array = NDArray[np.float64]
G = 9.81


def tip_on_board(mission: Mission, n: int = 40_000) -> tuple[Array, Array, Array]:
    """Times (n,), the swung tip in board coordinates (n, 3) and whether it touches (n,)."""
    traj, board = mission.trajectory, mission.board
    t = np.linspace(0.0, traj.duration, n)
    a = traj.evaluate(t, 2) + np.array([0.0, 0.0, G])
    tip = traj.evaluate(t) + mission.options.brush.length_m * (
        np.array([0.0, 0.0, 1.0]) - a / np.linalg.norm(a, axis=1, keepdims=True)
    )
    local = tip - board.origin  # a horizontal board: (u, v, height)
    size = mission.options.size_m
    over = np.all((local[:, :2] > -0.1) & (local[:, :2] < size + 0.1), axis=1)
    return t, local, over & (local[:, 2] < 0.0) & (local[:, 2] > -0.05)


def ink_runs(touching: Array) -> list[tuple[int, int]]:
    """``[start, stop)`` of every run of contact."""
    runs, start = [], None
    for i, on in enumerate(touching):
        if on and start is None:
            start = i
        elif not on and start is not None:
            runs.append((start, i))
            start = None
    if start is not None:
        runs.append((start, len(touching)))
    return runs


def ink_distance(mission: Mission) -> tuple[float, int]:
    """The largest in-plane distance from the planned ink to the nearest stroke, m, and the
    number of ink strokes."""
    _, local, touching = tip_on_board(mission)
    flat = [(s - mission.board.origin)[:, :2] for s in mission.strokes_world]
    ink = local[touching, :2]
    nearest = np.min([polyline_distance(ink, s) for s in flat], axis=0)
    return float(nearest.max()), len(ink_runs(touching))
