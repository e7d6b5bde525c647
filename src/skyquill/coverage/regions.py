"""Regions to cover: GeoJSON Polygon, WKT or a vertex list, in local metric coordinates.

A region is a shapely ``Polygon`` that is valid (no self-intersection), has
positive area and no holes (holes are not supported yet: said, not ignored).
:func:`coverage_fraction` measures how much of it a covering path sweeps with
a disc of the coverage diameter (issue 5's metric).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from shapely.geometry import LineString, Polygon, shape

from skyquill.errors import InputError
from skyquill.validation import FloatArray, as_array, as_float

#: Region coordinates beyond this (m) are refused: a local metric frame, not degrees or mm.
MAX_COORDINATE_M = 1e5


def region_from_vertices(vertices: Any, name: str = "vertices") -> Polygon:
    """A region from its boundary vertices (K, 2), m, in order; closing is optional."""
    pts = as_array(name, vertices, ndim=2, max_abs=MAX_COORDINATE_M)
    if pts.shape[1] != 2 or pts.shape[0] < 3:
        raise InputError(f"{name}: got shape {pts.shape}, expected (K >= 3, 2) boundary vertices")
    return _checked(Polygon(pts), name)


def load_region(source: str | Path) -> Polygon:
    """Read a region: a ``.geojson``/``.json`` file (Polygon, Feature or one-feature
    FeatureCollection), a ``.wkt`` file, or a WKT string.
    """
    text = str(source)
    path = Path(text)
    if text.lstrip().upper().startswith("POLYGON"):
        return _from_wkt(text, "region")
    if not path.is_file():
        raise InputError(f"region: got {text!r}, expected a GeoJSON or WKT file or a WKT string")
    content = path.read_text(encoding="utf-8")
    if path.suffix.lower() == ".wkt":
        return _from_wkt(content, path.name)
    try:
        data = json.loads(content)
    except json.JSONDecodeError as exc:
        raise InputError(f"{path.name}: got invalid JSON ({exc}), expected GeoJSON") from None
    return _from_geojson(data, path.name)


def _from_wkt(text: str, name: str) -> Polygon:
    try:
        geometry = shapely.from_wkt(text.strip())
    except shapely.errors.GEOSException as exc:
        raise InputError(f"{name}: got unreadable WKT ({exc}), expected a POLYGON") from None
    if not isinstance(geometry, Polygon):
        raise InputError(f"{name}: got a {geometry.geom_type}, expected a Polygon")
    return _checked(geometry, name)


def _from_geojson(data: Any, name: str) -> Polygon:
    if isinstance(data, dict) and data.get("type") == "FeatureCollection":
        features = data.get("features") or []
        if len(features) != 1:
            raise InputError(
                f"{name}: got a FeatureCollection of {len(features)} features, expected one"
            )
        data = features[0]
    if isinstance(data, dict) and data.get("type") == "Feature":
        data = data.get("geometry")
    if not isinstance(data, dict) or data.get("type") != "Polygon":
        kind = data.get("type") if isinstance(data, dict) else type(data).__name__
        raise InputError(f"{name}: got GeoJSON of type {kind!r}, expected a Polygon")
    try:
        geometry = shape(data)
    except (ValueError, TypeError, IndexError, shapely.errors.GEOSException) as exc:
        raise InputError(f"{name}: got malformed Polygon coordinates ({exc})") from None
    assert isinstance(geometry, Polygon)
    return _checked(geometry, name)


def _checked(polygon: Polygon, name: str) -> Polygon:
    coords = np.asarray(polygon.exterior.coords)
    if not np.all(np.isfinite(coords)) or (coords.size and np.abs(coords).max() > MAX_COORDINATE_M):
        raise InputError(
            f"{name}: got non-finite or huge coordinates, expected finite metres within "
            f"±{MAX_COORDINATE_M:g}"
        )
    if polygon.interiors:
        raise InputError(
            f"{name}: got a polygon with {len(polygon.interiors)} hole(s), expected none "
            "(holes are not supported yet)"
        )
    if not polygon.is_valid:
        reason = shapely.is_valid_reason(polygon)
        raise InputError(f"{name}: got an invalid polygon ({reason}), expected a simple one")
    if polygon.area <= 0.0:
        raise InputError(f"{name}: got a polygon of zero area, expected a region")
    _check_spikes(coords[:-1, :2], name)
    return shapely.normalize(polygon)


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


#: Longest covering path accepted, m, estimated before any path is made.
#: Planning time grows with it (a 100 m square at a 2 m swath, ~5 km, plans in
#: ~15 s) and the speed LP's grid is capped (``GRID_POINTS`` of
#: :mod:`skyquill.coverage.plan`), so beyond ~10 km it is too coarse to hold
#: the limits (a 200 m square at 2 m, ~20 km, fails after planning); 10 km at
#: 3 m/s is also about an hour of flight, more than one battery.
MAX_PATH_LENGTH_M = 10_000.0


def estimate_path_length(region: Polygon, spacing: float) -> float:
    """About how long a path with lines ``spacing`` m apart covering ``region`` is, m.

    Area over spacing (the sweeps or rings) plus the perimeter (turns, laps):
    an over-estimate of the planned spiral and zigzag lengths (by ~9 % on a
    100 m square at a 2 m swath, ~2x on a 10 m one, where the perimeter term dominates).
    """
    return float(region.area / spacing + region.exterior.length)


def check_width(region: Polygon, width: float, epsilon: float = 1.0) -> float:
    """The coverage diameter ``width`` (m), > 0, small enough to need a path at all
    and large enough for a path of at most :data:`MAX_PATH_LENGTH_M` at a spacing
    of ``epsilon * width`` (checked first, from the area: nothing is built)."""
    w = as_float("width", width, positive=True)
    spacing = epsilon * w
    length = estimate_path_length(region, spacing)
    if length > MAX_PATH_LENGTH_M:
        raise InputError(
            f"width: got {w:g} m on a region of {region.area:.4g} m², i.e. a path of about "
            f"{length / 1e3:.4g} km, expected at most {MAX_PATH_LENGTH_M / 1e3:g} km "
            f"({_what_fits(region, epsilon)})"
        )
    if region.buffer(-0.5 * w).is_empty:
        minx, miny, maxx, maxy = region.bounds
        raise InputError(
            f"width: got {w:g} m, expected less than the region's inner width (bounds "
            f"{maxx - minx:.3g} x {maxy - miny:.3g} m): one disc would already cover it"
        )
    return w


def _what_fits(region: Polygon, epsilon: float) -> str:
    """Which swath would fit the path budget, or that the region must be split."""
    room = MAX_PATH_LENGTH_M - region.exterior.length
    if room <= 0.0:
        return "the perimeter alone is too long: split the region into several missions"
    least = region.area / (epsilon * room)
    return f"a swath of at least {least:.3g} m, or a smaller region: split it into missions"


def coverage_fraction(region: Polygon, path: FloatArray, width: float) -> float:
    """Area of (region ∩ swept discs of diameter ``width`` along ``path`` (N, >=2)) / area."""
    pts = as_array("path", path, ndim=2)
    swept = LineString(pts[:, :2]).buffer(0.5 * as_float("width", width, positive=True))
    return float(region.intersection(swept).area / region.area)
