"""Several drones writing at once (paper 000 §6, Fig. 10-11): boards side by side.

Each drone gets its own board and home, its mission is planned in a process
of its own (planning is CPU-bound and independent), they all start together,
and the pairwise separation is checked over the whole flight, take-off and
landing included: a violation is an error. Optionally each mission is then
flown in closed-loop simulation over its board. This is the one show planner:
``skyquill write`` and the studio both call :func:`plan_show`.

For large shows the planning can go to a ``dask.distributed`` cluster instead
of the local process pool (``plan_show(..., scheduler="tcp://host:8786")``,
needs ``pip install 'skyquill[dask]'``); the missions are the same.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.mission import (
    Mission,
    WritingOptions,
    check_separation,
    contact_board,
    plan_writing,
)
from skyquill.errors import InputError
from skyquill.strokes import Strokes
from skyquill.validation import FloatArray, as_float, as_int

if TYPE_CHECKING:
    from skyquill.sim import Flight

#: Extra room between boards beyond the required separation, m (lifts, transits).
BOARD_MARGIN_M = 0.25

#: Most drones in one show: the separation check compares every pair over the
#: whole flight (n^2 / 2 distance sweeps) and paper 000's shows had a handful.
MAX_DRONES = 64

#: How long to wait for a ``dask.distributed`` scheduler to answer, s.
SCHEDULER_TIMEOUT_S = 5.0

#: One drone's planning job: the arguments of :func:`plan_writing`.
Job = tuple[Strokes, Board, WritingOptions, FloatArray]

#: ``progress(done, total, stage)``: called with ``done = 0`` before the first step and
#: after each step of a show (one drone planned, one drone flown), in the calling
#: process; ``stage`` says what was just done, for a person. It may raise to stop the
#: show (pending drones are cancelled).
Progress = Callable[[int, int, str], None]


@dataclass(frozen=True)
class Show:
    """Planned missions of every drone and their closest approach.

    Attributes
    ----------
    missions
        One per drone, in the order of the parts.
    homes
        Each drone's take-off and landing point, shape (3,), m, world frame.
    min_separation_m
        Smallest distance between two drones over the whole show, m (``inf`` for one).
    flights
        Each mission flown in closed loop (:func:`fly_mission`) when asked
        (``plan_show(..., fly=True)``), else empty.
    """

    missions: tuple[Mission, ...]
    homes: tuple[FloatArray, ...]
    min_separation_m: float
    flights: tuple[Flight, ...] = ()


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
    as_int("drones", n, low=1, high=MAX_DRONES)
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
    board_height_m: float = 1.0,
    lift_m: float = 0.05,
    fly: bool = False,
    progress: Progress | None = None,
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
    board_kind
        ``"horizontal"`` boards (paper 000) or ``"wall"``; see :func:`layout`.
    board_height_m
        Height of the boards (a wall's: of the writing's bottom), m.
    lift_m
        Brush lift between strokes, m.
    fly
        Also fly every mission in closed-loop simulation, in this process, after
        the separation check (:attr:`Show.flights`).
    progress
        See :data:`Progress`; with a process pool or a cluster it is called as
        the drones arrive, in any order. ``total`` is the number of drones,
        twice that with ``fly``.

    Returns
    -------
    Show
        The missions, homes, closest approach and, with ``fly``, the flights.

    Raises
    ------
    InputError
        Separation not positive, dask not installed, or the scheduler not
        reachable within :data:`SCHEDULER_TIMEOUT_S`.
    InfeasibleError
        A drone cannot be planned, or two drones come closer than ``separation_m``.
    """
    opts = options or WritingOptions()
    separation = as_float("separation_m", separation_m, positive=True)
    height = as_float("board_height_m", board_height_m)
    places = layout(
        len(parts), opts.size_m, separation, height_m=height, kind=board_kind, lift_m=lift_m
    )
    jobs = [(part, board, opts, home) for part, (board, home) in zip(parts, places, strict=True)]
    steps = _Steps(len(jobs) * (2 if fly else 1), progress)
    steps.start(f"planning {len(jobs)} drone(s)")
    missions = _plan_all(jobs, workers, scheduler, steps)
    closest = check_separation([m.trajectory for m in missions], separation)
    flights = []
    if fly:
        for i, mission in enumerate(missions):
            flights.append(fly_mission(mission))
            steps.done(f"flew drone {i + 1} of {len(missions)} in simulation")
    homes = tuple(home for _, home in places)
    return Show(tuple(missions), homes, closest, tuple(flights))


def fly_mission(mission: Mission) -> Flight:
    """Fly ``mission``'s vehicle trajectory in closed loop (RPT) over its board.

    A horizontal board is the simulator's contact board (:func:`contact_board`), so the
    flight records the ink; a wall has no contact model and records none.
    """
    from skyquill.sim import Quadrotor, simulate

    return simulate(
        mission.vehicle_trajectory(),
        Quadrotor(brush_length_m=mission.options.brush.length_m),
        board=contact_board(mission),
    )


class _Steps:
    """Counts a show's steps and reports each to ``progress`` (if any)."""

    def __init__(self, total: int, progress: Progress | None) -> None:
        self.total, self.count, self.progress = total, 0, progress

    def start(self, stage: str) -> None:
        if self.progress is not None:
            self.progress(0, self.total, stage)

    def done(self, stage: str) -> None:
        self.count += 1
        if self.progress is not None:
            self.progress(self.count, self.total, stage)

    def planned(self, i: int, n: int) -> None:
        self.done(f"planned drone {i + 1} of {n}")


def plan_jobs(
    jobs: Sequence[Job],
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Progress | None = None,
) -> list[Mission]:
    """Plan independent writing missions in parallel, in job order.

    Parameters
    ----------
    jobs
        The arguments of :func:`plan_writing`, one tuple per drone.
    workers, scheduler
        As for :func:`plan_show`.
    progress
        See :data:`Progress`; ``total`` is the number of jobs.

    Returns
    -------
    list of Mission
        One per job, in the order of ``jobs``.
    """
    steps = _Steps(len(jobs), progress)
    steps.start(f"planning {len(jobs)} drone(s)")
    return _plan_all(list(jobs), workers, scheduler, steps)


def _plan_all(
    jobs: list[Job], workers: int | None, scheduler: str | None, steps: _Steps
) -> list[Mission]:
    """Plan every job: on a dask cluster, in this process or in a process pool."""
    if scheduler is not None:
        return _plan_on_cluster(jobs, scheduler, steps)
    if len(jobs) == 1 or workers == 1:
        missions = []
        for i, job in enumerate(jobs):
            missions.append(_plan(job))
            steps.planned(i, len(jobs))
        return missions
    pool = ProcessPoolExecutor(max_workers=workers)
    try:
        futures = [pool.submit(_plan, job) for job in jobs]
        return _collect(futures, as_completed(futures), steps)
    finally:
        # On an error (a drone, or progress asking to stop) the pending drones are dropped.
        pool.shutdown(wait=True, cancel_futures=True)


def _collect(futures: Sequence[Any], arrivals: Iterator[Any], steps: _Steps) -> list[Mission]:
    """The futures' missions in job order, reporting each as it arrives."""
    index = {f: i for i, f in enumerate(futures)}
    missions: list[Mission | None] = [None] * len(futures)
    for future in arrivals:
        i = index[future]
        missions[i] = future.result()
        steps.planned(i, len(futures))
    return [m for m in missions if m is not None]


def _plan(job: Job) -> Mission:
    return plan_writing(*job)


def _plan_on_cluster(jobs: list[Job], scheduler: str, steps: _Steps) -> list[Mission]:
    """Plan the jobs on the ``dask.distributed`` scheduler ``scheduler`` (or a local one)."""
    if not isinstance(scheduler, str) or not scheduler:
        raise InputError(f"scheduler: expected an address or 'local', got {scheduler!r}")
    distributed = _import_distributed()
    if scheduler != "local":
        return _plan_with_client(distributed, scheduler, jobs, steps)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        return _plan_with_client(distributed, cluster.scheduler_address, jobs, steps)


def _import_distributed() -> ModuleType:
    try:
        import distributed
    except ImportError as exc:
        raise InputError(
            "scheduler: dask.distributed is not installed; pip install 'skyquill[dask]'"
        ) from exc
    return distributed


def _plan_with_client(
    distributed: ModuleType, address: str, jobs: list[Job], steps: _Steps
) -> list[Mission]:
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
        arrivals = distributed.as_completed(futures, loop=client.loop)
        return _collect(futures, arrivals, steps)
