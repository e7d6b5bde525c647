"""The exports that need the plan's geographic origin: px4-global, skyc's location, path.geojson.

Each is read back independently of the writer: the PX4 integers through
``pyproj.Geod`` (an azimuthal equidistant frame keeps the geodesic distance and
azimuth from its origin), path.geojson with shapely and a pyproj transformer of
its own, the show's location from show.json.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pyproj
import pytest
import shapely
from shapely.geometry import LineString, shape
from shapely.geometry.base import BaseGeometry

from skyquill.coverage.geo import GeoFrame
from skyquill.coverage.regions import swept
from skyquill.errors import InputError
from skyquill.export import EXPORTERS, ExportOptions
from skyquill.export.geojson import SIMPLIFY_M, write_path_geojson
from skyquill.export.px4.global_exporter import DEG_E7, read_px4_global
from skyquill.export.skybrush.skyc_file import read_show_json, read_show_location
from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.limits import VehicleLimits
from skyquill.trajectory import SplineTrajectory, dense_times

FRAME = GeoFrame(8.54, 47.37, 408.0)
LIMITS = VehicleLimits(3.0, 5.0, 20.0).derivative_limits(3)
GEOD = pyproj.Geod(ellps="WGS84")


def _local(to_local: Any, geometry: BaseGeometry) -> BaseGeometry:
    return shapely.transform(geometry, lambda xy: np.column_stack(to_local(xy[:, 0], xy[:, 1])))


def _planned() -> PlannedTrajectory:
    """A 3-D flight over ~80 m at 2 m height, pen down, up, down."""
    rng = np.random.default_rng(7)
    ctrl = np.column_stack([np.linspace(-40, 40, 16), rng.normal(0, 10, 16), np.full(16, 2.0)])
    ctrl[:3], ctrl[-3:] = ctrl[0], ctrl[-1]
    traj = SplineTrajectory(ctrl, 5, 66.0)  # inside LIMITS (at 60 s: 6 % over the speed)
    return PlannedTrajectory(traj, ((0.0, 20.0), (35.0, traj.duration)), LIMITS)


def test_px4_global_setpoints_are_within_a_centimetre_of_the_plan(tmp_path: Path) -> None:
    planned = _planned()
    report = EXPORTERS["px4-global"](
        [("d", planned)], tmp_path / "g.csv", ExportOptions(50.0, origin=FRAME)
    )
    assert report.max_error_m < 1e-2 and report.details["origin"] == FRAME.as_dict()
    rows = np.genfromtxt(report.files[0], delimiter=",", names=True)
    lat, lon = rows["lat_int"] * DEG_E7, rows["lon_int"] * DEG_E7
    azimuth, _, distance = GEOD.inv(
        np.full(lat.size, FRAME.lon_deg), np.full(lat.size, FRAME.lat_deg), lon, lat
    )
    p = planned.trajectory.evaluate(rows["t"])
    got = np.column_stack(
        [distance * np.sin(np.radians(azimuth)), distance * np.cos(np.radians(azimuth))]
    )
    assert np.abs(got - p[:, :2]).max() < 1e-2
    assert np.abs(rows["alt_rel_m"] - p[:, 2]).max() < 1e-6
    assert np.all(rows["lat_int"] == np.round(rows["lat_int"]))  # integers, as MAVLink sends
    back = read_px4_global(report.files[0], FRAME)
    assert np.abs(back.evaluate(np.zeros(1))[0] - p[0]).max() < 1e-2


def test_px4_global_without_an_origin_is_refused(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="origin: got none, expected a plan with a geographic"):
        EXPORTERS["px4-global"]([("d", _planned())], tmp_path / "g.csv", ExportOptions())


def test_skyc_carries_the_show_origin(tmp_path: Path) -> None:
    report = EXPORTERS["skyc"](
        [("d", _planned())], tmp_path / "s.skyc", ExportOptions(origin=FRAME)
    )
    show = read_show_json(report.files[0])
    env = show["environment"]
    assert env["type"] == "outdoor"
    assert env["location"] == {"origin": [473700000, 85400000, 408000], "orientation": 90.0}
    assert read_show_location(show) == (47.37, 8.54, 408.0, 90.0)
    assert report.details["location"]["shift_m"] < 1e-9
    plain = EXPORTERS["skyc"]([("d", _planned())], tmp_path / "p.skyc", ExportOptions())
    assert read_show_json(plain.files[0])["environment"] == {"type": "indoor"}


def test_path_geojson_reads_back_as_the_plan(tmp_path: Path) -> None:
    planned = _planned()
    t = dense_times(planned.trajectory.breakpoints)
    xy = planned.trajectory.evaluate(t)[:, :2]
    region = LineString(xy).buffer(6.0)
    covered = region.intersection(swept(xy, 4.0))
    check = write_path_geojson(tmp_path / "path.geojson", FRAME, planned, covered, region)
    assert check.lines == 3 and check.max_error_m <= SIMPLIFY_M + 1e-4  # + the 1e-9 degree rounding
    assert check.covered_area_error < 1e-6

    data = json.loads((tmp_path / "path.geojson").read_text())
    assert data["type"] == "FeatureCollection" and "crs" not in data  # RFC 7946: lon/lat
    to_local = pyproj.Transformer.from_crs(
        "EPSG:4326",
        f"+proj=aeqd +lat_0={FRAME.lat_deg} +lon_0={FRAME.lon_deg} +datum=WGS84 +units=m",
        always_xy=True,
    ).transform
    paths = [f for f in data["features"] if f["properties"]["kind"] == "path"]
    assert [f["properties"]["pen"] for f in paths] == [True, False, True]
    down = planned.pen(t).astype(bool)
    for f, (a, b) in zip(paths, [(0.0, 20.0), (20.0, 35.0), (35.0, 66.0)], strict=True):
        line = _local(to_local, shape(f["geometry"]))
        assert f["properties"]["start_s"] == pytest.approx(a, abs=0.05)
        assert f["properties"]["end_s"] == pytest.approx(b, abs=0.05)
        inside = (t >= f["properties"]["start_s"]) & (t <= f["properties"]["end_s"])
        gaps = [line.distance(shape({"type": "Point", "coordinates": p})) for p in xy[inside]]
        assert max(gaps) <= SIMPLIFY_M + 1e-4
    assert down.any() and not down.all()
    (area,) = [f for f in data["features"] if f["properties"]["kind"] == "covered"]
    assert area["geometry"]["type"] in ("Polygon", "MultiPolygon")
    assert _local(to_local, shape(area["geometry"])).area == pytest.approx(covered.area, rel=1e-6)
    lon, lat = np.array(shape(area["geometry"]).envelope.exterior.coords).T
    assert np.abs(lon - FRAME.lon_deg).max() < 1e-3 and np.abs(lat - FRAME.lat_deg).max() < 1e-3
