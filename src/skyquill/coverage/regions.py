"""Regions to cover: GeoJSON (Multi)Polygon, WKT or a vertex list, in local metric coordinates.

A region is a shapely ``Polygon`` or ``MultiPolygon`` (several fields flown in
one mission) that is valid: shells that do not cross themselves, holes
(keep-out zones: trees, buildings, poles) strictly inside their shell and
apart from each other, fields apart from each other, positive area.
:func:`coverage_fraction` measures how much of it a covering path sweeps with
a disc of the coverage diameter (issue 5's metric).
"""

from __future__ import annotations

import itertools
import re
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, TypeAlias

import numpy as np
import shapely
from shapely.geometry import LineString, MultiPolygon, Polygon, shape
from shapely.geometry.base import BaseGeometry

from skyquill.errors import InputError
from skyquill.io.json_read import check_depth, parse_json
from skyquill.io.numbers import NUMBER, is_number
from skyquill.io.source import decode_text, read_bytes
from skyquill.validation import FloatArray, as_array, as_float

#: Region coordinates beyond this (m) are refused: a local metric frame, not degrees or mm.
MAX_COORDINATE_M = 1e5
#: Largest region file read, bytes (checked before reading).
MAX_BYTES = 16 * 2**20
#: Most boundary vertices accepted: a field traced at 1 m over a 10 km boundary.
MAX_VERTICES = 10_000
_WHAT = "a GeoJSON Polygon or MultiPolygon in 2-D local metres"
#: A region: one field (with or without holes) or several fields flown in one mission.
Region: TypeAlias = Polygon | MultiPolygon


def region_from_vertices(
    vertices: Any, name: str = "vertices", *, holes: Sequence[Any] = ()
) -> Polygon:
    """A region from its boundary vertices (K, 2), m, in order; closing is optional.

    ``holes`` are keep-out rings ``(K_i, 2)``, m, each strictly inside the shell.
    """
    rings = [_ring(name, vertices)]
    rings += [_ring(f"holes[{i}]", hole) for i, hole in enumerate(holes)]
    return _checked_polygon(Polygon(rings[0], rings[1:]), name)


def _ring(name: str, vertices: Any) -> FloatArray:
    pts = as_array(name, vertices, ndim=2, max_abs=MAX_COORDINATE_M)
    if pts.shape[1] != 2 or pts.shape[0] < 3:
        raise InputError(
            f"{name}: got shape {pts.shape}, expected (K >= 3, 2) boundary vertices "
            "in 2-D local metres"
        )
    return pts


def fields(region: Region) -> list[Polygon]:
    """The fields of a region: the polygon itself, or a MultiPolygon's parts."""
    return list(region.geoms) if isinstance(region, MultiPolygon) else [region]


def holes(region: Region) -> list[Polygon]:
    """The keep-out zones (holes) of every field, as polygons (m), in field order."""
    return [Polygon(ring) for field in fields(region) for ring in field.interiors]


def has_keepouts(region: Region) -> bool:
    """Whether ``region`` needs the mission planner: holes, or several fields."""
    if isinstance(region, MultiPolygon):
        return True
    return isinstance(region, Polygon) and bool(region.interiors)


def vertex_turns(ring: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """How the closed ``ring`` (K, 2), m, turns at each of its vertices, each (K,):
    ``cross`` and ``dot``, the cross (z) and dot products of the edges into and out of
    the vertex, and ``scale``, the product of their lengths (m²): ``cross / scale`` is
    the sine of the turn (> 0 to the left), ``dot > 0`` goes on forward."""
    into = ring - np.roll(ring, 1, axis=0)
    out = np.roll(ring, -1, axis=0) - ring
    cross = into[:, 0] * out[:, 1] - into[:, 1] * out[:, 0]
    scale = np.linalg.norm(into, axis=1) * np.linalg.norm(out, axis=1)
    return cross, np.einsum("ij,ij->i", into, out), scale


def load_region(source: str | Path, project: Callable[[Any, str], Any] | None = None) -> Region:
    """Read a region: a ``.geojson``/``.json`` file (Polygon, Feature or one-feature
    FeatureCollection), a ``.wkt`` file, or a WKT string.

    ``project(data, file_name)`` maps a parsed GeoJSON document to one in local
    metres (:func:`skyquill.coverage.geo.load_geo_region` passes it); WKT is
    always local metres.

    Coordinates are 2-D local metres: JSON numbers (a string such as ``"1"`` is
    refused, not converted), ``[x, y]`` positions (a third value, a z, is refused,
    not dropped), at most :data:`MAX_VERTICES` of them. A file is UTF-8 (a
    byte-order mark is accepted), at most :data:`MAX_BYTES`.

    Raises
    ------
    InputError
        Naming the file (or ``region``) and what is wrong.
    """
    text = str(source)
    # A file called polygon_field.geojson is a file, not WKT text.
    if _WKT_TEXT.match(text) and not _names_a_file(text):
        return _from_wkt(text, "region")
    path = Path(text)
    if not _names_a_file(text):
        raise InputError(
            f"region: got {_shown(text)!r}, expected an existing GeoJSON or WKT file or a WKT "
            "string"
        )
    raw = read_bytes(path, "a region", max_bytes=MAX_BYTES, name=path.name)
    if path.suffix.lower() == ".wkt":
        return _from_wkt(decode_text(raw, path.name, "a WKT POLYGON"), path.name)
    data = parse_json(raw, path.name, _WHAT)
    return _from_geojson(data if project is None else project(data, path.name), path.name)


#: WKT text given in place of a file: ``POLYGON ((...``, ``MULTIPOLYGON Z EMPTY``.
_WKT_TEXT = re.compile(r"\s*(MULTI)?POLYGON\s*(ZM|Z|M)?\s*(\(|EMPTY)", re.IGNORECASE)


def _names_a_file(text: str) -> bool:
    """Whether ``text`` is the path of something that exists (a name too long is no file)."""
    try:
        return Path(text).exists()
    except (OSError, ValueError):
        return False


#: What WKT text may hold: words (POLYGON, EMPTY, Z), brackets, commas, spaces, numbers.
_WKT_TOKEN = re.compile(rf"\s+|[A-Za-z]+|[(),]|{NUMBER}", re.ASCII)


def check_wkt_numbers(text: str, name: str) -> None:
    """Refuse WKT numbers that are not plain decimals (GEOS reads ``nan``, ``1e999``, ...)."""
    at = 0
    while at < len(text):
        match = _WKT_TOKEN.match(text, at)
        word = match.group(0) if match else ""
        bad = not word or (word.isalpha() and word.upper() not in _WKT_WORDS)
        if not bad and not word.isalpha() and word not in "(),":
            bad = not word.isspace() and not is_number(word)
        if bad:
            got = re.split(r"[\s,()]", text[at:], maxsplit=1)[0][:20] or text[at : at + 1]
            raise InputError(
                f"{name}: got {got!r} at character {at}, expected WKT of plain decimal "
                "numbers (such as 1.5, -2 or 3e-4)"
            )
        at = match.end() if match else at + 1


_WKT_WORDS = {"POLYGON", "MULTIPOLYGON", "EMPTY", "Z", "M", "ZM"}


def _from_wkt(text: str, name: str) -> Region:
    check_wkt_numbers(text, name)
    try:
        geometry = shapely.from_wkt(text.strip())
    except shapely.errors.GEOSException as exc:
        raise InputError(f"{name}: got unreadable WKT ({exc}), expected a POLYGON") from None
    if not isinstance(geometry, Polygon | MultiPolygon):
        raise InputError(f"{name}: got a {geometry.geom_type}, expected a Polygon or MultiPolygon")
    if geometry.has_z or getattr(geometry, "has_m", False):
        raise InputError(
            f"{name}: got a POLYGON with a third coordinate (Z or M), expected 2-D local "
            "metres (x y)"
        )
    count = int(shapely.get_num_coordinates(geometry))
    if count > MAX_VERTICES:
        raise InputError(f"{name}: got {count:,} vertices, expected at most {MAX_VERTICES:,}")
    return _checked(geometry, name)


def _from_geojson(data: Any, name: str) -> Region:
    check_depth(data, name, _WHAT)
    if isinstance(data, dict) and data.get("type") == "FeatureCollection":
        features = data.get("features")
        if not isinstance(features, list) or len(features) != 1:
            got = f"{len(features)} features" if isinstance(features, list) else repr(features)
            raise InputError(f"{name}: got a FeatureCollection of {got[:60]}, expected one feature")
        data = features[0]
    if isinstance(data, dict) and data.get("type") == "Feature":
        data = data.get("geometry")
    if not isinstance(data, dict) or data.get("type") not in ("Polygon", "MultiPolygon"):
        kind = data.get("type") if isinstance(data, dict) else type(data).__name__
        raise InputError(
            f"{name}: got GeoJSON of type {str(kind)[:40]!r}, expected a Polygon or MultiPolygon"
        )
    if data["type"] == "Polygon":
        _check_coordinates(data.get("coordinates"), name)
    else:
        _check_multi_coordinates(data.get("coordinates"), name)
    try:
        geometry = shape(data)
    except (ValueError, TypeError, IndexError, shapely.errors.GEOSException) as exc:
        raise InputError(f"{name}: got malformed {data['type']} coordinates ({exc})") from None
    assert isinstance(geometry, Polygon | MultiPolygon)
    return _checked(geometry, name)


def check_geojson_polygon(data: Any, name: str) -> None:
    """Refuse a GeoJSON Polygon or MultiPolygon whose coordinates break RFC 7946.

    Positions are ``[x, y]`` JSON numbers, rings closed with four or more
    positions; anything else (other geometry types) is left to the caller.
    """
    if isinstance(data, dict) and data.get("type") == "Polygon":
        _check_coordinates(data.get("coordinates"), name)
    elif isinstance(data, dict) and data.get("type") == "MultiPolygon":
        _check_multi_coordinates(data.get("coordinates"), name)


def _check_multi_coordinates(polygons: Any, name: str) -> None:
    """Refuse MultiPolygon coordinates that are not lists of Polygon coordinates."""
    if not isinstance(polygons, list) or not polygons:
        raise InputError(
            f"{name}: coordinates: got {repr(polygons)[:40]}, expected a list of polygons "
            "[[[[x, y], ...], ...], ...]"
        )
    count = 0
    for p, rings in enumerate(polygons):
        _check_coordinates(rings, f"{name}: polygon {p + 1}")
        count += sum(len(ring) for ring in rings)
        if count > MAX_VERTICES:
            raise InputError(
                f"{name}: coordinates: got more than {MAX_VERTICES:,} vertices, expected at most "
                f"{MAX_VERTICES:,}"
            )


def _check_coordinates(rings: Any, name: str) -> None:
    """Refuse Polygon coordinates that are not rings of ``[x, y]`` JSON numbers.

    shapely would convert ``"1"`` to 1.0 and keep a z silently; both are refused here.
    """
    if not isinstance(rings, list) or not rings:
        raise InputError(
            f"{name}: coordinates: got {repr(rings)[:40]}, expected a list of rings "
            "[[[x, y], ...], ...]"
        )
    count = 0
    for r, ring in enumerate(rings):
        if not isinstance(ring, list):
            raise InputError(
                f"{name}: coordinates[{r}]: got {repr(ring)[:40]}, expected a ring [[x, y], ...]"
            )
        count += len(ring)
        if count > MAX_VERTICES:
            raise InputError(
                f"{name}: coordinates: got more than {MAX_VERTICES:,} vertices, expected at most "
                f"{MAX_VERTICES:,}"
            )
        for k, position in enumerate(ring):
            _check_position(position, f"{name}: coordinates[{r}][{k}]")
        _check_closed(ring, f"{name}: coordinates[{r}]")


def _check_closed(ring: list[Any], where: str) -> None:
    """RFC 7946 §3.1.6: a ring has four or more positions, its last identical to its first.

    shapely would close an open ring silently (and GEOS draw a lone triangle of three).
    """
    if len(ring) < 4:
        raise InputError(
            f"{where}: got a ring of {len(ring)} position(s), expected at least 4 with the last "
            "identical to the first (RFC 7946 section 3.1.6)"
        )
    if ring[0] != ring[-1]:
        raise InputError(
            f"{where}: got a ring from {repr(ring[0])[:40]} to {repr(ring[-1])[:40]}, expected "
            "a closed ring whose last position is identical to its first (RFC 7946 section 3.1.6)"
        )


def _check_position(position: Any, where: str) -> None:
    if isinstance(position, list) and len(position) > 2:
        raise InputError(
            f"{where}: got {len(position)} values {repr(position)[:40]}, expected [x, y]: "
            "2-D local metres (a z is not dropped silently; project and flatten first)"
        )
    if not (
        isinstance(position, list)
        and len(position) == 2
        and all(isinstance(v, int | float) and not isinstance(v, bool) for v in position)
    ):
        raise InputError(
            f"{where}: got {repr(position)[:40]}, expected [x, y] of two JSON numbers (m)"
        )


def _checked(region: Region, name: str) -> Region:
    """``region`` normalised, or an InputError naming what is wrong with it."""
    if isinstance(region, MultiPolygon):
        return _checked_fields(region, name)
    return _checked_polygon(region, name)


def _checked_fields(region: MultiPolygon, name: str) -> Region:
    """Each field checked on its own; fields must be apart (an overlap would be flown twice)."""
    parts = [_checked_polygon(p, f"{name}: field {k + 1}") for k, p in enumerate(region.geoms)]
    for a, b in itertools.combinations(range(len(parts)), 2):
        if parts[a].intersects(parts[b]):
            raise InputError(
                f"{name}: got fields {a + 1} and {b + 1} overlapping or touching, expected "
                "separate fields (merge touching fields into one polygon)"
            )
    if len(parts) == 1:
        return parts[0]
    return MultiPolygon(parts)


def _checked_polygon(polygon: Polygon, name: str) -> Polygon:
    coords = shapely.get_coordinates(polygon)
    if not np.all(np.isfinite(coords)) or (coords.size and np.abs(coords).max() > MAX_COORDINATE_M):
        raise InputError(
            f"{name}: got non-finite or huge coordinates, expected finite metres within "
            f"±{MAX_COORDINATE_M:g}"
        )
    _check_rings(polygon, name)
    if not polygon.is_valid:
        reason = shapely.is_valid_reason(polygon)
        raise InputError(f"{name}: got an invalid polygon ({reason}), expected a simple one")
    if polygon.area <= 0.0:
        raise InputError(f"{name}: got a polygon of zero area, expected a region")
    for ring in (polygon.exterior, *polygon.interiors):
        _check_spikes(np.asarray(ring.coords)[:-1, :2], name)
    return shapely.normalize(polygon)


def _check_rings(polygon: Polygon, name: str) -> None:
    """Name the ring at fault: a crossing shell, a hole outside it, holes that meet.

    GEOS's own reason ("Self-intersection at ...") does not say which ring;
    holes are numbered from 1 in input order.
    """
    shell = Polygon(polygon.exterior)
    if not shell.is_valid:
        reason = shapely.is_valid_reason(shell)
        raise InputError(
            f"{name}: got a self-intersecting or degenerate shell ({reason}), expected a "
            "simple boundary"
        )
    inner = [Polygon(ring) for ring in polygon.interiors]
    for k, hole in enumerate(inner, start=1):
        if not hole.is_valid or hole.area <= 0.0:
            reason = shapely.is_valid_reason(hole)
            raise InputError(
                f"{name}: got a self-intersecting or empty hole (hole {k}: {reason}), expected "
                "a simple ring"
            )
        if not shell.contains(hole):
            where = (
                "touching"
                if shell.covers(hole)
                else ("outside" if shell.disjoint(hole) else "crossing")
            )
            raise InputError(
                f"{name}: got a hole {where} the shell (hole {k}), expected holes inside it"
            )
        if hole.boundary.intersects(shell.boundary):
            raise InputError(
                f"{name}: got a hole touching the shell (hole {k}), expected holes strictly "
                "inside it (merge the hole into the boundary)"
            )
    for a, b in itertools.combinations(range(len(inner)), 2):
        if inner[a].intersects(inner[b]):
            raise InputError(
                f"{name}: got holes {a + 1} and {b + 1} overlapping or touching, expected "
                "separate holes (merge them into one)"
            )


#: Smallest interior angle accepted, rad: below it a vertex is a zero-width spike.
MIN_CORNER_RAD = 1e-6


def _check_spikes(ring: FloatArray, name: str) -> None:
    """Refuse zero-width spikes: an edge that doubles back onto the previous one.

    GEOS calls such a ring valid (the spike has no area), but a covering path
    would be sent along a line of no width. Repeated vertices are skipped:
    they do not change the region.
    """
    size = max(1.0, float(np.abs(ring).max()))
    steps = np.diff(np.vstack([ring, ring[:1]]), axis=0)
    keep = np.linalg.norm(steps, axis=1) > 1e-12 * size
    corners, legs = ring[keep], steps[keep]
    unit = legs / np.linalg.norm(legs, axis=1)[:, None]
    incoming = np.roll(unit, 1, axis=0)
    cos_turn = np.einsum("ij,ij->i", incoming, unit)
    spikes = np.flatnonzero(cos_turn < -np.cos(MIN_CORNER_RAD))
    if spikes.size:
        x, y = corners[spikes[0]]
        raise InputError(
            f"{name}: got a zero-width spike at vertex ({x:.6g}, {y:.6g}) (the boundary "
            "doubles back on itself), expected a simple polygon with corners of positive angle"
        )


#: Longest covering path accepted, m, estimated before any path is made: a
#: 10 ha field at a 4 m swath. Planning time grows linearly with it (~0.7 ms
#: per metre: a 316 m square at a 5 m swath, 19.8 km, plans in ~15 s; see
#: ``bench/coverage_scale.py``); 25 km at 3 m/s is also over two hours of
#: flight, several batteries.
MAX_PATH_LENGTH_M = 25_000.0
#: Longest covering path of a region too long to plan as one, m: a 1 km square
#: (:data:`~skyquill.coverage.plan.checks.MAX_REGION_SIZE_M`) at a 5 m swath. Such a region
#: is planned as a mission of pieces within :data:`MAX_PATH_LENGTH_M`, at once
#: (:mod:`skyquill.coverage.cells`): the 100 ha field at a 10 m swath (about 102 km) in
#: 20 s on 2 cores, the bare 1 km square in 16 cells in 7 s.
MAX_MISSION_PATH_M = 200_000.0


def estimate_path_length(region: Region, spacing: float) -> float:
    """About how long a path with lines ``spacing`` m apart covering ``region`` is, m.

    Area over spacing (the sweeps or rings) plus the perimeter (turns, laps):
    an over-estimate of the planned spiral and zigzag lengths (by ~9 % on a
    100 m square at a 2 m swath, ~2x on a 10 m one, where the perimeter term dominates).
    The perimeter counts every ring: holes are flown around.
    """
    return float(region.area / spacing + region.length)


def check_width(
    region: Region, width: float, epsilon: float = 1.0, max_path_m: float = MAX_PATH_LENGTH_M
) -> float:
    """The coverage diameter ``width`` (m), > 0, small enough to need a path at all
    and large enough for a path of at most ``max_path_m`` (m) at a spacing of
    ``epsilon * width`` (checked first, from the area: nothing is built)."""
    w = as_float("width", width, positive=True)
    spacing = epsilon * w
    length = estimate_path_length(region, spacing)
    if length > max_path_m:
        raise InputError(
            f"width: got {w:g} m on a region of {region.area:.4g} m², i.e. a path of about "
            f"{length / 1e3:.4g} km, expected at most {max_path_m / 1e3:g} km "
            f"({what_fits(region, epsilon, max_path_m)})"
        )
    for k, field in enumerate(fields(region)):
        if field.buffer(-0.5 * w).is_empty:
            minx, miny, maxx, maxy = field.bounds
            which = "region" if isinstance(region, Polygon) else f"field {k + 1}"
            raise InputError(
                f"width: got {w:g} m, expected less than the {which}'s inner width (bounds "
                f"{maxx - minx:.3g} x {maxy - miny:.3g} m): one disc would already cover it"
            )
    return w


def what_fits(region: Region, epsilon: float, budget_m: float = MAX_PATH_LENGTH_M) -> str:
    """Which swath would fit a path of ``budget_m`` metres, or that the region must be split."""
    room = budget_m - region.length
    if room <= 0.0:
        return "the perimeter alone is too long: split the region into several missions"
    least = region.area / (epsilon * room)
    return f"a swath of at least {least:.3g} m, or a smaller region: split it into missions"


#: The swept path is simplified to this fraction of the swath before it is buffered.
SIMPLIFY_FRACTION = 1e-4


def coverage_fraction(region: Region, path: FloatArray, width: float) -> float:
    """Area of (region ∩ swept discs of diameter ``width`` along ``path`` (N, >=2)) / area."""
    return float(region.intersection(swept(path, width)).area / region.area)


def swept(path: FloatArray, width: float) -> BaseGeometry:
    """The area swept by a disc of diameter ``width`` (m) along ``path`` (N, >= 2), m.

    The dense path (a point every ~2 cm) is simplified first, to within
    ``SIMPLIFY_FRACTION * width`` of itself: the buffer of the 1 M points of a
    20 km path took 10.5 s, of its 30k-point simplification 1.3 s with the
    same area to 1e-6 (the buffer's own 16-gon discs differ from circles by more).
    """
    pts = as_array("path", path, ndim=2)
    radius = 0.5 * as_float("width", width, positive=True)
    # Douglas-Peucker without topology repair: the buffer does not care whether the
    # simplified line crosses itself (it does anyway), and the repair took 1.2 s on 1 M points.
    line = LineString(pts[:, :2]).simplify(
        SIMPLIFY_FRACTION * 2.0 * radius, preserve_topology=False
    )
    return line.buffer(radius)


def _shown(text: str, limit: int = 200) -> str:
    """``text`` for a message: whole if short, else its start and its end (a file name)."""
    return text if len(text) <= limit else f"{text[: limit // 2]}...{text[-limit // 2 :]}"
