"""A geofence: a polygon in the show's local metres, and an optional altitude ceiling.

Read from GeoJSON (a ``Polygon`` or ``MultiPolygon`` geometry, a ``Feature``
holding one, or a ``FeatureCollection`` of exactly one; a ``ceiling_m`` in the
feature's ``properties`` is the ceiling) or from WKT text (``POLYGON ((x y,
...))``). Coordinates are x, y in metres in the show's frame (the frame of the
trajectories), not longitude and latitude. Parsing and geometry are shapely's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from shapely.geometry import MultiPolygon, Polygon, shape

from skyquill.coverage.regions import check_geojson_polygon, check_wkt_numbers
from skyquill.errors import InputError
from skyquill.io.json_read import parse_json
from skyquill.io.source import read_text
from skyquill.validation import FloatArray

#: Largest geofence file read, bytes.
MAX_BYTES = 16 * 2**20


@dataclass(frozen=True)
class Geofence:
    """Where the drones may fly.

    Attributes
    ----------
    area
        The allowed area, x and y in m (show frame).
    ceiling_m
        Highest allowed altitude, m, or ``None``.
    """

    area: Polygon | MultiPolygon
    ceiling_m: float | None = None

    def margin(self, xy: FloatArray) -> FloatArray:
        """Signed distance to the fence of points ``xy`` (N, 2), m: positive inside."""
        x, y = xy[:, 0], xy[:, 1]
        distance = shapely.distance(self.area.boundary, shapely.points(x, y))
        inside = shapely.contains_xy(self.area, x, y)
        return np.asarray(np.where(inside, distance, -distance), dtype=float)


def read_geofence(path: Path, name: str = "--geofence") -> Geofence:
    """The geofence in ``path`` (GeoJSON, or WKT text); see the module docstring.

    Raises
    ------
    InputError
        Naming ``name`` (the option or key that gave the file): a missing or
        unreadable file, malformed GeoJSON or WKT, a geometry that is not one valid,
        non-empty polygon (or multipolygon), a ceiling that is not a finite number.
    """
    if not path.exists():
        raise InputError(f"{name}: got {str(path)!r}, expected an existing GeoJSON or WKT file")
    text = read_text(path, "a GeoJSON or WKT polygon", max_bytes=MAX_BYTES, name=name)
    if text.lstrip().startswith("{"):
        area, ceiling = _from_geojson(parse_json(text.encode(), name, "a GeoJSON polygon"), name)
    else:
        check_wkt_numbers(text, name)
        area, ceiling = _from_wkt(text, name), None
    return Geofence(_checked(area, name), ceiling)


def _from_geojson(data: Any, name: str) -> tuple[Any, float | None]:
    if not isinstance(data, dict):
        raise InputError(f"{name}: got {type(data).__name__}, expected a GeoJSON object")
    if data.get("type") == "FeatureCollection":
        features = data.get("features")
        if not isinstance(features, list) or len(features) != 1:
            count = len(features) if isinstance(features, list) else features
            raise InputError(
                f"{name}: got a FeatureCollection of {count!r} features, expected exactly one"
            )
        data = features[0]
    ceiling = None
    if isinstance(data, dict) and data.get("type") == "Feature":
        properties = data.get("properties") or {}
        ceiling = _ceiling(
            properties.get("ceiling_m") if isinstance(properties, dict) else None, name
        )
        data = data.get("geometry")
    check_geojson_polygon(data, name)
    try:
        return shape(data), ceiling
    except (AttributeError, KeyError, TypeError, ValueError, IndexError) as exc:
        raise InputError(
            f"{name}: got a geometry shapely cannot read ({exc}), expected a GeoJSON Polygon"
        ) from None


def _ceiling(value: Any, name: str) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise InputError(f"{name}: properties.ceiling_m: got {value!r:.40}, expected metres")
    return float(value)


def _from_wkt(text: str, name: str) -> Any:
    try:
        return shapely.from_wkt(text.strip())
    except shapely.errors.ShapelyError as exc:
        raise InputError(
            f"{name}: got text that is neither GeoJSON nor WKT ({exc}), expected a polygon"
        ) from None


def _checked(area: Any, name: str) -> Polygon | MultiPolygon:
    if not isinstance(area, Polygon | MultiPolygon):
        raise InputError(
            f"{name}: got a {getattr(area, 'geom_type', type(area).__name__)}, expected a "
            "Polygon or MultiPolygon"
        )
    if not area.is_empty and not area.is_valid:
        reason = shapely.is_valid_reason(area)
        raise InputError(f"{name}: got an invalid polygon ({reason}), expected a valid one")
    if area.is_empty or area.area <= 0.0:
        raise InputError(f"{name}: got an empty polygon, expected one enclosing an area")
    return area
