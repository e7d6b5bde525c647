"""PX4 global setpoints: latitude/longitude as MAVLink carries them, for a plan with an origin.

The columns are the fields of MAVLink's ``SET_POSITION_TARGET_GLOBAL_INT`` in
``MAV_FRAME_GLOBAL_RELATIVE_ALT_INT`` (what MAVSDK's ``set_position_global`` and
PX4's offboard mode take): ``lat_int``/``lon_int`` in integer 1e-7 degrees
(about 1.1 cm: the link's own resolution), the altitude relative to home in m,
and velocity, acceleration (NED, m/s, m/s^2) and yaw (degrees clockwise from
north) as in :mod:`skyquill.export.px4.setpoints`. The plan's x east, y north (m) are mapped to
WGS84 through the plan's :class:`~skyquill.coverage.geo.GeoFrame`; its z is the
height above the take-off point, which PX4 calls home.

Read back, the integers are mapped to the local frame again with pyproj, as a
ground station would, and checked against the plan. (PX4 itself maps global
setpoints to its local frame with a spherical azimuthal equidistant projection
at its EKF origin; its GPS fusion uses the same one, so the vehicle is steered to
the latitude/longitude, not to the local numbers.)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from skyquill.coverage.geo import GeoFrame
from skyquill.errors import InputError
from skyquill.export.base import ExportOptions, ExportReport, NamedPlan
from skyquill.export.px4.flight_parameters import px4_flight_parameters
from skyquill.export.px4.setpoints import (
    PX4_COLUMNS,
    check_stream_rate,
    enu_to_ned,
    yaw_enu_to_ned_deg,
)
from skyquill.export.samples import SampledExporter
from skyquill.io.points import trajectory_table
from skyquill.io.table import read_table
from skyquill.trajectory import SampledTrajectory, Trajectory

#: Header of the global setpoint CSV (MAVLink ``SET_POSITION_TARGET_GLOBAL_INT`` fields):
#: the position as the link carries it, then velocity, acceleration and yaw as the NED CSV.
PX4_GLOBAL_COLUMNS = ("t", "lat_int", "lon_int", "alt_rel_m", *PX4_COLUMNS[4:])
#: MAVLink's integer latitude/longitude unit, degrees.
DEG_E7 = 1e-7


def write_px4_global(traj: Trajectory, path: Path, rate_hz: float, frame: GeoFrame) -> int:
    """Sample ``traj`` (x east, y north, z up; m) at ``rate_hz`` and write global setpoints.

    Returns
    -------
    int
        The number of rows written.
    """
    table = trajectory_table(traj, check_stream_rate(rate_hz))
    lon, lat = frame.to_geo(table[:, 1], table[:, 2])
    # float32: the MAVLink message's own type for altitude, velocity and acceleration
    f32 = np.float32
    rows = np.column_stack(
        [
            table[:, 0],
            np.round(lat / DEG_E7),
            np.round(lon / DEG_E7),
            table[:, 3].astype(f32),
            enu_to_ned(table[:, 4:7]).astype(f32),
            enu_to_ned(table[:, 7:10]).astype(f32),
            np.full(table.shape[0], float(yaw_enu_to_ned_deg(0.0))),
        ]
    )
    fmt = ["%.9g", "%d", "%d", *["%.9g"] * 8]
    np.savetxt(path, rows, delimiter=",", header=",".join(PX4_GLOBAL_COLUMNS), comments="", fmt=fmt)
    return int(rows.shape[0])


def read_px4_global(path: Path, frame: GeoFrame) -> SampledTrajectory:
    """Read a global setpoint CSV back into the plan's local frame (pyproj, ``frame``)."""
    table = read_table(path, required=PX4_GLOBAL_COLUMNS, min_rows=2, name="PX4 global setpoints")
    x, y = frame.to_local(table.column("lon_int") * DEG_E7, table.column("lat_int") * DEG_E7)
    p = np.column_stack([x, y, table.column("alt_rel_m")])
    v, a = (enu_to_ned(table.select(PX4_GLOBAL_COLUMNS[i : i + 3])) for i in (4, 7))
    return SampledTrajectory(table.column("t"), p, v, a)


@dataclass(frozen=True)
class Px4GlobalExporter:
    """One global setpoint CSV per drone; needs the plan's geographic origin."""

    name: str = "px4-global"
    suffix: str = ".csv"
    help: str = (
        "PX4 global setpoints CSV (MAVLink lat/lon in 1e-7 deg, altitude above home), "
        "for plans with a geographic origin (cover of a GeoJSON)"
    )

    def __call__(
        self, plans: Sequence[NamedPlan], out: Path, options: ExportOptions
    ) -> ExportReport:
        """Write each drone's setpoints, read them back through pyproj, compare with the plan."""
        if options.origin is None:
            raise InputError(
                "origin: got none, expected a plan with a geographic origin (a cover plan of "
                "a GeoJSON field in longitude/latitude or a projected CRS) for px4-global"
            )
        origin = options.origin

        def write(traj: Trajectory, path: Path, rate_hz: float) -> SampledTrajectory:
            write_px4_global(traj, path, rate_hz, origin)
            return read_px4_global(path, origin)

        # The sampled formats' loop: one file a drone, read back, checked against the plan.
        report = SampledExporter(
            self.name,
            self.suffix,
            self.help,
            write,
            mission_only=True,
            drone_details=lambda planned: px4_flight_parameters(planned.limits),
            details_key="px4_parameters",
        )(plans, out, options)
        return replace(
            report,
            message=f"wrote {len(report.files)} PX4 global setpoint file(s) at "
            f"{options.rate_hz:g} Hz around lat {origin.lat_deg:.7f}, "
            f"lon {origin.lon_deg:.7f}: " + ", ".join(f.name for f in report.files),
            details=report.details | {"origin": origin.as_dict()},
        )


EXPORTER = Px4GlobalExporter()
