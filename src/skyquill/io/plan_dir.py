"""The plan directory: what every planning command writes and ``fly``/``export`` read.

One writer for ``fit``, ``write``, ``cover`` and ``paint``:

* ``trajectory.csv`` (``trajectory_<i>.csv`` for several drones): samples in
  the shared columns :data:`~skyquill.io.points.TRAJECTORY_COLUMNS` plus
  ``yaw`` and ``pen``;
* ``trajectory.json`` (``trajectory_<i>.json``): the exact trajectory, naming
  its kind (:mod:`skyquill.io.trajectory_json`);
* ``summary.json``: the command's own fields plus ``plan``: the files per drone,
  their flight phases (take-off, mission, landing; :mod:`skyquill.phases`) and the
  minimum altitude they keep, and the dense check of each trajectory *as read back
  from the file written* (what is verified is what is delivered), and the largest
  difference between the CSV's samples and the exact trajectory;
* ``plot.png`` when the command draws one.

Every file is written atomically (:mod:`skyquill.io.atomic`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from skyquill.errors import InputError
from skyquill.io.atomic import atomic_path, write_json
from skyquill.io.json_read import parse_json
from skyquill.io.points import check_rows_written, write_table_csv
from skyquill.io.source import read_bytes, special_kind
from skyquill.io.trajectory_csv import read_trajectory_csv
from skyquill.io.trajectory_json import (
    PlannedTrajectory,
    read_trajectory_json,
    write_trajectory_json,
)
from skyquill.parallel import parallel_map
from skyquill.phases import MIN_ALTITUDE_M, flight_phases
from skyquill.trajectory import SampledTrajectory, Trajectory, sample
from skyquill.verify import verify

#: Largest summary.json read when looking for a plan's files, bytes.
SUMMARY_BYTES = 64 * 2**20

PLAN_FORMAT = "skyquill-plan"


def trajectory_names(count: int) -> list[tuple[str, str]]:
    """``(csv, json)`` file names for ``count`` drones."""
    if count == 1:
        return [("trajectory.csv", "trajectory.json")]
    return [(f"trajectory_{i}.csv", f"trajectory_{i}.json") for i in range(count)]


def write_plan(
    out: Path,
    planned: Sequence[PlannedTrajectory],
    *,
    rate: float,
    guaranteed: bool,
    summary: dict[str, Any],
    plot: Callable[[Path], None] | None = None,
    min_altitude_m: float | None = MIN_ALTITUDE_M,
    workers: int | None = 1,
) -> dict[str, Any]:
    """Write the plan directory ``out`` and return the ``summary.json`` written.

    Parameters
    ----------
    out
        The directory; created if missing.
    planned
        One trajectory per drone, each 3-D (z-up world frame), with the limits
        it was planned for: they are checked densely on what was written.
    rate
        Sample rate of the CSV files, Hz.
    guaranteed
        Whether the planner guarantees them (hull constraints) or only
        approximates them (the coverage speed LP).
    summary
        The command's own summary fields.
    plot
        Draws ``plot.png`` to the path it is given.
    min_altitude_m
        The mission's minimum altitude above the ground, m: each trajectory's phases are
        found (:func:`~skyquill.phases.flight_phases`, unless given) and recorded in its
        ``trajectory.json`` and in ``summary.json``. ``None`` records none: trajectories
        that are not a vehicle's flight (a test's synthetic show); exporters find them then.

    Raises
    ------
    InfeasibleError
        A trajectory whose mission goes below ``min_altitude_m``.
    """
    if not planned:
        raise InputError("planned: got no trajectory, expected at least one")
    for i, p in enumerate(planned):
        if p.trajectory.dim != 3:
            raise InputError(f"planned[{i}]: got {p.trajectory.dim} axes, expected 3 (x, y, z)")
    if min_altitude_m is not None:
        planned = [with_phases(p, min_altitude_m) for p in planned]
    out.mkdir(parents=True, exist_ok=True)
    drones = parallel_map(
        partial(_write_drone, out, rate=rate, guaranteed=guaranteed),
        list(zip(trajectory_names(len(planned)), planned, strict=True)),
        workers=workers,
    )
    if plot is not None:
        with atomic_path(out / "plot.png") as tmp:
            plot(tmp)
    full = summary | {
        "plan": {
            "format": PLAN_FORMAT,
            "version": 1,
            "rate_hz": rate,
            "limits_guaranteed": guaranteed,
            "min_altitude_m": min_altitude_m,
            "max_excess": max(d["verification"]["max_excess"] for d in drones),
            "drones": drones,
        }
    }
    write_json(out / "summary.json", full)
    return full


def with_phases(planned: PlannedTrajectory, min_altitude_m: float) -> PlannedTrajectory:
    """``planned`` with its phases (found at ``min_altitude_m`` unless it has them).

    Raises
    ------
    InfeasibleError
        A mission that goes below ``min_altitude_m``.
    """
    if planned.phases is not None:
        return planned
    return replace(planned, phases=flight_phases(planned.trajectory, min_altitude_m))


def _write_drone(
    out: Path,
    drone: tuple[tuple[str, str], PlannedTrajectory],
    *,
    rate: float,
    guaranteed: bool,
) -> dict[str, Any]:
    """Write one drone's ``(csv, json)`` files, read them back and check what was written."""
    (csv_name, json_name), planned = drone
    check_rows_written(planned.trajectory.duration, rate)  # its read-back would refuse more
    write_trajectory_json(out / json_name, planned)
    s = sample(planned.trajectory, rate)
    table = np.column_stack([s.t, s.p, s.v, s.a, s.j])
    with atomic_path(out / csv_name) as tmp:
        pen = planned.pen(s.t) if planned.pen_windows_s else None  # a fit has no pen
        rows = write_table_csv(tmp, table, pen=pen)
    back = read_trajectory_json(out / json_name)
    exact = back.trajectory
    written = read_trajectory_csv(out / csv_name)
    check = verify(exact, back.limits, guaranteed=guaranteed)
    return {
        "csv": csv_name,
        "json": json_name,
        "kind": _kind(exact),
        "duration_s": exact.duration,
        "phases": back.phases.as_dict() if back.phases is not None else None,
        "rows": rows,
        "verification": {
            "n_samples": check.n_samples,
            "max_speed": check.max_speed,
            "max_acc": list(check.max_acc),
            "max_jerk": list(check.max_jerk),
            "max_excess": check.max_excess,
            "limits": check.limits_report(),
            "csv_max_difference_m": _csv_difference(written, exact),
        },
    }


def _kind(traj: Trajectory) -> str:
    from skyquill.trajectory.codec import encode

    return str(encode(traj)["kind"])


def _csv_difference(written: SampledTrajectory, exact: Trajectory) -> float:
    """Largest distance between the CSV's positions and the exact trajectory at its times, m."""
    t = np.clip(written.t - written.t0, 0.0, exact.duration)
    return float(np.linalg.norm(written.p - exact.evaluate(t), axis=1).max())


def plan_files(path: Path) -> list[Path]:
    """The trajectory files a plan consists of, in drone order (what :func:`read_plan` reads).

    ``path`` is a plan directory (its ``summary.json`` names the files; a
    directory without one is searched for ``trajectory.json`` or
    ``trajectory_<i>.json``), a ``trajectory.json`` or a ``trajectory.csv``.
    Commands that read a plan never write over these.
    """
    if path.is_file():
        return [path]
    if not path.is_dir():
        kind = special_kind(path)
        got = repr(str(path)) if kind is None else f"{kind} {str(path)!r}"
        raise InputError(f"plan: got {got}, expected a plan directory or a trajectory file")
    files = _listed(path) or _found(path)
    if not files:
        raise InputError(
            f"plan: got {str(path)!r} without trajectory.json or trajectory_<i>.json, expected "
            "the output directory of fit, write, cover or paint"
        )
    return files


def read_plan(path: Path) -> list[tuple[str, PlannedTrajectory]]:
    """The trajectories of a plan directory or of one file (:func:`plan_files`), named."""
    return [
        (f.stem, PlannedTrajectory(read_trajectory_csv(f)))
        if f.suffix.lower() == ".csv"
        else (f.stem, read_trajectory_json(f))
        for f in plan_files(path)
    ]


def _listed(directory: Path) -> list[Path]:
    """The JSON files ``summary.json`` names (the plan the directory holds now)."""
    summary = directory / "summary.json"
    if not summary.is_file():
        return []
    what = "skyquill's summary.json"
    data = parse_json(read_bytes(summary, what, max_bytes=SUMMARY_BYTES), str(summary), what)
    plan = data.get("plan") if isinstance(data, dict) else None
    if not isinstance(plan, dict) or plan.get("format") != PLAN_FORMAT:
        return []
    names = [d.get("json") for d in plan.get("drones", []) if isinstance(d, dict)]
    files = [n for n in names if isinstance(n, str) and Path(n).name == n and n.endswith(".json")]
    if not files or len(files) != len(names):
        raise InputError(f"{summary}: got drone entries without file names, expected them")
    return [directory / n for n in files]


def _found(directory: Path) -> list[Path]:
    single = directory / "trajectory.json"
    if single.is_file():
        return [single]
    numbered = [p for p in directory.glob("trajectory_*.json") if p.stem[11:].isdigit()]
    return sorted(numbered, key=lambda p: int(p.stem[11:]))
