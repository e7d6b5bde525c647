"""Crazyswarm2 / cflib polynomial CSV, one file per upload, checked as the Crazyflie flies it.

A Crazyflie flies a plan's mission (:mod:`skyquill.phases`): it takes off and lands with
its firmware's own commands (the fly script, :mod:`.fly_script`, with durations that keep
the plan's limits: :mod:`.manoeuvres`), so the plan's own take-off and landing, if it has
them, are not uploaded. The mission is cut into uploads by
:func:`skyquill.targets.plan_uploads` (the one place that decides them); a plan that does
not fit a Crazyflie is refused with its message, never split mid-motion, and so is one
with landings inside its mission (one flight per export). Each upload is written exactly (one row
per knot span or polynomial piece), then read back the way it will fly: the
CSV parsed, packed with cflib's ``Poly4D`` arithmetic, at most 4096 B per
upload, and evaluated in float32 as the firmware's ``pptraj.c`` does
(:mod:`skyquill.export.crazyflie.memory`). That read-back, flown on the plan's
clock with the hovers between uploads, is what the distance check of
:func:`~skyquill.export.base.check_delivered` sees; the dense limit check sees the whole
flight, from the firmware's take-off through the uploads to the end of its landing
(:mod:`.whole_flight`), each manoeuvre as the firmware plans it.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from skyquill.errors import InfeasibleError, InputError
from skyquill.export.base import (
    ALLOWED_EXCESS,
    ORDER_NAMES,
    DeliveredCheck,
    ExportOptions,
    ExportReport,
    NamedPlan,
    check_delivered,
    mission_plan,
    target,
)
from skyquill.export.crazyflie import fly_script
from skyquill.export.crazyflie.csv_file import (
    read_crazyswarm_table,
    upload_pieces,
    write_crazyswarm,
)
from skyquill.export.crazyflie.manoeuvres import APPROACH_OFFSET_M, manoeuvre_s
from skyquill.export.crazyflie.memory import (
    MEMORY_BYTES,
    PIECE_BYTES,
    FlownUploads,
    end_states,
    flown_uploads,
    pack_pieces,
)
from skyquill.export.crazyflie.whole_flight import whole_flight
from skyquill.io.json_read import read_json_file
from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.phases import FlightPhases
from skyquill.targets import CRAZYFLIE, Upload, plan_uploads
from skyquill.trajectory import Trajectory
from skyquill.validation import FloatArray
from skyquill.verify import verify

#: Relative limit excess of the delivered float32 polynomials that is float32 rounding, not a
#: broken limit: a limit the plan meets exactly shows ~1.2e-7 (one float32 ulp) on the
#: firmware's Horner evaluation; 1e-6 allows the ~8 roundings of a degree-7 Horner.
FLOAT32_LIMIT_TOLERANCE = 1e-6
#: Largest speed (m/s) and acceleration (m/s^2) of the plan where an upload starts or ends.
REST_TOLERANCE = 1e-6
#: Drone name in the fly script's schedule when the plan has one drone.
SINGLE = "drone"


@dataclass(frozen=True)
class UploadFile:
    """One upload as written and read back.

    Attributes
    ----------
    file
        The CSV file.
    pieces
        Polynomial pieces (rows).
    bytes
        Bytes cflib writes for it (``Poly4D.pack``: 132 a piece), at most 4096.
    start_s, end_s
        When it is flown on the plan's clock, s.
    hover_before_s
        Planned hover before it (while it is uploaded), s; 0 for the first.
    start, end
        Position (m), velocity (m/s), acceleration (m/s^2) of the delivered
        float32 polynomials at its first and last instant, shape (3, 3) each
        (rows: order; columns: x, y, z).
    """

    file: Path
    pieces: int
    bytes: int
    start_s: float
    end_s: float
    hover_before_s: float
    start: FloatArray
    end: FloatArray

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready; ``file`` is the file's name (it sits beside the summary)."""
        return {
            "file": self.file.name,
            "pieces": self.pieces,
            "bytes": self.bytes,
            "start_s": self.start_s,
            "end_s": self.end_s,
            "hover_before_s": self.hover_before_s,
            "start": _state(self.start),
            "end": _state(self.end),
            "at_rest": self.at_rest,
        }

    @property
    def at_rest(self) -> bool:
        """Whether velocity and acceleration are within :data:`REST_TOLERANCE` at both ends."""
        return bool(np.abs(np.vstack([self.start[1:], self.end[1:]])).max() <= REST_TOLERANCE)


@dataclass(frozen=True)
class DroneExport:
    """One drone's uploads, what the Crazyflie flies from them, its check and its flight."""

    drone: str
    uploads: tuple[UploadFile, ...]
    flown: FlownUploads
    delivered: DeliveredCheck
    flight: dict[str, Any]

    @property
    def within_limits(self) -> bool:
        """Whether the delivered limit excess is within :data:`FLOAT32_LIMIT_TOLERANCE`."""
        return self.delivered.limit_excess <= FLOAT32_LIMIT_TOLERANCE

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: the uploads and the delivered check."""
        return {
            "drone": self.drone,
            "duration_s": self.flown.duration,
            "axes": self.flown.dim,
            "flight": self.flight,
            "uploads": [u.as_dict() for u in self.uploads],
            "delivered_within_limits": self.within_limits,
            "delivered": self.delivered.as_dict(),
        }


@dataclass(frozen=True)
class CrazyswarmExporter:
    """One CSV per upload and drone, a fly script, all checked as the Crazyflie flies them."""

    name: str = "crazyswarm"
    suffix: str = ".csv"
    help: str = (
        "Crazyswarm2/cflib polynomial CSV, one file per Crazyflie upload (plan with "
        "--target crazyflie), and a cflib fly script"
    )

    def __call__(
        self, plans: Sequence[NamedPlan], out: Path, options: ExportOptions
    ) -> ExportReport:
        """Cut each plan into uploads, write them, read them back as flown, check them."""
        several = len(plans) > 1
        drones = [
            export_drone(name, planned, target(out, name, several, ".csv"))
            for name, planned in plans
        ]
        script = write_fly_script(out.with_name(f"{out.stem}_fly.py"), drones, several)
        files = (*(u.file for d in drones for u in d.uploads), script)
        return ExportReport(
            self.name,
            files,
            exact=True,
            max_error_m=max(d.delivered.max_error_m for d in drones),
            message=_message(drones, script, plans),
            details={
                "target": CRAZYFLIE.name,
                "memory_bytes": MEMORY_BYTES,
                "float32_limit_tolerance": FLOAT32_LIMIT_TOLERANCE,
                "rest_tolerance": REST_TOLERANCE,
                "script": script.name,
                "drone_uploads": [d.as_dict() for d in drones],
            },
            delivered=tuple(d.delivered for d in drones),
        )


def export_drone(name: str, planned: PlannedTrajectory, path: Path) -> DroneExport:
    """Write ``planned``'s mission as the uploads a Crazyflie flies and check them as flown.

    Parameters
    ----------
    name
        The drone's name.
    planned
        Its plan (z-up world frame, m, s); its phases (recorded, else found at the default
        minimum altitude) say which part is the mission.
    path
        ``<stem>.csv`` for one upload; several are written as
        ``<stem>_part1.csv``, ``<stem>_part2.csv``, ... in flight order.

    Raises
    ------
    InputError
        A plan that is not 3-D, has landings inside its mission, does not fit a Crazyflie
        (:func:`~skyquill.targets.plan_uploads`) or is not at rest where an upload starts
        or ends.
    """
    if planned.trajectory.dim != 3:
        raise InputError(
            f"trajectory: got a {planned.trajectory.dim}-D plan, expected 3-D (x, y, z): plan "
            "2-D input with --altitude"
        )
    # What the plan is made of first (a Crazyflie flies polynomials, from rest to rest), then
    # where its mission is: a plan that fails both hears about the first.
    _check_rest(plan_uploads(planned.trajectory, CRAZYFLIE))
    phases = planned.flight()
    if phases.ground_stops_s:
        a, b = phases.ground_stops_s[0]
        raise InputError(
            f"plan: got drone {name} landing inside its mission ({a:.2f} to {b:.2f} s), "
            "expected one take-off and one landing per Crazyflie flight"
        )
    mission = mission_plan(planned)
    uploads = plan_uploads(mission.trajectory, CRAZYFLIE)
    _check_rest(uploads)
    paths = part_paths(path, len(uploads))
    for upload, file in zip(uploads, paths, strict=True):
        write_crazyswarm(upload_pieces(upload.parts), file)
    packed = [read_upload(file) for file in paths]
    flown = flown_uploads(
        [u.start_s for u in uploads], packed, mission.trajectory.duration, mission.trajectory.dim
    )
    files = []
    for upload, file, data, firmware in zip(uploads, paths, packed, flown.uploads, strict=True):
        start, end = end_states(firmware)
        files.append(
            UploadFile(
                file,
                firmware.n_pieces,
                len(data),
                upload.start_s,
                upload.end_s,
                upload.hover_before_s,
                start,
                end,
            )
        )
    flight = _flight(phases, planned)
    delivered = _whole_flight_checked(name, check_delivered(name, mission, flown), flight, flown,
                                      planned)  # fmt: skip
    return DroneExport(name, tuple(files), flown, delivered, flight)


def _whole_flight_checked(
    name: str,
    mission: DeliveredCheck,
    flight: dict[str, Any],
    flown: FlownUploads,
    planned: PlannedTrajectory,
) -> DeliveredCheck:
    """``mission``'s check with the limits checked from motors start to stop.

    The firmware's take-off, approach and landing around the uploads
    (:func:`~.whole_flight.whole_flight`) are checked densely at the plan's limits; the
    check's excess is the worse of the mission's and the whole flight's, and
    ``flight["as_played"]`` records the whole flight's numbers.

    Raises
    ------
    InfeasibleError
        The whole flight is over a limit by more than
        :data:`~skyquill.export.base.ALLOWED_EXCESS` (the manoeuvres' durations keep the
        limits, so this is the float32 polynomials' doing).
    """
    whole = whole_flight(flight, flown)
    check = verify(whole, planned.limits, guaranteed=False)
    excess = tuple(max(e, check.excess(n)) for n, e in enumerate(mission.excess_by_order, start=1))
    flight["as_played"] = {
        "from": "motors start (take-off) to motors stop (landing ended)",
        "duration_s": whole.duration,
        "relative_excess": {ORDER_NAMES[n]: check.excess(n) for n in ORDER_NAMES},
        "lowest_after_takeoff_m": float(
            whole.evaluate(np.linspace(whole.starts[1], whole.starts[3], 2001))[:, 2].min()
        ),
    }
    for order, value in enumerate(excess, start=1):
        if value > ALLOWED_EXCESS[order]:
            raise InfeasibleError(
                f"plan: got drone {name}'s {ORDER_NAMES[order]} {100 * value:.2f} % over its "
                f"limit as the Crazyflie flies it from take-off to landing, expected at most "
                f"{100 * ALLOWED_EXCESS[order]:g} % over; plan it with a lower "
                f"{ORDER_NAMES[order]} limit",
                ("limits",),
            )
    return replace(
        mission,
        limit_excess=max(mission.limit_excess, check.max_excess),
        limits=tuple(check.limits_report()),
        excess_by_order=(excess[0], excess[1], excess[2]),
    )


def _flight(phases: FlightPhases, planned: PlannedTrajectory) -> dict[str, Any]:
    """The firmware's take-off, approach and landing around the mission (:mod:`.manoeuvres`)."""
    first, last = np.array(phases.first_point_m), np.array(phases.last_point_m)
    climb = first[2] - phases.ground_m
    return {
        "takeoff": {
            "height_m": float(first[2]),
            "duration_s": manoeuvre_s(climb, planned.limits),
        },
        "approach": {
            "point_m": first.tolist(),
            "duration_s": manoeuvre_s(APPROACH_OFFSET_M, planned.limits),
            "from_within_m": APPROACH_OFFSET_M,
        },
        "landing": {
            "height_m": phases.ground_m,
            "from_m": last.tolist(),
            "duration_s": manoeuvre_s(last[2] - phases.ground_m, planned.limits),
        },
        "min_altitude_m": phases.min_altitude_m,
        "ground_m": phases.ground_m,
        "mission_s": list(phases.mission_s),
        "mission_lowest_m": phases.lowest_m,
    }


def part_paths(path: Path, n: int) -> list[Path]:
    """``[path]`` for one upload, else ``<stem>_part1.csv`` .. ``<stem>_part<n>.csv``."""
    if n == 1:
        return [path]
    return [path.with_name(f"{path.stem}_part{i}.csv") for i in range(1, n + 1)]


def read_upload(path: Path) -> bytes:
    """The bytes cflib writes to the Crazyflie for the CSV ``path`` (at most 4096).

    Raises
    ------
    InputError
        A file :func:`~skyquill.export.crazyflie.csv_file.read_crazyswarm_table` refuses, or one
        that does not fit the trajectory memory.
    """
    data = pack_pieces(read_crazyswarm_table(path))
    if len(data) > MEMORY_BYTES:
        raise InputError(
            f"{path.name}: got {len(data) // PIECE_BYTES} pieces ({len(data)} B), expected at most "
            f"{MEMORY_BYTES} B, the Crazyflie's trajectory memory"
        )
    return data


def read_export(summary: Path) -> dict[str, FlownUploads]:
    """What each drone flies from an export, from its ``<out>.summary.json``.

    The files the summary lists (beside it) are read, packed and evaluated as
    by the exporter; a file that is missing, corrupted or does not hold the
    pieces the summary says is refused.

    Raises
    ------
    InputError
        As :func:`read_upload`, a summary that is not a Crazyswarm export
        summary, or a piece count that differs from the summary's.
    """
    out = {}
    for drone, duration_s, axes, uploads in _schedule(summary):
        packed = []
        for file, pieces, size, _ in uploads:
            data = read_upload(Path(summary).parent / file)
            if len(data) != size:
                raise InputError(
                    f"{file}: got {len(data) // PIECE_BYTES} pieces, expected {pieces} "
                    "(as exported)"
                )
            packed.append(data)
        out[drone] = flown_uploads([u[3] for u in uploads], packed, duration_s, axes)
    return out


#: Per drone: name, duration (s), axes, and per upload (file, pieces, bytes, start in s).
_Schedule = list[tuple[str, float, int, list[tuple[str, int, int, float]]]]


def _schedule(summary: Path) -> _Schedule:
    """The drones' uploads as ``summary`` lists them (:data:`_Schedule`)."""
    try:
        data = read_json_file(summary, "a Crazyswarm export summary")  # a regular file, strictly
        return [
            (
                str(d["drone"]),
                float(d["duration_s"]),
                int(d["axes"]),
                [
                    (str(u["file"]), int(u["pieces"]), int(u["bytes"]), float(u["start_s"]))
                    for u in d["uploads"]
                ],
            )
            for d in data["drone_uploads"]
        ]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise InputError(
            f"summary: got {str(summary)!r} ({exc}), expected a readable Crazyswarm export summary"
        ) from exc


def write_fly_script(path: Path, drones: Sequence[DroneExport], several: bool) -> Path:
    """``path``: :mod:`skyquill.export.crazyflie.fly_script` with the drones' flights."""
    schedule = {
        (d.drone if several else SINGLE): d.flight
        | {
            "uploads": [
                {
                    "file": u.file.name,
                    "start_s": u.start_s,
                    "end_s": u.end_s,
                    "start": u.start[0].tolist(),
                    "end": u.end[0].tolist(),
                }
                for u in d.uploads
            ]
        }
        for d in drones
    }
    source = Path(fly_script.__file__).read_text(encoding="utf-8")
    marker = "SCHEDULE: dict[str, dict[str, Any]] = {}\n"
    if marker not in source:  # pragma: no cover - the template and this line go together
        raise RuntimeError("fly_script.py: the SCHEDULE line is missing")
    literal = json.dumps(schedule, indent=4)  # strings, numbers, lists: also a Python literal
    path.write_text(
        source.replace(marker, f"SCHEDULE: dict[str, dict[str, Any]] = {literal}\n"),
        encoding="utf-8",
    )
    return path


def _check_rest(uploads: Sequence[Upload]) -> None:
    """Refuse an upload that starts or ends in motion (the firmware would stop it dead)."""
    for i, upload in enumerate(uploads, start=1):
        ends: tuple[tuple[str, Trajectory, float, float], ...] = (
            ("start", upload.parts[0], 0.0, upload.start_s),
            ("end", upload.parts[-1], upload.parts[-1].duration, upload.end_s),
        )
        for where, part, local, t in ends:
            for order, name in ((1, "speed"), (2, "acceleration")):
                value = float(np.linalg.norm(part.evaluate(np.array([local]), order)[0]))
                if value > REST_TOLERANCE:
                    raise InputError(
                        f"trajectory: got {name} {value:.3g} at the {where} of upload {i} "
                        f"({t:.3f} s), expected rest (at most {REST_TOLERANCE:g}) where a "
                        f"Crazyflie upload starts or ends; plan it with target "
                        f"{CRAZYFLIE.name!r}"
                    )


def _state(rows: FloatArray) -> dict[str, list[float]]:
    return {k: rows[i].tolist() for i, k in enumerate(("position", "velocity", "acceleration"))}


def _message(drones: Sequence[DroneExport], script: Path, plans: Sequence[NamedPlan]) -> str:
    uploads = sum(len(d.uploads) for d in drones)
    largest = max(u.bytes for d in drones for u in d.uploads)
    error = max(d.delivered.max_error_m for d in drones)
    excess = max(d.delivered.limit_excess for d in drones)
    text = (
        f"wrote {uploads} Crazyflie upload(s) for {len(drones)} drone(s) (largest {largest} B "
        f"of {MEMORY_BYTES}) and {script.name}; flown as the firmware evaluates them (float32): "
        f"within {1e3 * error:.3g} mm of the plan, limit excess {excess:.2g} (float32 "
        f"rounding allowed: {FLOAT32_LIMIT_TOLERANCE:g})"
    )
    if any(not d.within_limits for d in drones):
        text += (
            f" -- WARNING: above the float32 rounding tolerance {FLOAT32_LIMIT_TOLERANCE:g}; "
            "plan with a margin below the vehicle's limits"
        )
    return text


EXPORTER = CrazyswarmExporter()
