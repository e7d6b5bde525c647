"""``skyquill cover`` on a field in longitude/latitude: the origin kept, path.geojson, exports."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import shapely
from shapely.geometry import Polygon, shape
from typer.testing import CliRunner

from skyquill.cli.main import app
from skyquill.coverage.geo import GeoFrame
from skyquill.export.skybrush.skyc_file import read_show_json

#: A 30 m x 20 m field centred on 47.37 N, 8.54 E.
FRAME = GeoFrame(8.54, 47.37)


@pytest.fixture(scope="module")
def plan_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("geo")
    lon, lat = FRAME.to_geo(np.array([-15.0, 15.0, 15.0, -15.0]), np.array([-10.0, -10, 10, 10]))
    ring = np.column_stack([lon, lat]).tolist()
    field = root / "field.geojson"
    field.write_text(json.dumps({"type": "Polygon", "coordinates": [[*ring, ring[0]]]}))
    out = root / "plan"
    args = ["cover", str(field), "--out", str(out), "--width", "4", "--pattern", "zigzag"]
    # a generous budget: the suite runs on a shared, loaded machine
    result = CliRunner().invoke(app, [*args, "--origin-alt", "408", "--time-limit", "600"])
    assert result.exit_code == 0, result.output
    return out


def test_the_summary_records_the_origin_and_the_area_in_square_metres(plan_dir: Path) -> None:
    summary = json.loads((plan_dir / "summary.json").read_text())
    geo = summary["geo"]
    assert geo["crs"] == "EPSG:4326"
    assert geo["origin"]["lon_deg"] == pytest.approx(8.54, abs=1e-7)
    assert geo["origin"]["lat_deg"] == pytest.approx(47.37, abs=1e-7)
    assert geo["origin"]["alt_m"] == 408.0
    assert summary["region_area_m2"] == pytest.approx(600.0, rel=1e-6)
    assert summary["path_geojson"]["max_error_m"] < 0.006
    # Degrees rounded to 1e-9 (0.1 mm) along the covered area's whole boundary, gaps
    # included: ~1e-4 m times a few hundred metres, over 600 m².
    assert summary["path_geojson"]["covered_area_error"] < 1e-5
    data = json.loads((plan_dir / "path.geojson").read_text())
    kinds = [f["properties"]["kind"] for f in data["features"]]
    assert kinds == ["path", "covered", "region"]
    assert data["features"][0]["properties"]["pen"] is True


def test_the_exports_use_the_origin(plan_dir: Path, tmp_path: Path) -> None:
    runner = CliRunner()
    out = tmp_path / "g.csv"
    result = runner.invoke(
        app, ["export", str(plan_dir), "--out", str(out), "--format", "px4-global"]
    )
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "g.csv.summary.json").read_text())
    assert report["max_error_m"] < 0.01
    show = tmp_path / "s.skyc"
    result = runner.invoke(app, ["export", str(plan_dir), "--out", str(show), "--format", "skyc"])
    assert result.exit_code == 0, result.output
    location = read_show_json(show)["environment"]["location"]
    assert location["origin"] == [473700000, 85400000, 408000] and location["orientation"] == 90


def test_px4_global_of_a_plan_in_metres_is_refused(tmp_path: Path) -> None:
    examples = Path(__file__).parents[2] / "examples" / "coverage"
    plan = tmp_path / "p"
    args = ["cover", str(examples / "square_10m.geojson"), "--out", str(plan), "--width", "4"]
    runner = CliRunner()
    assert runner.invoke(app, [*args, "--pattern", "zigzag"]).exit_code == 0
    assert json.loads((plan / "summary.json").read_text())["geo"] == {
        "crs": "local",
        "origin": None,
    }
    assert not (plan / "path.geojson").exists()
    result = runner.invoke(
        app, ["export", str(plan), "--out", str(tmp_path / "g.csv"), "--format", "px4-global"]
    )
    assert result.exit_code == 2 and "origin: got none" in result.output


def test_out_of_range_coordinates_are_one_line_and_status_2(tmp_path: Path) -> None:
    field = tmp_path / "bad.geojson"
    ring = [[8.54, 47.37], [8.55, 47.37], [8.55, 91.0], [8.54, 47.37]]
    field.write_text(json.dumps({"type": "Polygon", "coordinates": [ring]}))
    result = CliRunner().invoke(app, ["cover", str(field), "--out", str(tmp_path / "o")])
    assert result.exit_code == 2
    assert "coordinates[0][2]: got latitude 91.0, expected -90..90" in result.output
    result = CliRunner().invoke(
        app, ["cover", str(field), "--out", str(tmp_path / "o"), "--crs", "EPSG:0"]
    )
    assert result.exit_code == 2 and "crs: got 'EPSG:0'" in result.output


def test_the_covered_area_of_a_field_with_holes_is_what_the_spray_sweeps(tmp_path: Path) -> None:
    # The mission's spray is off on its transits and within half a swath of the holes: the
    # GeoJSON's covered area is the sprayed one, as coverage_fraction counts it (it was the
    # whole path's swath, transits included, until session 41).
    local = Polygon(
        [(-12.0, -8.0), (12.0, -8.0), (12.0, 8.0), (-12.0, 8.0)],
        [
            [(-7.0, -3.0), (-4.0, -3.0), (-4.0, 1.0), (-7.0, 1.0)],
            [(3.0, -1.0), (7.0, -1.0), (5.0, 3.0)],
        ],
    )

    def lonlat(ring: object) -> list[list[float]]:
        lon, lat = FRAME.to_geo(*np.asarray(ring).T)
        return [[float(a), float(b)] for a, b in zip(lon, lat, strict=True)]

    rings = [lonlat(local.exterior.coords)] + [lonlat(h.coords) for h in local.interiors]
    field = tmp_path / "field.geojson"
    field.write_text(json.dumps({"type": "Polygon", "coordinates": rings}))
    out = tmp_path / "plan"
    args = ["cover", str(field), "--out", str(out), "--width", "2", "--time-limit", "600"]
    result = CliRunner().invoke(app, [*args, "--no-pictures"])
    assert result.exit_code == 0, result.output
    summary = json.loads((out / "summary.json").read_text())
    data = json.loads((out / "path.geojson").read_text())
    covered_ll = shape(
        next(f for f in data["features"] if f["properties"]["kind"] == "covered")["geometry"]
    )
    origin = summary["geo"]["origin"]
    frame = GeoFrame(origin["lon_deg"], origin["lat_deg"])
    covered = shapely.transform(
        covered_ll, lambda lonlat: np.column_stack(frame.to_local(lonlat[:, 0], lonlat[:, 1]))
    )
    assert covered.area / local.area == pytest.approx(summary["coverage_fraction"], abs=1e-4)
