"""Regions: loading, validation with named errors, the coverage metric."""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import MultiPolygon, Polygon

from skyquill.coverage.regions import (
    MAX_VERTICES,
    check_width,
    coverage_fraction,
    fields,
    has_keepouts,
    holes,
    load_region,
    region_from_vertices,
    vertex_turns,
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
        ([[0, 0], [1, 1], [0, 1], [1, 0]], "self-intersecting or degenerate shell"),  # a bow tie
        ([[0, 0], [1, 1], [2, 2]], "self-intersecting or degenerate shell|zero area"),
        ([[0, 0], [1, 0]], r"expected \(K >= 3, 2\)"),
        ([[0, 0], [np.nan, 0], [0, 1]], "NaN"),
        ([[0, 0], [1e9, 0], [0, 1]], "magnitude"),
    ],
)
def test_bad_polygons_are_named(vertices: list[list[float]], message: str) -> None:
    with pytest.raises(InputError, match=message):
        region_from_vertices(vertices)


def test_holes_and_several_fields_are_read() -> None:
    holed = load_region("POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0), (4 4, 6 4, 6 6, 4 6, 4 4))")
    assert isinstance(holed, Polygon)
    assert holed.area == pytest.approx(96.0)
    assert [h.area for h in holes(holed)] == [pytest.approx(4.0)]
    two = load_region(
        "MULTIPOLYGON (((0 0, 10 0, 10 10, 0 10, 0 0)), ((20 0, 30 0, 30 10, 20 10, 20 0)))"
    )
    assert isinstance(two, MultiPolygon)
    assert len(fields(two)) == 2
    assert has_keepouts(two) and has_keepouts(holed)
    assert not has_keepouts(region_from_vertices(SQUARE))


def test_geojson_multipolygon_with_a_hole(tmp_path: Path) -> None:
    square = [[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]]
    hole = [[4, 4], [6, 4], [6, 6], [4, 6], [4, 4]]
    other = [[20, 0], [30, 0], [30, 10], [20, 10], [20, 0]]
    data = {"type": "MultiPolygon", "coordinates": [[square, hole], [other]]}
    (tmp_path / "m.geojson").write_text(json.dumps(data))
    region = load_region(tmp_path / "m.geojson")
    assert region.area == pytest.approx(196.0)
    assert len(holes(region)) == 1


_SHELL = [[0, 0], [10, 0], [10, 10], [0, 10]]
_INSIDE = [[4, 4], [6, 4], [6, 6], [4, 6]]


@pytest.mark.parametrize(
    ("hole_list", "message"),
    [
        (
            [_INSIDE, [[20, 20], [22, 20], [22, 22]]],
            r"got a hole outside the shell \(hole 2\), expected holes inside it",
        ),
        ([[[8, 8], [12, 8], [12, 12], [8, 12]]], r"got a hole crossing the shell \(hole 1\)"),
        ([[[0, 4], [2, 4], [2, 6], [0, 6]]], r"hole touching the shell \(hole 1\)"),
        ([_INSIDE, [[5, 5], [7, 5], [7, 7], [5, 7]]], "holes 1 and 2 overlapping"),
        ([_INSIDE, [[6, 4], [7, 4], [7, 6]]], "holes 1 and 2 overlapping or touching"),
        ([[[4, 4], [6, 6], [6, 4], [4, 6]]], r"self-intersecting or empty hole \(hole 1"),
    ],
)
def test_bad_holes_are_named(hole_list: list[list[list[float]]], message: str) -> None:
    with pytest.raises(InputError, match=message):
        region_from_vertices(_SHELL, holes=hole_list)


def test_overlapping_fields_are_refused() -> None:
    with pytest.raises(InputError, match="fields 1 and 2 overlapping"):
        load_region(
            "MULTIPOLYGON (((0 0, 10 0, 10 10, 0 10, 0 0)), ((5 0, 15 0, 15 10, 5 10, 5 0)))"
        )


def test_a_swath_wider_than_one_field_is_named() -> None:
    two = load_region(
        "MULTIPOLYGON (((0 0, 10 0, 10 10, 0 10, 0 0)), ((20 0, 21 0, 21 9, 20 9, 20 0)))"
    )
    with pytest.raises(InputError, match="width: got 2 m, expected less than the field 2's inner"):
        check_width(two, 2.0)


@pytest.mark.parametrize(
    ("source", "message"),
    [
        ("nope.geojson", "expected an existing GeoJSON or WKT file"),
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


def _geojson(tmp_path: Path, coordinates: object, name: str = "r.geojson") -> Path:
    path = tmp_path / name
    path.write_text(json.dumps({"type": "Polygon", "coordinates": coordinates}), encoding="utf-8")
    return path


def test_string_coordinates_are_refused_not_converted(tmp_path: Path) -> None:
    ring = [["0", "0"], ["10", "0"], ["10", "10"], ["0", "0"]]
    with pytest.raises(
        InputError, match=r"r\.geojson: coordinates\[0\]\[0\]: got \['0', '0'\], expected \[x, y\]"
    ):
        load_region(_geojson(tmp_path, [ring]))


def test_a_z_is_refused_not_dropped(tmp_path: Path) -> None:
    ring = [[0, 0, 5], [10, 0, 5], [10, 10, 5], [0, 0, 5]]
    with pytest.raises(
        InputError,
        match=r"coordinates\[0\]\[0\]: got 3 values .*expected \[x, y\]: 2-D local metres",
    ):
        load_region(_geojson(tmp_path, [ring]))
    with pytest.raises(InputError, match=r"region: got a POLYGON with a third coordinate"):
        load_region("POLYGON Z ((0 0 1, 10 0 1, 10 10 1, 0 0 1))")


def test_deep_nesting_is_named(tmp_path: Path) -> None:
    path = tmp_path / "deep.geojson"
    path.write_text("[" * 100_000 + "]" * 100_000, encoding="utf-8")
    with pytest.raises(InputError, match=r"deep\.geojson: got JSON nested too deeply"):
        load_region(path)
    with pytest.raises(InputError, match=r"deep2\.geojson: got JSON nested more than 64"):
        load_region(_geojson(tmp_path, _nest(70), "deep2.geojson"))


def _nest(depth: int) -> object:
    value: object = []
    for _ in range(depth):
        value = [value]
    return value


@pytest.mark.parametrize(
    ("raw", "match"),
    [
        (b'{"type": "Polygon"}'.decode().encode("utf-16"), "got UTF-16 text"),
        (b'{"type": "Polyg\xf6n"}', r"got bytes that are not UTF-8 \(at offset 15\)"),
        (b"\x00\x01\x02", r"got binary data \(a NUL byte at offset 0\)"),
    ],
)
@pytest.mark.parametrize("suffix", [".geojson", ".wkt"])
def test_text_that_is_not_utf8_is_named(
    tmp_path: Path, raw: bytes, match: str, suffix: str
) -> None:
    path = tmp_path / f"enc{suffix}"
    path.write_bytes(raw)
    with pytest.raises(InputError, match=rf"enc\{suffix}: {match}"):
        load_region(path)


def test_byte_order_mark_is_accepted(tmp_path: Path) -> None:
    path = tmp_path / "bom.geojson"
    body = json.dumps({"type": "Polygon", "coordinates": [[*SQUARE, SQUARE[0]]]})
    path.write_bytes(b"\xef\xbb\xbf" + body.encode())
    assert load_region(path).area == pytest.approx(100.0)


def test_too_many_vertices_are_refused(tmp_path: Path) -> None:
    t = np.linspace(0, 2 * np.pi, MAX_VERTICES + 5)[:-1]
    ring = np.column_stack([10 * np.cos(t), 10 * np.sin(t)]).tolist()
    with pytest.raises(InputError, match=rf"more than {MAX_VERTICES:,} vertices"):
        load_region(_geojson(tmp_path, [[*ring, ring[0]]]))


def test_a_feature_collection_with_features_not_a_list(tmp_path: Path) -> None:
    path = tmp_path / "fc.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": 5}), encoding="utf-8")
    with pytest.raises(InputError, match=r"fc\.geojson: got a FeatureCollection of 5, expected"):
        load_region(path)


_scalar = st.one_of(
    st.floats(),
    st.integers(-(10**20), 10**20),
    st.text(max_size=3),
    st.booleans(),
    st.none(),
)
_position = st.one_of(
    st.lists(st.floats(-20, 20), min_size=2, max_size=2),
    st.lists(_scalar, max_size=4),
    _scalar,
)
_ring = st.one_of(st.lists(_position, max_size=7), _scalar)
_geometry = st.fixed_dictionaries(
    {
        "type": st.sampled_from(["Polygon", "Point", "MultiPolygon", 3]),
        "coordinates": st.one_of(st.lists(_ring, max_size=3), _scalar),
    }
)
_document = st.one_of(
    _geometry,
    st.fixed_dictionaries({"type": st.just("Feature"), "geometry": _geometry}),
    st.fixed_dictionaries(
        {"type": st.just("FeatureCollection"), "features": st.one_of(st.lists(_geometry), _scalar)}
    ),
    _scalar,
)


@settings(max_examples=200, deadline=None)
@given(doc=_document)
def test_random_geojson_gives_a_region_or_an_input_error(doc: object) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "random.geojson"
        path.write_text(json.dumps(doc), encoding="utf-8")
        try:
            region = load_region(path)
        except InputError as exc:
            assert "random.geojson" in str(exc)
            return
    assert region.is_valid and region.area > 0 and not region.has_z


@settings(max_examples=100, deadline=None)
@given(raw=st.binary(max_size=60), suffix=st.sampled_from([".geojson", ".wkt"]))
def test_random_bytes_give_an_input_error(raw: bytes, suffix: str) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"raw{suffix}"
        path.write_bytes(raw)
        with pytest.raises(InputError, match=r"raw\."):
            load_region(path)


def test_vertex_turns_give_each_vertex_its_turn() -> None:
    # Counter-clockwise: a left turn of 90° at each corner, straight on at (5, 0), back
    # along the edge at the spike's tip (12, 5).
    ring = np.array([[0, 0], [5, 0], [10, 0], [10, 5], [12, 5], [10, 5], [10, 10], [0, 10]], float)
    cross, dot, scale = vertex_turns(ring)
    sine = cross / scale
    np.testing.assert_allclose(sine[[0, 2, 6, 7]], 1.0)
    assert sine[1] == 0.0 and dot[1] > 0.0  # straight on
    assert sine[4] == 0.0 and dot[4] < 0.0  # the spike turns back
    np.testing.assert_allclose(scale[1], 25.0)
