"""Skybrush ``.skyc`` show (cubic Bézier segments), read back as Skybrush plays it."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from skyquill.export.base import ExportOptions, ExportReport, NamedPlan, max_distance
from skyquill.export.refit import as_spline
from skyquill.io.skyc import read_show_json, show_trajectories, write_skyc


@dataclass(frozen=True)
class SkycExporter:
    """One show file for every drone of the plan."""

    name: str = "skyc"
    suffix: str = ".skyc"
    help: str = "Skybrush show (.skyc), one drone per trajectory"

    def __call__(
        self, plans: Sequence[NamedPlan], out: Path, options: ExportOptions
    ) -> ExportReport:
        """Write, reopen the archive, rebuild each drone's curve, compare."""
        fitted = [as_spline(p.trajectory, p.limits) for _, p in plans]
        show = write_skyc([f.spline for f in fitted], out.with_suffix(".skyc"))
        back = show_trajectories(read_show_json(show.path))
        error = max(max_distance(p.trajectory, b) for (_, p), b in zip(plans, back, strict=True))
        refit = max(f.max_deviation_m for f in fitted)
        return ExportReport(
            self.name,
            (show.path,),
            exact=show.exact and refit == 0.0,
            max_error_m=error,
            message=show.message,
            details={"segments": show.segments, "refit_max_deviation_m": refit},
        )


EXPORTER = SkycExporter()
