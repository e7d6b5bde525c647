"""Exporters behind one protocol, chosen from one registry (the CLI and the studio read it).

A new format is one file defining an :class:`~skyquill.export.base.Exporter`
and one entry in :data:`EXPORTERS`.
"""

from __future__ import annotations

from skyquill.errors import InputError
from skyquill.export.base import Exporter, ExportOptions, ExportReport, NamedPlan
from skyquill.export.crazyswarm import EXPORTER as CRAZYSWARM
from skyquill.export.px4_global import EXPORTER as PX4_GLOBAL
from skyquill.export.samples import CSV, JSON, PX4
from skyquill.export.skybrush_csv import EXPORTER as SKYBRUSH_CSV
from skyquill.export.skyc import EXPORTER as SKYC

EXPORTERS: dict[str, Exporter] = {
    e.name: e for e in (CRAZYSWARM, SKYC, SKYBRUSH_CSV, PX4, PX4_GLOBAL, CSV, JSON)
}


def exporter(name: str) -> Exporter:
    """The exporter called ``name``; :class:`InputError` naming the choices otherwise."""
    if name not in EXPORTERS:
        raise InputError(f"format: got {name!r}, expected one of {', '.join(EXPORTERS)}")
    return EXPORTERS[name]


__all__ = ["EXPORTERS", "ExportOptions", "ExportReport", "Exporter", "NamedPlan", "exporter"]
