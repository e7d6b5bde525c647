"""Several drones writing at once (paper 000 §6, Fig. 10-11): boards side by side or a sky grid.

Each drone gets its own board and home (side by side, or for sky boards a grid
on one plane in the air: :func:`skyquill.calligraphy.artwork.sky_grid`; or the
caller's places, e.g. one shared board: :mod:`skyquill.calligraphy.artwork`),
its mission is planned in a process of its own (planning is CPU-bound and
independent), they all start together,
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
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from skyquill.calligraphy.artwork import sky_grid
from skyquill.calligraphy.board import Board, BoardKind
from skyquill.calligraphy.mission import (
    Mission,
    WritingOptions,
    check_separation,
    contact_board,
    plan_writing,
)
from skyquill.errors import InputError
from skyquill.parallel import dask_client, one_blas_thread
from skyquill.phases import MIN_ALTITUDE_M, check_min_altitude
from skyquill.strokes import Strokes
from skyquill.validation import FloatArray, as_float, as_int

if TYPE_CHECKING:
    from skyquill.sim import Flight

#: Extra room between boards beyond the required separation, m (lifts, transits).
BOARD_MARGIN_M = 0.25

#: Most drones in one show: the separation check looks only at neighbours (sweep and
#: prune over space-time boxes, :mod:`skyquill.show.separation`), so it grows about
#: linearly with the drones; the planning work is bounded by the strokes below.
MAX_DRONES = 1000
#: Most strokes over all drones of one show: the planning work (each stroke
#: costs ~0.1-0.3 s of solving on one core, measured on Latin letters and
#: hanzi), so about 5-15 minutes on two cores at the ceiling.
MAX_SHOW_STROKES = 3_000
#: Lift between strokes when none is given: a brush clears a contact board by
#: 5 cm; on a sky board the light is off and the transits stay in the plane.
DEFAULT_LIFT_M = {"horizontal": 0.05, "wall": 0.05, "sky": 0.0}

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
    kind: BoardKind = "horizontal",
    lift_m: float | None = None,
    yaw_deg: float = 0.0,
    tilt_deg: float = 0.0,
    grid: tuple[int, int] | None = None,
) -> list[tuple[Board, FloatArray]]:
    """Each drone's board and home (3,), m.

    Horizontal boards and walls side by side along x, each with a home on the
    ground 1 m in front of it: a horizontal board lies at ``height_m``; a wall
    is the plane ``y = 0`` with the character's bottom at ``height_m``. Sky
    boards in a grid on one plane of pose ``yaw_deg``, ``tilt_deg`` whose
    bottom edge is at ``height_m`` (``grid``: rows and columns, else nearly
    square; :func:`~skyquill.calligraphy.artwork.sky_grid`). ``lift_m``:
    ``None`` for :data:`DEFAULT_LIFT_M`.
    """
    as_int("drones", n, low=1, high=MAX_DRONES)
    lift = DEFAULT_LIFT_M.get(kind, 0.05) if lift_m is None else lift_m
    if kind == "sky":
        places = sky_grid(
            n, size_m, separation_m, height_m=height_m, yaw_deg=yaw_deg, tilt_deg=tilt_deg,
            grid=grid,
        )  # fmt: skip
        return [(replace(board, lift_m=lift), home) for board, home in places]
    if grid is not None:
        raise InputError(f"grid: got {grid!r} for {kind} boards, expected None (sky boards only)")
    pitch = as_float("size_m", size_m, positive=True) + separation_m + BOARD_MARGIN_M
    out = []
    for i in range(n):
        origin = np.array([i * pitch, 0.0, height_m])
        home = np.array([i * pitch + 0.5 * size_m, -1.0, 0.0])
        out.append((Board(kind, origin, lift, yaw_deg, tilt_deg), home))
    return out


def _raised(home: FloatArray, height_m: float) -> FloatArray:
    """``home`` (3,) raised to at least ``height_m``."""
    out = np.array(home, dtype=float)
    out[2] = max(out[2], height_m)
    return out


def check_show_size(parts: Sequence[Strokes]) -> None:
    """Refuse a show above :data:`MAX_DRONES` drones or :data:`MAX_SHOW_STROKES` strokes.

    Estimated before any planning: the strokes over all drones are the
    planning work, the ``n (n - 1) / 2`` pairs the separation check's.
    """
    n = len(parts)
    strokes = sum(p.n_strokes for p in parts)
    pairs = n * (n - 1) // 2
    if n > MAX_DRONES or strokes > MAX_SHOW_STROKES:
        raise InputError(
            f"drones: got {n} drones writing {strokes:,} strokes ({pairs:,} pairs to keep "
            f"apart), expected at most {MAX_DRONES} drones and {MAX_SHOW_STROKES:,} strokes "
            "in all (fewer drones or a shorter text)"
        )


def plan_show(
    parts: Sequence[Strokes],
    options: WritingOptions | None = None,
    separation_m: float = 1.0,
    workers: int | None = None,
    *,
    scheduler: str | None = None,
    board_kind: BoardKind = "horizontal",
    board_height_m: float = 1.0,
    lift_m: float | None = None,
    fly: bool = False,
    progress: Progress | None = None,
    board_yaw_deg: float = 0.0,
    board_tilt_deg: float = 0.0,
    grid: tuple[int, int] | None = None,
    places: Sequence[tuple[Board, FloatArray]] | None = None,
    home_altitude_m: float = MIN_ALTITUDE_M,
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
        ``distributed.LocalCluster`` of one single-threaded worker process per
        CPU, started for this call (about 2 s) and closed after it. Needs
        ``pip install 'skyquill[dask]'`` here, and skyquill on a remote
        cluster's workers. The missions are the same as planned locally.
    board_kind
        ``"horizontal"`` boards (paper 000), ``"wall"`` or ``"sky"`` (light
        painting, a grid on one plane); see :func:`layout`.
    board_height_m
        Height of the boards (a wall's or a sky grid's: of the writing's bottom), m.
    lift_m
        Pen lift between strokes, m; ``None``: :data:`DEFAULT_LIFT_M`.
    fly
        Also fly every mission in closed-loop simulation, in this process, after
        the separation check (:attr:`Show.flights`).
    progress
        See :data:`Progress`; with a process pool or a cluster it is called as
        the drones arrive, in any order. ``total`` is the number of drones,
        twice that with ``fly``.
    board_yaw_deg, board_tilt_deg, grid
        Sky boards: the plane's pose, degrees, and the grid's rows and columns
        (``None``: nearly square); see :func:`layout`.
    places
        Each drone's board and home, instead of :func:`layout`'s (e.g. drones
        sharing one board: :func:`~skyquill.calligraphy.artwork.split_strokes`);
        the board arguments above are then unused.
    home_altitude_m
        Each home is raised to at least this height, m: the mission starts and ends
        hovering there, above its pad, and the vehicle takes off to it and lands from it
        (:mod:`skyquill.phases`; the minimum flight altitude, by default).

    Returns
    -------
    Show
        The missions, homes, closest approach and, with ``fly``, the flights.

    Raises
    ------
    InputError
        Separation not positive, a show above the ceilings
        (:func:`check_show_size`), ``places`` not one per part, dask not
        installed, or the scheduler not reachable within
        :data:`skyquill.parallel.SCHEDULER_TIMEOUT_S`.
    InfeasibleError
        A drone cannot be planned, or two drones come closer than ``separation_m``.
    """
    opts = options or WritingOptions()
    separation = as_float("separation_m", separation_m, positive=True)
    height = as_float("board_height_m", board_height_m)
    check_show_size(parts)
    if places is None:
        places = layout(
            len(parts), opts.size_m, separation, height_m=height, kind=board_kind,
            lift_m=lift_m, yaw_deg=board_yaw_deg, tilt_deg=board_tilt_deg, grid=grid,
        )  # fmt: skip
    elif len(places) != len(parts):
        raise InputError(f"places: got {len(places)}, expected one per part ({len(parts)})")
    lift = check_min_altitude("home_altitude_m", home_altitude_m)
    places = [(board, _raised(home, lift)) for board, home in places]
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
    pool = ProcessPoolExecutor(max_workers=workers, initializer=one_blas_thread)
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
    with dask_client(scheduler) as (distributed, client):
        futures: list[Any] = client.map(_plan, jobs, pure=False)
        arrivals = distributed.as_completed(futures, loop=client.loop)
        return _collect(futures, arrivals, steps)
