"""Exporters behind one protocol, chosen from one registry (the CLI and the studio read it).

A consumer is one package (``crazyflie/``, ``skybrush/``, ``px4/``): its encoding, its
model of what the vehicle plays, its exporter and its fly script. A new format is one
:class:`~skyquill.export.base.Exporter` there and one entry in :data:`EXPORTERS`; the
generic sampled formats (``samples.py``) and GeoJSON (``geojson.py``) sit beside them.
"""

from __future__ import annotations

from skyquill.errors import InputError
from skyquill.export.base import Exporter, ExportOptions, ExportReport, NamedPlan
from skyquill.export.crazyflie.exporter import EXPORTER as CRAZYSWARM
from skyquill.export.px4.global_exporter import EXPORTER as PX4_GLOBAL
from skyquill.export.px4.local_exporter import EXPORTER as PX4
from skyquill.export.samples import CSV, JSON
from skyquill.export.skybrush.csv_exporter import EXPORTER as SKYBRUSH_CSV
from skyquill.export.skybrush.skyc_exporter import EXPORTER as SKYC

EXPORTERS: dict[str, Exporter] = {
    e.name: e for e in (CRAZYSWARM, SKYC, SKYBRUSH_CSV, PX4, PX4_GLOBAL, CSV, JSON)
}


def exporter(name: str) -> Exporter:
    """The exporter called ``name``; :class:`InputError` naming the choices otherwise."""
    if name not in EXPORTERS:
        raise InputError(f"format: got {name!r}, expected one of {', '.join(EXPORTERS)}")
    return EXPORTERS[name]


__all__ = ["EXPORTERS", "ExportOptions", "ExportReport", "Exporter", "NamedPlan", "exporter"]
