"""Fly a skyquill plan on a Crazyflie with cflib: one upload at a time, hovering in between.

``skyquill export --format crazyswarm`` writes this file beside the CSV files
it lists in :data:`SCHEDULE` (one file per upload, in flight order, with the
time each starts on the plan's clock). It needs only the standard library and
cflib (``pip install cflib``)::

    python cs_fly.py --uri radio://0/80/2M/E7E7E7E7E7 [--drone NAME]

What it does (cflib's high-level commander,
``cflib/crazyflie/high_level_commander.py``):

1. writes upload 1 into the trajectory memory while on the ground
   (``TrajectoryMemory.trajectory = [Poly4D, ...]``, ``write_data_sync``) and
   defines it (``define_trajectory``);
2. takes off to the first point's height and goes to the first point;
3. starts each upload at its planned time (``start_trajectory``, absolute
   coordinates, time scale 1); after an upload ends it sends a ``go_to`` to
   the point where it ended, so that the hover is flown from the commander's
   own buffer: the firmware keeps evaluating a finished trajectory from the
   trajectory memory (crazyflie-firmware ``src/modules/src/planner.c``,
   ``plan_current_goal``; ``crtp_commander_high_level.c``,
   ``start_trajectory`` points the trajectory at ``trajectories_memory``),
   which the next upload overwrites;
4. writes the next upload during the hover; if writing takes longer than the
   planned hover, that upload starts late and the later ones keep their
   planned spacing (a message says so);
5. lands below the last point.

The positioning system (Lighthouse, Loco, motion capture) is the user's to
set up; the plan's coordinates are used as they are (z up, metres).

Crazyswarm2's Python API does the same with ``cf.uploadTrajectory(0, 0,
Trajectory.loadcsv(file))`` and ``cf.startTrajectory(0, timescale=1.0,
relative=False)`` (``crazyflie_py``), after ``cf.takeoff`` / ``cf.goTo``.
"""

from __future__ import annotations

import argparse
import csv
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

#: Per drone, its uploads in flight order (written by ``skyquill export``).
SCHEDULE: dict[str, list[dict[str, Any]]] = {}
#: The Crazyflie's trajectory memory, B (crazyflie-firmware ``TRAJECTORY_MEMORY_SIZE``).
MEMORY_BYTES = 4096
#: Takeoff, approach to the first point and landing, each, s.
MANOEUVRE_S = 3.0
#: The trajectory slot used for every upload (its memory is reused).
TRAJECTORY_ID = 1
#: Lowest takeoff height, m (the ground effect below it).
MIN_TAKEOFF_M = 0.3


@dataclass(frozen=True)
class Part:
    """One upload: its CSV file and when it is flown on the plan's clock (s)."""

    file: str
    start_s: float
    end_s: float
    start: tuple[float, float, float]
    end: tuple[float, float, float]


def parts_of(drone: str | None, schedule: dict[str, list[dict[str, Any]]]) -> list[Part]:
    """The uploads of ``drone`` (the only one when ``None``) from ``schedule``."""
    if drone is None:
        if len(schedule) != 1:
            raise SystemExit(f"--drone: got none, expected one of {', '.join(schedule)}")
        drone = next(iter(schedule))
    if drone not in schedule:
        raise SystemExit(f"--drone: got {drone!r}, expected one of {', '.join(schedule)}")
    return [
        Part(
            str(u["file"]),
            float(u["start_s"]),
            float(u["end_s"]),
            (float(u["start"][0]), float(u["start"][1]), float(u["start"][2])),
            (float(u["end"][0]), float(u["end"][1]), float(u["end"][2])),
        )
        for u in schedule[drone]
    ]


def read_pieces(path: Path) -> list[Any]:
    """The rows of a Crazyswarm CSV as cflib ``Poly4D`` pieces (duration, x, y, z, yaw)."""
    from cflib.crazyflie.mem import Poly4D

    with path.open(newline="", encoding="utf-8") as fh:
        rows = [r for r in csv.reader(fh) if r][1:]  # skip the header
    pieces = []
    for row in rows:
        values = [float(v) for v in row]
        axes = [Poly4D.Poly(values[1 + 8 * a : 9 + 8 * a]) for a in range(4)]
        pieces.append(Poly4D(values[0], *axes))
    return pieces


def upload(cf: Any, pieces: Sequence[Any]) -> int:
    """Write ``pieces`` into the trajectory memory and define them; return the bytes written."""
    from cflib.crazyflie.mem import MemoryElement

    size = sum(len(p.pack()) for p in pieces)
    if size > MEMORY_BYTES:
        raise RuntimeError(f"upload: got {size} B, expected at most {MEMORY_BYTES} B")
    memory = cf.mem.get_mems(MemoryElement.TYPE_TRAJ)[0]
    memory.trajectory = list(pieces)
    if not memory.write_data_sync():
        raise RuntimeError("upload: the Crazyflie did not confirm the trajectory write")
    cf.high_level_commander.define_trajectory(TRAJECTORY_ID, 0, len(pieces))
    return size


def fly(
    cf: Any,
    parts: Sequence[Part],
    folder: Path,
    clock: Callable[[], float] = time.monotonic,
    sleep: Callable[[float], None] = time.sleep,
) -> None:
    """Fly ``parts`` (files in ``folder``) on the connected Crazyflie ``cf``."""
    hlc = cf.high_level_commander
    first, last = parts[0], parts[-1]
    upload(cf, read_pieces(folder / first.file))
    hlc.takeoff(max(first.start[2], MIN_TAKEOFF_M), MANOEUVRE_S)
    sleep(MANOEUVRE_S)
    hlc.go_to(*first.start, 0.0, MANOEUVRE_S)
    sleep(MANOEUVRE_S)
    origin = clock() - first.start_s  # the plan's clock
    for i, part in enumerate(parts):
        if i > 0:
            before = parts[i - 1]
            _wait(origin + before.end_s, clock, sleep)
            # Hold from the commander's buffer before the memory is overwritten.
            hlc.go_to(*before.end, 0.0, 1.0)
            upload(cf, read_pieces(folder / part.file))
            late = clock() - (origin + part.start_s)
            if late > 0:
                print(f"{part.file}: written {late:.2f} s after its planned start")
                origin += late
        _wait(origin + part.start_s, clock, sleep)
        hlc.start_trajectory(TRAJECTORY_ID, 1.0, relative_position=False)
    _wait(origin + last.end_s, clock, sleep)
    hlc.land(0.0, MANOEUVRE_S)
    sleep(MANOEUVRE_S)
    hlc.stop()


def _wait(until: float, clock: Callable[[], float], sleep: Callable[[float], None]) -> None:
    left = until - clock()
    if left > 0:
        sleep(left)


def main(argv: Sequence[str] | None = None) -> None:
    """Connect to ``--uri`` and fly ``--drone``'s uploads."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--uri", required=True, help="e.g. radio://0/80/2M/E7E7E7E7E7")
    parser.add_argument("--drone", help=f"one of: {', '.join(SCHEDULE)}")
    args = parser.parse_args(argv)
    parts = parts_of(args.drone, SCHEDULE)

    import cflib.crtp
    from cflib.crazyflie import Crazyflie
    from cflib.crazyflie.syncCrazyflie import SyncCrazyflie

    cflib.crtp.init_drivers()
    with SyncCrazyflie(args.uri, cf=Crazyflie(rw_cache="./cache")) as scf:
        scf.cf.param.set_value("commander.enHighLevel", "1")
        fly(scf.cf, parts, Path(__file__).resolve().parent)


if __name__ == "__main__":
    main()
