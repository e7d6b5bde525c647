"""The sampled formats: ``trajectory.csv`` columns and setpoints JSON.

PX4's NED setpoints use the same :class:`SampledExporter`
(:mod:`skyquill.export.px4.local_exporter`).

Each samples the trajectory at the requested rate, writes, reads the file back
with its reader
and measures the distance of that read-back from the plan.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from skyquill.export.base import (
    ExportOptions,
    ExportReport,
    NamedPlan,
    check_delivered,
    mission_plan,
    target,
)
from skyquill.io.points import write_trajectory_csv
from skyquill.io.setpoints_json import read_setpoints_json, write_setpoints_json
from skyquill.io.trajectory_csv import read_trajectory_csv
from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.trajectory import SampledTrajectory, Trajectory


def _write_csv(traj: Trajectory, path: Path, rate: float) -> SampledTrajectory:
    write_trajectory_csv(path, traj, rate)
    return read_trajectory_csv(path)


def _write_json(traj: Trajectory, path: Path, rate: float) -> SampledTrajectory:
    write_setpoints_json(traj, path, rate)
    return read_setpoints_json(path).trajectory


@dataclass(frozen=True)
class SampledExporter:
    """A format that holds samples: one file per drone, read back by its own reader.

    ``mission_only``: the file holds the plan's mission (:mod:`skyquill.phases`) on its own
    clock, for a vehicle that takes off and lands by itself (PX4: its first row is the first
    airborne setpoint, where offboard starts); else the whole plan.
    """

    name: str
    suffix: str
    help: str
    write: Callable[[Trajectory, Path, float], SampledTrajectory]
    mission_only: bool = False
    #: Per drone, more for the summary's ``details`` (PX4: its take-off and landing
    #: parameters), under ``details_key``.
    drone_details: Callable[[PlannedTrajectory], dict[str, Any]] | None = None
    details_key: str = ""

    def __call__(
        self, plans: Sequence[NamedPlan], out: Path, options: ExportOptions
    ) -> ExportReport:
        """Write each drone's samples, read them back, compare with the plan."""
        files, checks = [], []
        if self.mission_only:
            plans = [(name, mission_plan(planned)) for name, planned in plans]
        for name, planned in plans:
            path = target(out, name, len(plans) > 1, self.suffix)
            back = self.write(planned.trajectory, path, options.rate_hz)
            checks.append(check_delivered(name, planned, back))
            files.append(path)
        return ExportReport(
            self.name,
            tuple(files),
            exact=False,
            max_error_m=max(c.max_error_m for c in checks),
            message=f"wrote {len(files)} {self.name} file(s) at {options.rate_hz:g} Hz: "
            + ", ".join(f.name for f in files),
            details={"rate_hz": options.rate_hz} | self._more(plans),
            delivered=tuple(checks),
        )

    def _more(self, plans: Sequence[NamedPlan]) -> dict[str, Any]:
        if self.drone_details is None:
            return {}
        return {self.details_key: {name: self.drone_details(p) for name, p in plans}}


CSV = SampledExporter("csv", ".csv", "trajectory.csv columns (t, x..jz), z-up, SI", _write_csv)
JSON = SampledExporter("json", ".json", "setpoints JSON (rows of t, x..jz), z-up, SI", _write_json)
