"""The writing of a ``write`` scene: parts of a text on vertical boards, planned in parallel.

The text is shared out among the writers (:func:`skyquill.strokes.typed_parts`,
one scale for all), each part goes on its own board (:func:`writing_boards`:
the one place the writing surface is chosen), and the flights are planned as
``skyquill write`` plans them (:func:`skyquill.calligraphy.show.plan_jobs`).
Each flight starts and ends hovering at its board; where the drones come
from, and who holds, is the show's business (:mod:`skyquill.show.build`).
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import cast

import numpy as np

from skyquill.calligraphy.board import Board, sky_board
from skyquill.calligraphy.mission import WritingOptions, check_reach, offset_trajectory
from skyquill.calligraphy.show import Job, Progress, plan_jobs
from skyquill.errors import InputError
from skyquill.show.script import ShowScript, WriteScene
from skyquill.strokes import Strokes
from skyquill.trajectory import Trajectory
from skyquill.validation import FloatArray

#: Extra room between writing boards beyond the safety distance, m.
BOARD_MARGIN_M = 0.5


@dataclass(frozen=True)
class Writing:
    """The writers' flights, each from 0 on its own clock.

    Attributes
    ----------
    flights
        The vehicles' trajectories, one per board, at rest at both ends.
    pen_windows
        Each flight's strokes ``(start, end)``, s.
    starts
        Where each flight starts (W, 3), m.
    """

    flights: tuple[Trajectory, ...]
    pen_windows: tuple[tuple[tuple[float, float], ...], ...]
    starts: FloatArray

    @property
    def duration_s(self) -> float:
        """The longest flight, s."""
        return max(f.duration for f in self.flights)


def writing_boards(count: int, scene: WriteScene, safety_m: float) -> list[Board]:
    """The writing boards of a scene: sky boards facing -y, in rows of ``scene.columns``.

    Board ``k`` is at ``origin + pitch (k mod columns, 0, k div columns)``
    with ``pitch = size + safety_m + BOARD_MARGIN_M``. Light painting: no contact,
    the transits stay in the plane, and paper 003's plane cost keeps the drawing
    on it (:func:`skyquill.calligraphy.board.sky_board`).
    """
    pitch = scene.size_m + safety_m + BOARD_MARGIN_M
    cells = [np.array([k % scene.columns, 0.0, k // scene.columns]) for k in range(count)]
    return [sky_board(scene.origin + pitch * cell) for cell in cells]


def writer_count(scene: WriteScene) -> int:
    """``scene.drones``, or one writer per word (per character for Chinese)."""
    from skyquill.strokes import is_cjk

    if scene.drones is not None:
        return scene.drones
    text = scene.text
    return len("".join(text.split())) if is_cjk(text) else len(text.split())


def plan_writing_scene(
    scene: WriteScene,
    script: ShowScript,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Progress | None = None,
) -> Writing:
    """Plan the writers' flights of ``scene`` with the show's limits.

    Raises
    ------
    InputError
        More writers than drones, fewer words (characters) than writers.
    InfeasibleError
        A part that cannot be written within the limits and the tolerance.
    """
    from skyquill.strokes import typed_parts

    count = writer_count(scene)
    if count > script.drones:
        raise InputError(
            f"write.drones: got {count} writers, expected at most the show's {script.drones}"
        )
    parts = typed_parts(scene.text, count, scene.font)
    options = WritingOptions(size_m=scene.size_m, limits=script.limits)
    boards = writing_boards(count, scene, script.safety_m)
    first = first_alike(parts, boards)
    for board in boards:
        check_reach(board, options)  # as plan_writing would for each board planned
    planned = sorted(set(first))
    # home=None: each flight starts and ends hovering at its board (plan_writing takes
    # it; calligraphy.show.Job's annotation says FloatArray).
    jobs = [cast(Job, (parts[k], boards[k], options, None)) for k in planned]
    missions = dict(zip(planned, plan_jobs(jobs, workers, scheduler, progress), strict=True))
    flights = tuple(
        offset_trajectory(missions[k].vehicle_trajectory(), board.origin - boards[k].origin)
        if k != i
        else missions[k].vehicle_trajectory()
        for i, (k, board) in enumerate(zip(first, boards, strict=True))
    )
    return Writing(
        flights,
        tuple(missions[k].pen_windows for k in first),
        np.array([f.evaluate(np.zeros(1))[0] for f in flights]),
    )


def first_alike(parts: list[Strokes], boards: list[Board]) -> list[int]:
    """For each writer, the first writer whose flight is the same up to a translation.

    Two writers write the same flight, moved, when they write the same strokes (the same
    points, timestamps and layout box: the same glyph at the one scale of the scene) on
    boards of the same kind, pose and lift (sky boards differ only in ``origin``). The
    planner works in world coordinates, so its flight for the second writer is the first
    one's moved by the difference of the origins to floating-point round-off (limits,
    timing and fidelity do not depend on where a board is); the show's check then proves
    the moved flights like any other. SKY QUILL's letters repeat: 40 writers write 20
    distinct letters.
    """
    seen: dict[tuple[object, ...], int] = {}
    first = []
    for i, (part, board) in enumerate(zip(parts, boards, strict=True)):
        key = (
            tuple(p.tobytes() for p in part.paths),
            None if part.times is None else tuple(t.tobytes() for t in part.times),
            None if part.box is None else np.asarray(part.box).tobytes(),
            # every field of the board but where it is (a field added later counts too)
            *(getattr(board, f.name) for f in fields(board) if f.name != "origin"),
        )
        first.append(seen.setdefault(key, i))
    return first
