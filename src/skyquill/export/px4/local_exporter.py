"""PX4 offboard setpoints in PX4's local NED frame: a CSV of samples, read back as ENU.

The frame conversion is :mod:`skyquill.export.px4.setpoints`; the file is checked as a
consumer reads it, with the NED-to-ENU conversion applied. It holds the plan's mission only
(:mod:`skyquill.phases`): ``send_mavsdk`` arms, takes off with PX4's own take-off to the first
row's height, enters offboard there, streams the rows and lands with PX4's own landing; the
summary's ``px4_parameters`` (per drone) are the parameters to pass it, which keep that
take-off and landing inside the plan's limits (:mod:`.flight_parameters`).
"""

from __future__ import annotations

from pathlib import Path

from skyquill.export.px4.flight_parameters import px4_flight_parameters
from skyquill.export.px4.setpoints import px4_setpoints, read_px4_csv
from skyquill.export.samples import SampledExporter
from skyquill.trajectory import SampledTrajectory, Trajectory


def _write_px4(traj: Trajectory, path: Path, rate: float) -> SampledTrajectory:
    px4_setpoints(traj, rate_hz=rate).to_csv(path)
    return read_px4_csv(path)


EXPORTER = SampledExporter(
    "px4",
    ".csv",
    "PX4 offboard setpoints CSV in NED, yaw in degrees: the plan's mission, from its first "
    "airborne point (PX4 takes off to it and lands after it)",
    _write_px4,
    mission_only=True,
    drone_details=lambda planned: px4_flight_parameters(planned.limits),
    details_key="px4_parameters",
)
