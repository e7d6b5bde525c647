"""Crazyswarm2 / cflib polynomial CSV (exact), read back with the reader's own layout."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from skyquill.export.base import ExportOptions, ExportReport, NamedPlan, max_distance, target
from skyquill.export.refit import as_spline
from skyquill.io.crazyswarm import read_crazyswarm, write_crazyswarm


@dataclass(frozen=True)
class CrazyswarmExporter:
    """One CSV of degree-7 pieces per drone (split into uploads of at most 31 pieces)."""

    name: str = "crazyswarm"
    suffix: str = ".csv"
    help: str = "Crazyswarm2/cflib polynomial CSV, exact (uploads of <= 31 pieces)"

    def __call__(
        self, plans: Sequence[NamedPlan], out: Path, options: ExportOptions
    ) -> ExportReport:
        """Write, read back with :func:`read_crazyswarm`, compare."""
        files: list[Path] = []
        notes, error, refit = [], 0.0, 0.0
        for name, planned in plans:
            fitted = as_spline(planned.trajectory, planned.limits)
            written = write_crazyswarm(fitted.spline, target(out, name, len(plans) > 1, ".csv"))
            back = read_crazyswarm(written.files)
            error = max(error, max_distance(planned.trajectory, back))
            refit = max(refit, fitted.max_deviation_m)
            files += written.files
            notes.append(written.message)
        return ExportReport(
            self.name,
            tuple(files),
            exact=refit == 0.0,
            max_error_m=error,
            message="; ".join(notes),
            details={"refit_max_deviation_m": refit},
        )


EXPORTER = CrazyswarmExporter()
