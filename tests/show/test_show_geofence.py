"""Geofences from GeoJSON and WKT, in the show's metres; every bad file is one InputError."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from skyquill.errors import InputError
from skyquill.show import read_geofence

SQUARE = [[-10.0, -10.0], [10.0, -10.0], [10.0, 10.0], [-10.0, 10.0], [-10.0, -10.0]]


def _write(tmp_path: Path, name: str, content: object) -> Path:
    path = tmp_path / name
    path.write_text(content if isinstance(content, str) else json.dumps(content))
    return path


def test_geojson_feature_with_a_ceiling(tmp_path: Path) -> None:
    feature = {
        "type": "Feature",
        "properties": {"ceiling_m": 30},
        "geometry": {"type": "Polygon", "coordinates": [SQUARE]},
    }
    fence = read_geofence(_write(tmp_path, "fence.geojson", feature))
    assert fence.ceiling_m == 30.0
    margin = fence.margin(np.array([[0.0, 0.0], [9.0, 0.0], [12.0, 0.0]]))
    assert margin == pytest.approx([10.0, 1.0, -2.0])


def test_geojson_collection_and_wkt(tmp_path: Path) -> None:
    collection = {
        "type": "FeatureCollection",
        "features": [{"type": "Feature", "geometry": {"type": "Polygon", "coordinates": [SQUARE]}}],
    }
    assert read_geofence(_write(tmp_path, "c.json", collection)).area.area == pytest.approx(400.0)
    wkt = read_geofence(_write(tmp_path, "f.wkt", "POLYGON ((0 0, 4 0, 4 4, 0 4, 0 0))"))
    assert wkt.area.area == pytest.approx(16.0) and wkt.ceiling_m is None


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ({"type": "Point", "coordinates": [0, 0]}, r"got a Point, expected a Polygon"),
        ("POLYGON ((0 0, 1", r"neither GeoJSON nor WKT"),
        ("{not json", r"malformed JSON"),
        ({"type": "FeatureCollection", "features": []}, r"of 0 features, expected exactly one"),
        (
            {"type": "Polygon", "coordinates": [[[0, 0], [2, 2], [2, 0], [0, 2], [0, 0]]]},
            r"got an invalid polygon",
        ),
        (
            {
                "type": "Feature",
                "properties": {"ceiling_m": "high"},
                "geometry": {"type": "Polygon", "coordinates": [SQUARE]},
            },
            r"ceiling_m: got 'high', expected metres",
        ),
        ({"type": "Polygon", "coordinates": "x"}, r"coordinates: got 'x', expected a list"),
        (
            {"type": "Polygon", "coordinates": [[[0, 0], [9, 0], [9, 9], [0, 9]]]},
            r"coordinates\[0\]: got a ring from \[0, 0\] to \[0, 9\], expected a closed ring",
        ),
    ],
)
def test_bad_geofences_are_one_input_error(tmp_path: Path, content: object, message: str) -> None:
    with pytest.raises(InputError, match=r"^--geofence: .*" + message):
        read_geofence(_write(tmp_path, "bad.geojson", content))


def test_a_missing_file(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"--geofence: got '.*nope.json', expected an existing"):
        read_geofence(tmp_path / "nope.json")
