"""Several drones writing at once (paper 000 §6, Fig. 10-11): boards side by side.

Each drone gets its own board and home, its mission is planned in a process
of its own (planning is CPU-bound and independent), they all start together,
and the pairwise separation is checked over the whole flight, take-off and
landing included: a violation is an error.

For large shows the planning can go to a ``dask.distributed`` cluster instead
of the local process pool (``plan_show(..., scheduler="tcp://host:8786")``,
needs ``pip install 'skyquill[dask]'``); the missions are the same.
"""

from __future__ import annotations

from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from types import ModuleType
from typing import Any, Literal

import numpy as np

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.mission import Mission, WritingOptions, check_separation, plan_writing
from skyquill.errors import InputError
from skyquill.strokes import Strokes
from skyquill.validation import FloatArray, as_float, as_int

#: Extra room between boards beyond the required separation, m (lifts, transits).
BOARD_MARGIN_M = 0.25

#: How long to wait for a ``dask.distributed`` scheduler to answer, s.
SCHEDULER_TIMEOUT_S = 5.0

#: One drone's planning job: the arguments of :func:`plan_writing`.
Job = tuple[Strokes, Board, WritingOptions, FloatArray]


@dataclass(frozen=True)
class Show:
    """Planned missions of every drone and their closest approach."""

    missions: tuple[Mission, ...]
    homes: tuple[FloatArray, ...]
    min_separation_m: float


def layout(
    n: int,
    size_m: float,
    separation_m: float,
    *,
    height_m: float = 1.0,
    kind: Literal["horizontal", "wall"] = "horizontal",
    lift_m: float = 0.05,
) -> list[tuple[Board, FloatArray]]:
    """Boards side by side along x, each with a home on the ground 1 m in front of it.

    A horizontal board lies at ``height_m``; a wall is the plane ``y = 0`` with
    the character's bottom at ``height_m``.
    """
    as_int("drones", n, low=1, high=64)
    pitch = as_float("size_m", size_m, positive=True) + separation_m + BOARD_MARGIN_M
    out = []
    for i in range(n):
        origin = np.array([i * pitch, 0.0, height_m])
        home = np.array([i * pitch + 0.5 * size_m, -1.0, 0.0])
        out.append((Board(kind, origin, lift_m), home))
    return out


def plan_show(
    parts: Sequence[Strokes],
    options: WritingOptions | None = None,
    separation_m: float = 1.0,
    workers: int | None = None,
    *,
    scheduler: str | None = None,
    board_kind: Literal["horizontal", "wall"] = "horizontal",
    lift_m: float = 0.05,
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
        1 plans in this process. Ignored when ``scheduler`` is given.
    scheduler
        ``None``: plan locally (see ``workers``). Otherwise the address of a
        ``dask.distributed`` scheduler (e.g. ``"tcp://127.0.0.1:8786"``) the
        jobs are submitted to, or ``"local"``: a
        ``distributed.LocalCluster(n_workers=2, threads_per_worker=1,
        processes=False)`` started for this call and closed after it. Needs
        ``pip install 'skyquill[dask]'`` here, and skyquill on a remote
        cluster's workers. The missions are the same as planned locally.

    Returns
    -------
    Show
        The missions, homes and closest approach.

    Raises
    ------
    InputError
        Separation not positive, dask not installed, or the scheduler not
        reachable within :data:`SCHEDULER_TIMEOUT_S`.
    """
    opts = options or WritingOptions()
    separation = as_float("separation_m", separation_m, positive=True)
    places = layout(len(parts), opts.size_m, separation, kind=board_kind, lift_m=lift_m)
    jobs = [(part, board, opts, home) for part, (board, home) in zip(parts, places, strict=True)]
    missions = _plan_all(jobs, workers, scheduler)
    closest = check_separation([m.trajectory for m in missions], separation)
    return Show(tuple(missions), tuple(home for _, home in places), closest)


def _plan_all(jobs: list[Job], workers: int | None, scheduler: str | None) -> list[Mission]:
    """Plan every job: on a dask cluster, in this process or in a process pool."""
    if scheduler is not None:
        return _plan_on_cluster(jobs, scheduler)
    if len(jobs) == 1 or workers == 1:
        return [_plan(job) for job in jobs]
    with ProcessPoolExecutor(max_workers=workers) as pool:
        return list(pool.map(_plan, jobs))


def _plan(job: Job) -> Mission:
    return plan_writing(*job)


def _plan_on_cluster(jobs: list[Job], scheduler: str) -> list[Mission]:
    """Plan the jobs on the ``dask.distributed`` scheduler ``scheduler`` (or a local one)."""
    if not isinstance(scheduler, str) or not scheduler:
        raise InputError(f"scheduler: expected an address or 'local', got {scheduler!r}")
    distributed = _import_distributed()
    if scheduler != "local":
        return _plan_with_client(distributed, scheduler, jobs)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        return _plan_with_client(distributed, cluster.scheduler_address, jobs)


def _import_distributed() -> ModuleType:
    try:
        import distributed
    except ImportError as exc:
        raise InputError(
            "scheduler: dask.distributed is not installed; pip install 'skyquill[dask]'"
        ) from exc
    return distributed


def _plan_with_client(distributed: ModuleType, address: str, jobs: list[Job]) -> list[Mission]:
    """Submit one task per job to the scheduler at ``address`` and gather the missions."""
    try:
        client = distributed.Client(address, timeout=SCHEDULER_TIMEOUT_S, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError(
            f"scheduler: cannot reach the dask scheduler at {address!r} "
            f"within {SCHEDULER_TIMEOUT_S:g} s ({exc})"
        ) from exc
    with client:
        futures: list[Any] = client.map(_plan, jobs, pure=False)
        missions: list[Mission] = client.gather(futures)
    return missions
