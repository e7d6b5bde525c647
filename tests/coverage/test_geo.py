"""Geographic regions: GeoJSON in WGS84 lon/lat or a named CRS, projected to local metres."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pyproj
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import Polygon

from skyquill.coverage.geo import GeoFrame, load_geo_region, plan_frame
from skyquill.coverage.plan import CoverageOptions, plan_coverage
from skyquill.errors import InputError

#: The test field: 100 m x 60 m centred on a point in Zurich.
LON0, LAT0 = 8.54, 47.37
FIELD_M = np.array([[-50.0, -30.0], [50.0, -30.0], [50.0, 30.0], [-50.0, 30.0]])
GEOD = pyproj.Geod(ellps="WGS84")


def _lonlat(frame: GeoFrame, xy: np.ndarray) -> list[list[float]]:
    lon, lat = frame.to_geo(xy[:, 0], xy[:, 1])
    ring = np.column_stack([lon, lat]).tolist()
    return [*ring, ring[0]]


def _write(path: Path, ring: list[list[float]], crs: str | None = None) -> Path:
    data: dict[str, Any] = {"type": "Polygon", "coordinates": [ring]}
    if crs is not None:
        data["crs"] = {"type": "name", "properties": {"name": crs}}
    path.write_text(json.dumps(data))
    return path


def _field(tmp_path: Path) -> Path:
    return _write(tmp_path / "field.geojson", _lonlat(GeoFrame(LON0, LAT0), FIELD_M))


def test_round_trip_is_under_a_millimetre_over_a_km() -> None:
    frame = GeoFrame(LON0, LAT0)
    xy = np.random.default_rng(3).uniform(-1000.0, 1000.0, size=(500, 2))
    back = np.column_stack(frame.to_local(*frame.to_geo(xy[:, 0], xy[:, 1])))
    assert np.abs(back - xy).max() < 1e-3


def test_the_projected_area_is_the_geodesic_area(tmp_path: Path) -> None:
    for size in (1.0, 10.0):  # the 100 m x 60 m field, and 1 km x 600 m
        ring = _lonlat(GeoFrame(LON0, LAT0), size * FIELD_M)
        geo = load_geo_region(_write(tmp_path / "f.geojson", ring))
        lon, lat = np.array(ring).T
        area, _ = GEOD.polygon_area_perimeter(lon, lat)
        assert geo.region.area == pytest.approx(abs(area), rel=1e-3)
        assert geo.region.area == pytest.approx(6000.0 * size**2, rel=1e-3)


def test_a_lonlat_field_plans_as_the_same_field_in_metres(tmp_path: Path) -> None:
    geo = load_geo_region(_field(tmp_path))
    assert geo.frame is not None
    assert (geo.frame.lon_deg, geo.frame.lat_deg) == pytest.approx((LON0, LAT0), abs=1e-7)
    local = Polygon(FIELD_M)
    assert geo.region.hausdorff_distance(local) < 1e-3
    options = CoverageOptions(width=10.0, pattern="zigzag")
    geo_plan, local_plan = plan_coverage(geo.region, options), plan_coverage(local, options)
    assert geo_plan.duration == pytest.approx(local_plan.duration, abs=1e-3)
    t = np.linspace(0.0, min(geo_plan.duration, local_plan.duration), 2000)
    gap = np.linalg.norm(
        geo_plan.trajectory.evaluate(t) - local_plan.trajectory.evaluate(t), axis=1
    )
    assert gap.max() < 1e-3
    assert geo_plan.coverage == pytest.approx(local_plan.coverage, abs=1e-6)


def test_a_utm_file_names_its_crs(tmp_path: Path) -> None:
    ring = _lonlat(GeoFrame(LON0, LAT0), FIELD_M)
    to_utm = pyproj.Transformer.from_crs("EPSG:4326", "EPSG:32632", always_xy=True)
    utm = [list(to_utm.transform(lon, lat)) for lon, lat in ring]
    named = load_geo_region(_write(tmp_path / "utm.geojson", utm, "urn:ogc:def:crs:EPSG::32632"))
    asked = load_geo_region(_write(tmp_path / "bare.geojson", utm), crs="EPSG:32632")
    for geo in (named, asked):
        assert geo.frame is not None and geo.frame.crs == "EPSG:32632"
        assert geo.region.hausdorff_distance(Polygon(FIELD_M)) < 1e-3
        assert geo.summary()["geo"]["crs"] == "EPSG:32632"


@pytest.mark.parametrize(
    ("corner", "message"),
    [
        ([200.0, 47.0], r"coordinates\[0\]\[1\]: got longitude 200.0, expected -180..180"),
        ([8.5, -95.0], r"coordinates\[0\]\[1\]: got latitude -95.0, expected -90..90"),
    ],
)
def test_coordinates_out_of_range_are_refused(
    tmp_path: Path, corner: list[float], message: str
) -> None:
    ring = [[8.54, 47.37], corner, [8.55, 47.38], [8.54, 47.37]]
    with pytest.raises(InputError, match=message):
        load_geo_region(_write(tmp_path / "bad.geojson", ring))
    geometry = {"type": "Polygon", "coordinates": [ring]}
    feature = {"type": "Feature", "properties": {}, "geometry": geometry}
    (tmp_path / "f.geojson").write_text(
        json.dumps({"type": "FeatureCollection", "features": [feature]})
    )
    with pytest.raises(InputError, match=r"features\[0\]\.geometry\." + message):
        load_geo_region(tmp_path / "f.geojson")


def test_metres_read_as_degrees_say_how_to_read_metres(tmp_path: Path) -> None:
    ring = [[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]]
    path = _write(tmp_path / "m.geojson", ring)
    with pytest.raises(InputError, match=r"m\.geojson: got a field reaching .* --crs local"):
        load_geo_region(path)
    for geo in (load_geo_region(path, crs="local"), load_geo_region(_write(path, ring, "local"))):
        assert geo.frame is None and geo.region.area == pytest.approx(100.0)
        assert geo.summary()["geo"] == {"crs": "local", "origin": None}


def test_unknown_crs_and_wkt_with_a_crs_are_refused(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="crs: got 'EPSG:999999', expected 'local', 'wgs84'"):
        load_geo_region(_field(tmp_path), crs="EPSG:999999")
    with pytest.raises(InputError, match=r"crs.properties.name: got 'nowhere'"):
        load_geo_region(_write(tmp_path / "n.geojson", [[0, 0], [1, 0], [0, 1], [0, 0]], "nowhere"))
    wkt = "POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0))"
    assert load_geo_region(wkt).frame is None and load_geo_region(wkt, "local").frame is None
    with pytest.raises(InputError, match="crs: got 'wgs84' for a WKT region"):
        load_geo_region(wkt, crs="wgs84")


def test_the_frame_is_recorded_and_read_back(tmp_path: Path) -> None:
    geo = load_geo_region(_field(tmp_path), alt_m=408.5)
    assert geo.frame is not None and geo.frame.alt_m == 408.5
    (tmp_path / "summary.json").write_text(json.dumps(geo.summary()))
    back = plan_frame(tmp_path)
    assert back is not None and back.as_dict() == geo.frame.as_dict()
    assert plan_frame(tmp_path / "summary.json") is None  # a file, not a plan directory
    with pytest.raises(InputError, match=r"origin: got latitude 95\.0, expected -90\.\.90"):
        GeoFrame(8.0, 95.0)


@settings(max_examples=40, deadline=None)
@given(
    lon=st.floats(-179.0, 179.0),
    lat=st.floats(-80.0, 80.0),
    size=st.floats(5.0, 1000.0),
    seed=st.integers(0, 2**16),
)
def test_random_fields_round_trip_and_keep_their_geodesic_area(
    lon: float, lat: float, size: float, seed: int
) -> None:
    frame = GeoFrame(lon, lat)
    angles = np.sort(np.random.default_rng(seed).uniform(0.0, 2 * np.pi, 7))
    xy = 0.5 * size * np.column_stack([np.cos(angles), np.sin(angles)])
    glon, glat = frame.to_geo(xy[:, 0], xy[:, 1])
    back = np.column_stack(frame.to_local(glon, glat))
    assert np.abs(back - xy).max() < 1e-3
    area, _ = GEOD.polygon_area_perimeter(glon, glat)
    if Polygon(xy).area > 1.0:
        assert Polygon(xy).area == pytest.approx(abs(area), rel=1e-3)
