"""Skybrush ``.skyc`` show: keyframes on Skybrush's ms and mm grid, lights, yaw, validation.

Each drone's plan becomes cubic Bézier keyframes on the grid Skybrush's server stores
(:mod:`skyquill.export.skybrush.keyframes`), a light program that is on in the chosen colour
while the pen is down (:mod:`skyquill.export.skybrush.lights`), a constant yaw of 0, and the
show gets the validation settings its plan implies (:mod:`.skybrush_validation`). The
written file is then read back and played with Skybrush's own arithmetic
(:mod:`skyquill.export.skybrush.playback`): the distance from the plan and the dense limit check
are measured on what the drones will fly, and the lights on what they will show.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from skyquill.colors import RGB
from skyquill.coverage.geo import GeoFrame
from skyquill.errors import InputError
from skyquill.export.base import (
    DeliveredCheck,
    ExportOptions,
    ExportReport,
    NamedPlan,
    check_delivered,
)
from skyquill.export.skybrush.keyframes import skybrush_keyframes
from skyquill.export.skybrush.lights import (
    colored_frames,
    encode_light_program,
    light_slices,
    longest_mismatch_ms,
    program_bytes,
)
from skyquill.export.skybrush.playback import played_show, played_trajectory
from skyquill.export.skybrush.skyc_file import (
    SkycDrone,
    read_show_json,
    read_show_location,
    show_location,
    write_skyc,
)
from skyquill.export.skybrush.validation import validation_settings
from skyquill.io.trajectory_json import PlannedTrajectory

#: A limit excess below this counts as none (float rounding of the read-back), relative.
EXCESS_TOLERANCE = 1e-9
#: Heading of the show's X+ axis, degrees clockwise from north: skyquill's x is east.
SHOW_X_HEADING_DEG = 90.0


@dataclass(frozen=True)
class SkycExporter:
    """One show file for every drone of the plan."""

    name: str = "skyc"
    suffix: str = ".skyc"
    help: str = "Skybrush show (.skyc), one drone per trajectory, lit while the pen is down"

    def __call__(
        self, plans: Sequence[NamedPlan], out: Path, options: ExportOptions
    ) -> ExportReport:
        """Write the show, read it back as the drones play it, check it against the plans."""
        drones = [
            SkycDrone(
                name,
                skybrush_keyframes(plan.trajectory),
                encode_light_program(
                    plan.pen_windows_s, plan.colors(options.light_rgb), plan.trajectory.duration
                ),
            )
            for name, plan in plans
        ]
        # The validation settings are measured on what the drones will fly.
        flown = [
            played_trajectory(d.name, {"points": d.keyframes.points()}).trajectory() for d in drones
        ]
        validation = validation_settings([p.limits for _, p in plans], flown)
        frame = options.origin
        location = (
            None
            if frame is None
            # skyquill's x is east: the show's X+ axis heads 90 degrees from north
            else show_location(frame.lat_deg, frame.lon_deg, frame.alt_m, SHOW_X_HEADING_DEG)
        )
        path = write_skyc(
            drones, out.with_suffix(self.suffix), validation=validation, location=location
        )
        show = read_show_json(path)
        played = [p.trajectory() for p in played_show(show)]
        delivered = tuple(
            check_delivered(name, plan, back)
            for (name, plan), back in zip(plans, played, strict=True)
        )
        lights = [
            _light_mismatch(show, i, plan, options.light_rgb, back.duration)
            for i, ((_, plan), back) in enumerate(zip(plans, played, strict=True))
        ]
        details = _details(drones, delivered, lights, validation)
        shift = 0.0 if frame is None else _location_shift(show, frame)
        if frame is not None:
            details["location"] = show["environment"]["location"] | {"shift_m": shift}
        return ExportReport(
            self.name,
            (path,),
            exact=False,
            # the whole show is flown around the stored (rounded) origin
            max_error_m=max(d.max_error_m for d in delivered) + shift,
            message=_message(path, details),
            details=details,
            delivered=delivered,
        )


def _location_shift(show: dict[str, Any], frame: GeoFrame) -> float:
    """How far the origin read back from the show lies from the plan's, m (1e-7 deg rounding).

    A heading other than :data:`SHOW_X_HEADING_DEG` would turn the show: refused.
    """
    stored = read_show_location(show)
    assert stored is not None  # written with one
    lat, lon, _, heading = stored
    if heading != SHOW_X_HEADING_DEG:  # pragma: no cover - written here
        raise InputError(f"orientation: got {heading:g}, expected {SHOW_X_HEADING_DEG:g}")
    x, y = frame.to_local(lon, lat)
    return float(np.hypot(x, y))


def _light_mismatch(
    show: dict[str, Any],
    index: int,
    plan: PlannedTrajectory,
    rgb: RGB,
    duration_s: float,
) -> dict[str, Any]:
    """Where the light Skybrush shows differs from the pen's, on every millisecond of the show.

    Each millisecond compares the colour shown with the colour of the pen window it falls
    in (black outside).
    """
    where = f"show.json: swarm.drones[{index}].settings.lights"
    data = program_bytes(where, show["swarm"]["drones"][index]["settings"]["lights"])
    end_ms = math.ceil(duration_s * 1000)
    # the longest run of wrong milliseconds: how far a switch is from the pen's
    offset = longest_mismatch_ms(
        light_slices(where, data, end_ms), plan.pen_windows_s, plan.colors(rgb), end_ms
    )
    return {
        "windows": len(plan.pen_windows_s),
        "lit_windows": len(colored_frames(plan.pen_windows_s, plan.colors(rgb))),
        "colors": len(set(plan.colors(rgb))),
        "max_offset_ms": offset,
    }


def _details(
    drones: Sequence[SkycDrone],
    delivered: Sequence[DeliveredCheck],
    lights: Sequence[dict[str, Any]],
    validation: dict[str, float],
) -> dict[str, Any]:
    excess = max(d.limit_excess for d in delivered)
    return {
        "segments": sum(d.keyframes.units.shape[0] for d in drones),
        "keyframe_grid": "integer ms, coordinates in whole units of scale mm",
        "scale_mm": [d.keyframes.scale for d in drones],
        "keyframe_fit_max_m": max(d.keyframes.fit_error_m for d in drones),
        "pen_down_max_error_m": max(d.pen_down_max_error_m for d in delivered),
        "limit_excess": excess,
        "limits_hold": bool(excess <= EXCESS_TOLERANCE),
        "lights": {"frame_ms": 20, "per_drone": list(lights)},
        "yaw_deg": 0.0,
        "validation": validation,
    }


def _message(path: Path, details: dict[str, Any]) -> str:
    excess = details["limit_excess"]
    limits = (
        "the limits hold on it"
        if details["limits_hold"]
        else f"it exceeds the plan's limits by up to {100 * excess:.3g} % (see delivered)"
    )
    offset = max(light["max_offset_ms"] for light in details["lights"]["per_drone"])
    return (
        f"wrote {len(details['scale_mm'])} drone(s), {details['segments']} Bézier segment(s) on "
        f"Skybrush's ms/mm grid to {path.name}; as Skybrush plays it, {limits}; lights switch "
        f"within {offset} ms of the pen (20 ms light frames)"
    )


EXPORTER = SkycExporter()
