"""Regions: loading, validation with named errors, the coverage metric."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.coverage.regions import (
    check_width,
    coverage_fraction,
    load_region,
    region_from_vertices,
)
from skyquill.errors import InputError

SQUARE = [[0, 0], [10, 0], [10, 10], [0, 10]]


def test_geojson_feature_wkt_and_vertices_agree(tmp_path: Path) -> None:
    polygon = {"type": "Polygon", "coordinates": [[*SQUARE, SQUARE[0]]]}
    (tmp_path / "a.geojson").write_text(json.dumps(polygon))
    (tmp_path / "b.json").write_text(
        json.dumps(
            {
                "type": "FeatureCollection",
                "features": [{"type": "Feature", "geometry": polygon, "properties": {}}],
            }
        )
    )
    (tmp_path / "c.wkt").write_text("POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0))")
    regions = [load_region(tmp_path / n) for n in ("a.geojson", "b.json", "c.wkt")]
    regions += [
        load_region("POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0))"),
        region_from_vertices(SQUARE),
    ]
    assert all(r.equals(regions[0]) for r in regions)
    assert regions[0].area == pytest.approx(100.0)


@pytest.mark.parametrize(
    ("vertices", "message"),
    [
        ([[0, 0], [1, 1], [0, 1], [1, 0]], "invalid polygon"),  # a bow tie
        ([[0, 0], [1, 1], [2, 2]], "invalid polygon|zero area"),
        ([[0, 0], [1, 0]], r"expected \(K >= 3, 2\)"),
        ([[0, 0], [np.nan, 0], [0, 1]], "NaN"),
        ([[0, 0], [1e9, 0], [0, 1]], "magnitude"),
    ],
)
def test_bad_polygons_are_named(vertices: list[list[float]], message: str) -> None:
    with pytest.raises(InputError, match=message):
        region_from_vertices(vertices)


def test_holes_are_refused_not_ignored() -> None:
    with pytest.raises(InputError, match=r"hole\(s\), expected none \(holes are not supported"):
        load_region("POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0), (4 4, 6 4, 6 6, 4 6, 4 4))")


@pytest.mark.parametrize(
    ("source", "message"),
    [
        ("nope.geojson", "expected a GeoJSON or WKT file"),
        ("POLYGON ((0 0, 1 0", "unreadable WKT"),
    ],
)
def test_bad_sources(source: str, message: str) -> None:
    with pytest.raises(InputError, match=message):
        load_region(source)


def test_wrong_geojson_type(tmp_path: Path) -> None:
    (tmp_path / "p.geojson").write_text(json.dumps({"type": "Point", "coordinates": [0, 0]}))
    with pytest.raises(InputError, match="got GeoJSON of type 'Point', expected a Polygon"):
        load_region(tmp_path / "p.geojson")


def test_width_checks() -> None:
    region = region_from_vertices(SQUARE)
    assert check_width(region, 2.0) == 2.0
    with pytest.raises(InputError, match="width: got 0, expected a number > 0"):
        check_width(region, 0.0)
    with pytest.raises(InputError, match="width: got 30 m, expected less than"):
        check_width(region, 30.0)


def test_coverage_fraction_of_a_boustrophedon() -> None:
    region = region_from_vertices(SQUARE)
    rows = [
        [x, y]
        for i, y in enumerate(np.arange(1.0, 10.0, 2.0))
        for x in ((0.0, 10.0) if i % 2 == 0 else (10.0, 0.0))
    ]
    assert coverage_fraction(region, np.array(rows), 2.0) > 0.97
    assert coverage_fraction(region, np.array(rows[:2]), 2.0) == pytest.approx(0.2, abs=0.01)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(-50, 50), st.floats(-50, 50)), min_size=0, max_size=8))
def test_random_polygons_give_a_region_or_an_input_error(points: list[tuple[float, float]]) -> None:
    try:
        region = region_from_vertices(points if points else np.zeros((0, 2)))
    except InputError as exc:
        assert str(exc)
        return
    assert region.is_valid and region.area > 0


def test_a_zero_width_spike_is_refused() -> None:
    # GEOS calls this ring valid: the spike (2, 0) - (4, 0) has no area.
    spike = [[4, 0], [2, 0], [4, 1e-300], [1, 3], [-2, 3], [1, -4]]
    with pytest.raises(InputError, match="zero-width spike"):
        region_from_vertices(spike)
    # Repeated vertices are no spike.
    region_from_vertices([[0, 0], [5, 0], [5, 0], [5, 5], [0, 5]])
