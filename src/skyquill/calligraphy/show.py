"""Several drones writing at once (paper 000 §6, Fig. 10-11): boards side by side.

Each drone gets its own board and home, its mission is planned in a process
of its own (planning is CPU-bound and independent), they all start together,
and the pairwise separation is checked over the whole flight, take-off and
landing included: a violation is an error.
"""

from __future__ import annotations

from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import numpy as np

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.mission import Mission, WritingOptions, check_separation, plan_writing
from skyquill.strokes import Strokes
from skyquill.validation import FloatArray, as_float, as_int

#: Extra room between boards beyond the required separation, m (lifts, transits).
BOARD_MARGIN_M = 0.25


@dataclass(frozen=True)
class Show:
    """Planned missions of every drone and their closest approach."""

    missions: tuple[Mission, ...]
    homes: tuple[FloatArray, ...]
    min_separation_m: float


def layout(
    n: int, size_m: float, separation_m: float, height_m: float = 1.0
) -> list[tuple[Board, FloatArray]]:
    """Boards side by side along x, each with a home on the ground 1 m in front of it."""
    as_int("drones", n, low=1, high=64)
    pitch = as_float("size_m", size_m, positive=True) + separation_m + BOARD_MARGIN_M
    out = []
    for i in range(n):
        origin = np.array([i * pitch, 0.0, height_m])
        home = np.array([i * pitch + 0.5 * size_m, -1.0, 0.0])
        out.append((Board("horizontal", origin), home))
    return out


def plan_show(
    parts: Sequence[Strokes],
    options: WritingOptions | None = None,
    separation_m: float = 1.0,
    workers: int | None = None,
) -> Show:
    """Plan one mission per part (one drone each) and check their separation.

    Parameters
    ----------
    parts
        What each drone writes.
    options
        Shared writing options.
    separation_m
        Minimum distance between any two drones at any time, m.
    workers
        Processes for planning; ``None``: one per drone up to the CPU count;
        1 plans in this process.
    """
    opts = options or WritingOptions()
    separation = as_float("separation_m", separation_m, positive=True)
    places = layout(len(parts), opts.size_m, separation)
    jobs = [(part, board, opts, home) for part, (board, home) in zip(parts, places, strict=True)]
    if len(jobs) == 1 or workers == 1:
        missions = [plan_writing(*job) for job in jobs]
    else:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            missions = list(pool.map(_plan, jobs))
    closest = check_separation([m.trajectory for m in missions], separation)
    return Show(tuple(missions), tuple(home for _, home in places), closest)


def _plan(job: tuple[Strokes, Board, WritingOptions, FloatArray]) -> Mission:
    return plan_writing(*job)
