"""The drones of a show, read from plan directories, trajectory files and ``.skyc`` archives.

Every path is read by the reader that already exists for it
(:func:`skyquill.io.plan_dir.read_plan`, :func:`skyquill.export.skybrush.skyc_file.read_show_json`);
several paths are one show on one clock.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from skyquill.errors import InputError
from skyquill.export.skybrush.skyc_file import read_show_json, show_trajectories
from skyquill.io.plan_dir import read_plan
from skyquill.trajectory import Trajectory

#: File types read, by suffix.
SUFFIXES = (".json", ".csv", ".skyc")


@dataclass(frozen=True)
class ShowDrone:
    """One drone of a show.

    Attributes
    ----------
    name
        Where it came from (``plan/trajectory_0``, ``show.skyc/drone3``).
    trajectory
        Its flight, z-up world frame, m, on its own clock from 0.
    start_s
        Show time of the trajectory's time 0, s, >= 0. Before it the drone
        waits at its first position, after its end it holds its last.
    """

    trajectory: Trajectory
    name: str
    start_s: float = 0.0

    @property
    def end_s(self) -> float:
        """Show time at which it has finished, s."""
        return self.start_s + self.trajectory.duration


def load_show(paths: Sequence[Path], max_drones: int | None = None) -> list[ShowDrone]:
    """Every drone of ``paths`` (plan directories, trajectory ``.json``/``.csv``, ``.skyc``).

    ``max_drones``: refuse more, counted before a ``.skyc``'s drones are played back
    (the slow part of reading one).

    Raises
    ------
    InputError
        No path, a path that does not exist or has another suffix, more drones
        than ``max_drones``, or what the file's reader refuses.
    """
    if not paths:
        raise InputError("PATH: got none, expected a plan directory, trajectory file or .skyc")
    drones: list[ShowDrone] = []
    for path in paths:
        drones += _read(Path(path), None if max_drones is None else max_drones - len(drones))
        _check_count(len(drones), max_drones)
    if not drones:  # pragma: no cover - every reader refuses an empty input
        raise InputError("PATH: got no drone, expected at least one")
    return drones


def _check_count(count: int, max_drones: int | None) -> None:
    if max_drones is not None and count > max_drones:
        raise InputError(
            f"PATH: got {count:,} drones, expected at most {max_drones:,} in one check (check "
            "the show in parts of fewer drones)"
        )


def _read(path: Path, room: int | None = None) -> list[ShowDrone]:
    if not path.exists():
        raise InputError(
            f"PATH: got {str(path)!r}, which does not exist; expected a plan directory, a "
            "trajectory .json/.csv or a .skyc"
        )
    suffix = path.suffix.lower()
    if path.is_file() and suffix not in SUFFIXES:
        raise InputError(
            f"PATH: got {str(path)!r}, expected a plan directory or a file ending in "
            f"{', '.join(SUFFIXES)}"
        )
    if suffix == ".skyc" and path.is_file():
        return _read_skyc(path, room)
    prefix = path.name if path.is_dir() else path.parent.name
    return [
        ShowDrone(planned.trajectory, f"{prefix}/{name}" if prefix else name)
        for name, planned in read_plan(path)
    ]


def _read_skyc(path: Path, room: int | None = None) -> list[ShowDrone]:
    """The drones of a ``.skyc`` as their firmware plays them, on the show's clock."""
    show = read_show_json(path)
    count = len(show["swarm"]["drones"])
    if room is not None and count > room:
        raise InputError(
            f"PATH: got {path.name} of {count:,} drones, expected at most {room:,} more "
            "in one check (check the show in parts of fewer drones)"
        )
    return skyc_drones(show, path.name)


def skyc_drones(show: dict[str, Any], file_name: str) -> list[ShowDrone]:
    """The drones of a ``.skyc``'s validated ``show.json`` (read by
    :func:`~skyquill.export.skybrush.skyc_file.read_show_json`) as their firmware plays
    them, on the show's clock; named ``<file_name>/<drone>``."""
    drones: list[Any] = show["swarm"]["drones"]
    starts = [_firmware_zero(d["settings"]["trajectory"]) for d in drones]
    first = min(starts)  # a takeoff before the first keyframe moves the show's 0 earlier
    return [
        ShowDrone(traj, f"{file_name}/{_name(i, d)}", start - first)
        for i, (traj, d, start) in enumerate(
            zip(show_trajectories(show), drones, starts, strict=True)
        )
    ]


def _firmware_zero(trajectory: dict[str, Any]) -> float:
    """Show time of the firmware's 0, s.

    The first keyframe; with a ``takeoffTime`` Skybrush puts a still segment from
    ``-takeoffTime`` in front of it (:mod:`skyquill.export.skybrush.playback`).
    """
    takeoff = float(trajectory.get("takeoffTime", 0.0))
    return -takeoff if takeoff > 0 else float(trajectory["points"][0][0])


def _name(i: int, drone: dict[str, Any]) -> str:
    name = drone["settings"].get("name")
    return name if isinstance(name, str) and name else f"drone{i}"
