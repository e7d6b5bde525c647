"""Fly a skyquill plan on a Crazyflie with cflib: take off, one upload at a time, land.

``skyquill export --format crazyswarm`` writes this file beside the CSV files it lists in
:data:`SCHEDULE` (per drone: its take-off, the uploads of its mission in flight order with
the time each starts on the mission's clock, its landing). It needs only the standard
library and cflib 0.1.29 or newer (``pip install 'cflib>=0.1.29'``: ``start_trajectory``'s
``relative_position``, cflib ``high_level_commander.py``)::

    python cs_fly.py --uri radio://0/80/2M/E7E7E7E7E7 [--drone NAME]

Before connecting it refuses (``error: ...``, exit status 2) a cflib older than that, and a
mission that goes below the minimum flight altitude it was planned for (it reads the
uploads' polynomials itself).
Then, with cflib's high-level commander (crazyflie-firmware ``crtp_commander_high_level.c``,
``planner.c``):

1. writes upload 1 into the trajectory memory while on the ground
   (``TrajectoryMemory.trajectory = [Poly4D, ...]``, ``write_data_sync``) and defines it
   (``define_trajectory``);
2. takes off with the firmware's ``takeoff`` straight up to the height of the mission's first
   point (the drone stands on its pad, below that point: within 0.5 m), then ``go_to`` that
   point at that height, each as long as the plan's limits need (the firmware flies both as
   7th-order polynomials from rest to rest);
3. starts each upload at its planned time (``start_trajectory``, absolute coordinates,
   time scale 1); after an upload ends it sends a ``go_to`` to the point where it ended, so
   that the hover is flown from the commander's own buffer: the firmware keeps evaluating a
   finished trajectory from the trajectory memory (``planner.c``, ``plan_current_goal``;
   ``crtp_commander_high_level.c``, ``start_trajectory`` points the trajectory at
   ``trajectories_memory``), which the next upload overwrites;
4. writes the next upload during the hover; if writing takes longer than the planned
   hover, that upload starts late and the later ones keep their planned spacing;
5. lands with the firmware's ``land`` straight down from the mission's last point to the
   ground, then stops the motors.

Between the end of the take-off and the landing the commanded position never goes below
the minimum altitude (the take-off ends at the first point's height, the approach keeps
it, the mission was checked, the hovers hold points of it). The positioning system
(Lighthouse, Loco, motion capture) is the user's to set up; the plan's coordinates are used
as they are (z up, metres).

Crazyswarm2's Python API does the same with ``cf.takeoff``, ``cf.goTo``,
``cf.uploadTrajectory(0, 0, Trajectory.loadcsv(file))``, ``cf.startTrajectory(0,
timescale=1.0, relative=False)`` and ``cf.land`` (``crazyflie_py``).
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NoReturn

#: Per drone, its flight: take-off, uploads, landing (written by ``skyquill export``).
SCHEDULE: dict[str, dict[str, Any]] = {}
#: The Crazyflie's trajectory memory, B (crazyflie-firmware ``TRAJECTORY_MEMORY_SIZE``).
MEMORY_BYTES = 4096
#: The trajectory slot used for every upload (its memory is reused).
TRAJECTORY_ID = 1
#: The oldest cflib whose ``start_trajectory`` takes ``relative_position`` (0.1.29).
CFLIB_NEEDED = (0, 1, 29)
#: Hover sent after each upload, s (a go_to to where it ended).
HOLD_S = 1.0
#: Points per polynomial piece at which the mission's altitude is checked.
CHECK_SAMPLES = 64
#: Round-off allowed below the minimum altitude, m.
ALTITUDE_TOLERANCE_M = 1e-6


@dataclass(frozen=True)
class Part:
    """One upload: its CSV file and when it is flown on the mission's clock (s)."""

    file: str
    start_s: float
    end_s: float
    start: tuple[float, float, float]
    end: tuple[float, float, float]


@dataclass(frozen=True)
class Flight:
    """One drone's flight: take-off, approach, the uploads, landing."""

    takeoff_height_m: float
    takeoff_s: float
    first_point: tuple[float, float, float]
    approach_s: float
    parts: tuple[Part, ...]
    landing_height_m: float
    landing_s: float
    min_altitude_m: float
    ground_m: float


def refuse(message: str) -> NoReturn:
    """``error: message`` on stderr, exit status 2: nothing was sent to the Crazyflie."""
    print(f"error: {message}", file=sys.stderr)
    raise SystemExit(2)


def _point(values: Sequence[Any]) -> tuple[float, float, float]:
    return float(values[0]), float(values[1]), float(values[2])


def flight_of(drone: str | None, schedule: dict[str, dict[str, Any]]) -> Flight:
    """The flight of ``drone`` (the only one when ``None``) from ``schedule``."""
    if drone is None:
        if len(schedule) != 1:
            refuse(f"--drone: got none, expected one of {', '.join(schedule)}")
        drone = next(iter(schedule))
    if drone not in schedule:
        refuse(f"--drone: got {drone!r}, expected one of {', '.join(schedule)}")
    entry = schedule[drone]
    parts = tuple(
        Part(str(u["file"]), float(u["start_s"]), float(u["end_s"]), _point(u["start"]),
             _point(u["end"]))
        for u in entry["uploads"]
    )  # fmt: skip
    return Flight(
        float(entry["takeoff"]["height_m"]),
        float(entry["takeoff"]["duration_s"]),
        _point(entry["approach"]["point_m"]),
        float(entry["approach"]["duration_s"]),
        parts,
        float(entry["landing"]["height_m"]),
        float(entry["landing"]["duration_s"]),
        float(entry["min_altitude_m"]),
        float(entry["ground_m"]),
    )


def cflib_version() -> tuple[int, ...]:
    """The installed cflib's version as numbers (``0.1.34`` -> ``(0, 1, 34)``)."""
    from importlib.metadata import version

    numbers = []
    for part in version("cflib").split("."):
        digits = "".join(c for c in part if c.isdigit()) if part[:1].isdigit() else ""
        if not digits:
            break
        numbers.append(int(digits))
    return tuple(numbers)


def check_cflib(found: tuple[int, ...] | None = None) -> None:
    """Refuse a cflib older than :data:`CFLIB_NEEDED` (one line, exit status 2)."""
    try:
        found = cflib_version() if found is None else found
    except Exception:  # not installed
        refuse("cflib: got none, expected cflib 0.1.29 or newer (pip install 'cflib>=0.1.29')")
    if found < CFLIB_NEEDED:
        refuse(
            f"cflib: got {'.'.join(map(str, found))}, expected 0.1.29 or newer "
            "(start_trajectory's relative_position); pip install -U cflib"
        )


def read_rows(path: Path) -> list[list[float]]:
    """The rows of a Crazyswarm CSV: duration, then x^0..x^7, y^0..y^7, z^0..z^7, yaw^0..."""
    with path.open(newline="", encoding="utf-8") as fh:
        rows = [r for r in csv.reader(fh) if r][1:]  # skip the header
    return [[float(v) for v in row] for row in rows]


def lowest_z(rows: Sequence[Sequence[float]]) -> float:
    """The lowest z of an upload's polynomials, sampled :data:`CHECK_SAMPLES` times a piece."""
    lowest = float("inf")
    for row in rows:
        duration, z = row[0], row[17:25]
        for k in range(CHECK_SAMPLES + 1):
            t = duration * k / CHECK_SAMPLES
            value = 0.0
            for c in reversed(z):
                value = value * t + c
            lowest = min(lowest, value)
    return lowest


def check_mission(flight: Flight, folder: Path) -> None:
    """Refuse a mission that goes below the minimum altitude it was planned for."""
    floor = flight.ground_m + flight.min_altitude_m - ALTITUDE_TOLERANCE_M
    heights = [("take-off height", flight.takeoff_height_m), ("first point", flight.first_point[2])]
    heights += [(part.file, lowest_z(read_rows(folder / part.file))) for part in flight.parts]
    for what, z in heights:
        if z < floor:
            refuse(
                f"mission: got {what} at {z - flight.ground_m:.3f} m above the ground, expected "
                f"at least {flight.min_altitude_m:g} m (the minimum altitude): not flying"
            )


def read_pieces(path: Path) -> list[Any]:
    """The rows of a Crazyswarm CSV as cflib ``Poly4D`` pieces (duration, x, y, z, yaw)."""
    from cflib.crazyflie.mem import Poly4D

    pieces = []
    for values in read_rows(path):
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
    flight: Flight,
    folder: Path,
    clock: Callable[[], float] = time.monotonic,
    sleep: Callable[[float], None] = time.sleep,
) -> None:
    """Fly ``flight`` (files in ``folder``) on the connected Crazyflie ``cf``."""
    hlc = cf.high_level_commander
    parts = flight.parts
    upload(cf, read_pieces(folder / parts[0].file))
    hlc.takeoff(flight.takeoff_height_m, flight.takeoff_s)
    sleep(flight.takeoff_s)
    hlc.go_to(*flight.first_point, 0.0, flight.approach_s)
    sleep(flight.approach_s)
    origin = clock() - parts[0].start_s  # the mission's clock
    for i, part in enumerate(parts):
        if i > 0:
            before = parts[i - 1]
            _wait(origin + before.end_s, clock, sleep)
            # Hold from the commander's buffer before the memory is overwritten.
            hlc.go_to(*before.end, 0.0, HOLD_S)
            upload(cf, read_pieces(folder / part.file))
            late = clock() - (origin + part.start_s)
            if late > 0:
                print(f"{part.file}: written {late:.2f} s after its planned start")
                origin += late
        _wait(origin + part.start_s, clock, sleep)
        hlc.start_trajectory(TRAJECTORY_ID, 1.0, relative_position=False)
    _wait(origin + parts[-1].end_s, clock, sleep)
    hlc.land(flight.landing_height_m, flight.landing_s)
    sleep(flight.landing_s)
    hlc.stop()


def _wait(until: float, clock: Callable[[], float], sleep: Callable[[float], None]) -> None:
    left = until - clock()
    if left > 0:
        sleep(left)


def main(argv: Sequence[str] | None = None) -> None:
    """Check cflib and the mission, connect to ``--uri`` and fly ``--drone``'s flight."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--uri", required=True, help="e.g. radio://0/80/2M/E7E7E7E7E7")
    parser.add_argument("--drone", help=f"one of: {', '.join(SCHEDULE)}")
    args = parser.parse_args(argv)
    folder = Path(__file__).resolve().parent
    flight = flight_of(args.drone, SCHEDULE)
    check_cflib()
    check_mission(flight, folder)

    import cflib.crtp
    from cflib.crazyflie import Crazyflie
    from cflib.crazyflie.syncCrazyflie import SyncCrazyflie

    cflib.crtp.init_drivers()
    with SyncCrazyflie(args.uri, cf=Crazyflie(rw_cache="./cache")) as scf:
        scf.cf.param.set_value("commander.enHighLevel", "1")
        fly(scf.cf, flight, folder)


if __name__ == "__main__":
    main()
