"""The export registry: every format writes, reads itself back as its consumer does, reports."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import make_interp_spline

from skyquill.coverage.geo import GeoFrame
from skyquill.errors import InputError
from skyquill.export import EXPORTERS, ExportOptions, exporter
from skyquill.export.skybrush.refit import MAX_DEVIATION_M
from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.limits import VehicleLimits
from skyquill.trajectory import RetimedPath, SplineTrajectory, Trajectory

LIMITS = VehicleLimits(2.0, 4.0, 20.0).derivative_limits(3)
#: Exact formats to float rounding; Skybrush's cubics on its ms/mm grid to 2 mm; sampled
#: formats to the interpolation between their 100 Hz rows.
TOLERANCE_M = {
    "crazyswarm": 1e-5,
    # Skybrush: C2 cubic keyframes fitted within MAX_DEVIATION_M (2 cm), then on its grid
    "skyc": MAX_DEVIATION_M + 2e-3,
    "skybrush-csv": MAX_DEVIATION_M + 2e-3,
    "px4": 1e-3,
    "px4-global": 1e-2,  # MAVLink's 1e-7 degree integers: up to 6.7 mm at 47 N
    "csv": 1e-3,
    "json": 1e-3,
}


def _spline() -> SplineTrajectory:
    ctrl = np.random.default_rng(1).normal(scale=0.3, size=(14, 3))
    ctrl[:3], ctrl[-3:] = ctrl[0], ctrl[-1]
    ctrl[:, 2] += 1.5  # in the air: its mission above the minimum altitude (issue 26)
    return SplineTrajectory(ctrl, 5, 7.0)  # inside LIMITS (at 5 s: 78 % over the jerk)


def _retimed() -> RetimedPath:
    u = np.linspace(0.0, 1.0, 12)
    curve = make_interp_spline(u, np.c_[np.cos(u), np.sin(u), 1.0 + 0 * u], k=5)
    t = np.linspace(0.0, 3.0, 60)
    x = t / 3.0
    law = (10 * x**3 - 15 * x**4 + 6 * x**5, (30 * x**2 - 60 * x**3 + 30 * x**4) / 3.0,
           (60 * x - 180 * x**2 + 120 * x**3) / 9.0)  # fmt: skip
    return RetimedPath.from_samples(curve, t, *law)


@pytest.mark.parametrize("name", list(EXPORTERS))
@pytest.mark.parametrize("kind", ["spline", "retimed"])
def test_every_format_reads_back_within_its_tolerance(tmp_path: Path, name: str, kind: str) -> None:
    traj: Trajectory = _spline() if kind == "spline" else _retimed()
    plans = [("drone", PlannedTrajectory(traj, (), LIMITS))]
    chosen = EXPORTERS[name]
    if name == "crazyswarm" and kind == "retimed":  # not polynomial: plan it for the target
        with pytest.raises(InputError, match="plan it with target 'crazyflie'"):
            chosen(plans, tmp_path / "out.csv", ExportOptions(100.0))
        return
    # every format takes an origin; px4-global needs one
    options = ExportOptions(100.0, origin=GeoFrame(8.54, 47.37))
    report = chosen(plans, tmp_path / f"out{chosen.suffix}", options)
    assert report.format == name and report.files and all(f.is_file() for f in report.files)
    assert report.max_error_m <= TOLERANCE_M[name]
    assert report.as_dict()["max_error_m"] == report.max_error_m


def test_two_drones_get_two_files_or_one_show(tmp_path: Path) -> None:
    plans = [(f"trajectory_{i}", PlannedTrajectory(_spline(), (), LIMITS)) for i in range(2)]
    csv = EXPORTERS["csv"](plans, tmp_path / "x.csv", ExportOptions())
    assert [f.name for f in csv.files] == ["x_trajectory_0.csv", "x_trajectory_1.csv"]
    show = EXPORTERS["skyc"](plans, tmp_path / "show.skyc", ExportOptions())
    assert [f.name for f in show.files] == ["show.skyc"]


def test_unknown_format_is_named() -> None:
    with pytest.raises(InputError, match="format: got 'kml', expected one of crazyswarm"):
        exporter("kml")
    assert exporter("skyc") is EXPORTERS["skyc"]
