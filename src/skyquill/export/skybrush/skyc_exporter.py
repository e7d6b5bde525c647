"""Skybrush ``.skyc`` show: keyframes on Skybrush's ms and mm grid, lights, yaw, validation.

Each drone's plan becomes C2 cubic Bézier keyframes on the grid Skybrush's server stores,
played back and refitted until they play inside the plan's limits
(:mod:`skyquill.export.skybrush.refit`), starting and ending on its pad
(:mod:`skyquill.export.skybrush.pads`), a light program that is on in the chosen colour
while the pen is down (:mod:`skyquill.export.skybrush.lights`), a constant yaw of 0, and the
show gets validation settings that the played curves meet (:mod:`.validation`). The written
file is then read back and played with Skybrush's own arithmetic
(:mod:`skyquill.export.skybrush.playback`): the distance from the plan and the dense limit check
are measured on what the drones will fly (``as_played`` in the summary), and the lights on
what they will show.
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
    AsPlayed,
    DeliveredCheck,
    ExportOptions,
    ExportReport,
    NamedPlan,
    check_delivered,
)
from skyquill.export.skybrush.lights import (
    colored_frames,
    encode_light_program,
    light_slices,
    longest_mismatch_ms,
    program_bytes,
)
from skyquill.export.skybrush.pads import on_pads, takeoff_report
from skyquill.export.skybrush.playback import played_show
from skyquill.export.skybrush.refit import PlayedKeyframes, played_keyframes
from skyquill.export.skybrush.skyc_file import (
    SkycDrone,
    read_show_json,
    read_show_location,
    show_location,
    write_skyc,
)
from skyquill.export.skybrush.validation import validation_settings
from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.parallel import parallel_map
from skyquill.trajectory import Trajectory

#: Heading of the show's X+ axis, degrees clockwise from north: skyquill's x is east.
SHOW_X_HEADING_DEG = 90.0


@dataclass(frozen=True)
class SkycExporter:
    """One show file for every drone of the plan."""

    name: str = "skyc"
    suffix: str = ".skyc"
    help: str = "Skybrush show (.skyc), one drone per trajectory, lit while the pen is down"
    #: Where each drone's keyframes are made (:func:`skyquill.parallel.parallel_map`): in
    #: this process by default, in ``workers`` processes, or on the dask ``scheduler``.
    workers: int | None = 1
    scheduler: str | None = None

    def __call__(
        self, plans: Sequence[NamedPlan], out: Path, options: ExportOptions
    ) -> ExportReport:
        """Write the show, read it back as the drones play it, check it against the plans."""
        return self.export(plans, out, options)[0]

    def export(
        self, plans: Sequence[NamedPlan], out: Path, options: ExportOptions
    ) -> tuple[ExportReport, dict[str, Any]]:
        """As calling the exporter, and the ``show.json`` read back from the file written
        (:func:`~skyquill.export.skybrush.skyc_file.read_show_json`), for a caller's own
        checks of what was written (``skyquill show`` proves it apart as played) without
        reading it again."""
        grounded = parallel_map(
            _keyframed, list(plans), workers=self.workers, scheduler=self.scheduler
        )
        plans = [(name, plan) for (name, _), (plan, _) in zip(plans, grounded, strict=True)]
        made = [keys for _, keys in grounded]
        drones = [
            SkycDrone(
                name,
                keys.keyframes,
                encode_light_program(
                    plan.pen_windows_s, plan.colors(options.light_rgb), plan.trajectory.duration
                ),
            )
            for (name, plan), keys in zip(plans, made, strict=True)
        ]
        # The validation settings are measured on what the drones will fly.
        validation = validation_settings([p.limits for _, p in plans], [m.played for m in made])
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
            parallel_map(
                _checked,
                [(name, plan, back) for (name, plan), back in zip(plans, played, strict=True)],
                workers=self.workers,
                scheduler=self.scheduler,
            )
        )
        lights = [
            _light_mismatch(show, i, plan, options.light_rgb, back.duration)
            for i, ((_, plan), back) in enumerate(zip(plans, played, strict=True))
        ]
        details = _details(drones, delivered, lights, validation)
        details["pads"] = [
            takeoff_report(plan.trajectory) | {"drone": name} for name, plan in plans
        ]
        details["keyframes"] = [
            keys.report() | {"drone": name} for (name, _), keys in zip(plans, made, strict=True)
        ]
        shift = 0.0 if frame is None else _location_shift(show, frame)
        if frame is not None:
            details["location"] = show["environment"]["location"] | {"shift_m": shift}
        report = ExportReport(
            self.name,
            (path,),
            exact=False,
            # the whole show is flown around the stored (rounded) origin
            max_error_m=max(d.max_error_m for d in delivered) + shift,
            message=_message(path, details, AsPlayed.of(delivered)),
            details=details,
            delivered=delivered,
        )
        return report, show


def _keyframed(named: NamedPlan) -> tuple[PlannedTrajectory, PlayedKeyframes]:
    """A drone's plan on its pads (as Skybrush expects) and its keyframes, played and checked."""
    name, plan = named
    grounded = on_pads(plan)
    return grounded, played_keyframes(name, grounded)


def _checked(drone: tuple[str, PlannedTrajectory, Trajectory]) -> DeliveredCheck:
    """A drone as read back from the file, checked against its plan."""
    return check_delivered(*drone)


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
    as_played = AsPlayed.of(delivered)
    return {
        "segments": sum(d.keyframes.units.shape[0] for d in drones),
        "keyframe_grid": "integer ms, coordinates in whole units of scale mm",
        "keyframe_degree": 3,
        "scale_mm": [d.keyframes.scale for d in drones],
        "keyframe_fit_max_m": max(d.keyframes.fit_error_m for d in drones),
        "pen_down_max_error_m": max(d.pen_down_max_error_m for d in delivered),
        "limit_excess": max(d.limit_excess for d in delivered),
        "limits_hold": as_played.within_allowed,
        "lights": {"frame_ms": 20, "per_drone": list(lights)},
        "yaw_deg": 0.0,
        "validation": validation,
    }


def _message(path: Path, details: dict[str, Any], as_played: AsPlayed) -> str:
    offset = max(light["max_offset_ms"] for light in details["lights"]["per_drone"])
    return (
        f"wrote {len(details['scale_mm'])} drone(s), {details['segments']} C2 Bézier segment(s) "
        f"on Skybrush's ms/mm grid to {path.name}; as Skybrush plays it: "
        f"{as_played.describe()} (as_played in the summary); lights switch within {offset} ms "
        "of the pen (20 ms light frames)"
    )


EXPORTER = SkycExporter()
