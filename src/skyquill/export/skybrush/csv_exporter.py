"""Skybrush Studio's zipped CSV (``Time_msec,x_m,y_m,z_m,Red,Green,Blue``, one file per drone).

Rows every ``1 / rate_hz`` s on the millisecond grid, plus rows one millisecond either side
of every pen-window end (rounded to the ms), so the light switches on the millisecond the
pen does even though Studio fades colours linearly between rows. Read back as Studio reads
it (:mod:`skyquill.export.skybrush.csv_file`: positions interpolated linearly), then checked: the
distance from the plan, the speed limit (a linear interpolation has no acceleration between
rows and an impulse at each, so only the speed check means something), the lights. Each
drone starts and ends on its pad (:mod:`.pads`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from skyquill.colors import RGB
from skyquill.export.base import (
    DeliveredCheck,
    ExportOptions,
    ExportReport,
    NamedPlan,
    check_delivered,
)
from skyquill.export.skybrush.csv_file import CsvDrone, read_csv_zip, write_csv_zip
from skyquill.export.skybrush.pads import on_pads
from skyquill.io.trajectory_json import PlannedTrajectory, light_at
from skyquill.parallel import parallel_map


def _ms_windows(windows_s: Sequence[tuple[float, float]]) -> list[tuple[int, int]]:
    return [(round(a * 1000), round(b * 1000)) for a, b in windows_s]


def _row_times(plan: PlannedTrajectory, rate_hz: float) -> NDArray[np.int64]:
    end = max(1, math.ceil(plan.trajectory.duration * 1000 - 1e-6))
    step = max(1, round(1000 / rate_hz))
    edges = [e for a, b in _ms_windows(plan.pen_windows_s) for e in (a - 1, a, b, b + 1)]
    times = np.concatenate([np.arange(0, end, step), [end], edges])
    return np.unique(np.clip(times, 0, end)).astype(np.int64)


def _ms_light(plan: PlannedTrajectory, t_ms: NDArray[np.int64], rgb: RGB) -> NDArray[np.int64]:
    """The light at ``t_ms`` (N,): each pen window's colour on its milliseconds, else black."""
    return light_at(t_ms, _ms_windows(plan.pen_windows_s), plan.colors(rgb))


def csv_drone(name: str, plan: PlannedTrajectory, rate_hz: float, rgb: RGB) -> CsvDrone:
    """The rows of one drone: lit on every millisecond of a pen window, in the window's colour."""
    t_ms = _row_times(plan, rate_hz)
    positions = plan.trajectory.evaluate(np.minimum(t_ms / 1000, plan.trajectory.duration))
    return CsvDrone(name, t_ms, positions, _ms_light(plan, t_ms, rgb))


def _lights_exact(back: CsvDrone, plan: PlannedTrajectory, rgb: RGB) -> bool:
    return bool(np.array_equal(back.colors, _ms_light(plan, back.t_ms, rgb)))


def _rows(rate_hz: float, rgb: RGB, named: NamedPlan) -> tuple[PlannedTrajectory, CsvDrone]:
    """A drone's plan on its pads (as Skybrush expects) and its rows."""
    name, plan = named
    grounded = on_pads(plan)
    return grounded, csv_drone(name, grounded, rate_hz, rgb)


def _speed_check(drone: tuple[str, PlannedTrajectory, CsvDrone]) -> DeliveredCheck:
    """A drone's rows as read back, checked against its plan: linear between rows, so only
    the speed means something."""
    name, plan, back = drone
    return check_delivered(name, plan, back.trajectory(), orders=(1,))


@dataclass(frozen=True)
class SkybrushCsvExporter:
    """One ZIP of per-drone CSVs, as Skybrush Studio exports and imports them."""

    name: str = "skybrush-csv"
    suffix: str = ".zip"
    help: str = "Skybrush Studio zipped CSV (Time_msec,x_m,y_m,z_m,Red,Green,Blue), one per drone"
    #: Where each drone's rows are made and checked (:func:`skyquill.parallel.parallel_map`):
    #: in this process by default, in ``workers`` processes, or on the dask ``scheduler``.
    workers: int | None = 1
    scheduler: str | None = None

    def __call__(
        self, plans: Sequence[NamedPlan], out: Path, options: ExportOptions
    ) -> ExportReport:
        """Write the rows, read the archive back as Studio does, check each drone."""
        rgb = options.light_rgb
        made = parallel_map(
            partial(_rows, options.rate_hz, rgb),
            list(plans),
            workers=self.workers,
            scheduler=self.scheduler,
        )
        plans = [(name, plan) for (name, _), (plan, _) in zip(plans, made, strict=True)]
        rows = [row for _, row in made]
        path = write_csv_zip(rows, out.with_suffix(self.suffix))
        back = {d.name: d for d in read_csv_zip(path)}
        delivered = tuple(
            parallel_map(
                _speed_check,
                [(n, p, back[n]) for n, p in plans],
                workers=self.workers,
                scheduler=self.scheduler,
            )
        )
        details: dict[str, Any] = {
            "rows": sum(d.t_ms.size for d in rows),
            "rate_hz": options.rate_hz,
            "interpolation": "linear between rows (Skybrush Studio's import): only the speed "
            "limit is meaningful on it",
            "lights_exact_to_ms": all(_lights_exact(back[n], p, rgb) for n, p in plans),
        }
        error = max(d.max_error_m for d in delivered)
        return ExportReport(
            self.name,
            (path,),
            exact=False,
            max_error_m=error,
            message=f"wrote {len(rows)} drone CSV(s), {details['rows']} rows, to {path.name}",
            details=details,
            delivered=delivered,
        )


EXPORTER = SkybrushCsvExporter()
