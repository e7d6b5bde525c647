"""Geographic regions: GeoJSON in longitude/latitude (or a named CRS) planned in local metres.

RFC 7946 says GeoJSON positions are WGS84 ``[longitude, latitude]`` in degrees. A
region read that way is projected once, where it enters, to a local metric frame
centred on the field (:class:`GeoFrame`: azimuthal equidistant on the WGS84
ellipsoid, x east, y north, metres, through pyproj/PROJ) and planned there; the
frame's origin travels with the plan (``summary.json``) so the exports that need
it (PX4 global setpoints, Skybrush's show origin, ``path.geojson``) map back.

The CRS of a GeoJSON file is, in order: the ``crs`` argument (``"local"``: the
positions are already local metres, as before; ``"wgs84"``; any CRS pyproj knows,
e.g. ``"EPSG:32633"``), the legacy ``"crs"`` member of the file (GeoJSON 2008,
still written by QGIS and GDAL for projected data; ``{"type": "name",
"properties": {"name": "local"}}`` marks a file in local metres, as skyquill's
examples are), else WGS84. WKT carries no CRS and stays local metres.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
import pyproj
from pyproj.exceptions import CRSError
from shapely.geometry import Polygon

from skyquill.coverage.regions import MAX_COORDINATE_M, load_region
from skyquill.errors import InputError
from skyquill.io.json_read import check_depth, read_json_file
from skyquill.validation import FloatArray, as_float

#: The ``crs`` values that mean "the positions are local metres already".
LOCAL = "local"
#: The ``crs`` value for RFC 7946's own CRS (WGS84 longitude/latitude, degrees).
WGS84 = "wgs84"
#: How the local frame is described in ``summary.json``.
FRAME_DESCRIPTION = "azimuthal equidistant on WGS84 at the origin: x east, y north, z up, m"
_GEOMETRY_KEYS = ("features", "geometry", "geometries")


@dataclass(frozen=True)
class GeoFrame:
    """A local metric frame (x east, y north, z up; m) centred on a geographic origin.

    Azimuthal equidistant on the WGS84 ellipsoid (PROJ ``aeqd``): distances and
    directions from the origin are true, and over a field of a few km the scale
    error elsewhere is below 1e-7 (far below the planner's tolerances), so areas
    in it are square metres on the ground.

    Attributes
    ----------
    lon_deg, lat_deg
        The origin, WGS84 degrees: longitude in [-180, 180], latitude in (-90, 90).
    alt_m
        Altitude of the frame's z = 0 above mean sea level, m, when known
        (None: heights are only relative to the take-off point).
    crs
        The CRS the region was given in (``"EPSG:4326"``, ``"EPSG:32633"``, ...).
    """

    lon_deg: float
    lat_deg: float
    alt_m: float | None = None
    crs: str = "EPSG:4326"
    _cache: dict[str, pyproj.Transformer] = field(
        default_factory=dict, init=False, repr=False, compare=False
    )

    def __post_init__(self) -> None:
        check_lon_lat(self.lon_deg, self.lat_deg, "origin")
        if abs(self.lat_deg) == 90.0:  # x east and y north have no meaning at a pole
            raise InputError(f"origin: got latitude {self.lat_deg:g}, expected one off a pole")
        if self.alt_m is not None:
            as_float("alt_m", self.alt_m)

    @cached_property
    def local_crs(self) -> pyproj.CRS:
        """The local frame as a pyproj CRS."""
        return pyproj.CRS.from_proj4(
            f"+proj=aeqd +lat_0={self.lat_deg!r} +lon_0={self.lon_deg!r} +x_0=0 +y_0=0 "
            "+datum=WGS84 +units=m +no_defs"
        )

    def transformer_from(self, crs: str | pyproj.CRS) -> pyproj.Transformer:
        """A transformer from ``crs`` (x, y order: easting/longitude first) to this frame."""
        key = str(crs)
        if key not in self._cache:
            self._cache[key] = pyproj.Transformer.from_crs(crs, self.local_crs, always_xy=True)
        return self._cache[key]

    def to_local(self, lon: Any, lat: Any) -> tuple[FloatArray, FloatArray]:
        """WGS84 longitude/latitude (deg, any matching shapes) to local x east, y north (m)."""
        x, y = self.transformer_from("EPSG:4326").transform(
            np.asarray(lon, dtype=float), np.asarray(lat, dtype=float), errcheck=True
        )
        return np.asarray(x, dtype=float), np.asarray(y, dtype=float)

    def to_geo(self, x: Any, y: Any) -> tuple[FloatArray, FloatArray]:
        """Local x east, y north (m) to WGS84 longitude, latitude (deg)."""
        lon, lat = self.transformer_from("EPSG:4326").transform(
            np.asarray(x, dtype=float),
            np.asarray(y, dtype=float),
            direction=pyproj.enums.TransformDirection.INVERSE,
            errcheck=True,
        )
        return np.asarray(lon, dtype=float), np.asarray(lat, dtype=float)

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: ``summary.json``'s ``geo`` entry (read back by :meth:`from_dict`)."""
        return {
            "origin": {"lon_deg": self.lon_deg, "lat_deg": self.lat_deg, "alt_m": self.alt_m},
            "crs": self.crs,
            "frame": FRAME_DESCRIPTION,
        }

    @classmethod
    def from_dict(cls, data: Any, name: str = "geo") -> GeoFrame:
        """The frame :meth:`as_dict` wrote; an InputError names what is missing."""
        origin = data.get("origin") if isinstance(data, dict) else None
        if not isinstance(origin, dict):
            raise InputError(
                f"{name}: got {repr(data)[:60]}, expected {{'origin': {{'lon_deg', 'lat_deg', "
                "'alt_m'}, 'crs': ...}"
            )
        alt = origin.get("alt_m")
        crs = data.get("crs", "EPSG:4326")
        return cls(
            as_float(f"{name}.origin.lon_deg", origin.get("lon_deg")),
            as_float(f"{name}.origin.lat_deg", origin.get("lat_deg")),
            None if alt is None else as_float(f"{name}.origin.alt_m", alt),
            crs if isinstance(crs, str) else "EPSG:4326",
        )


@dataclass(frozen=True)
class GeoRegion:
    """A region in local metres and, when it was geographic, the frame it was projected to.

    Attributes
    ----------
    region
        The polygon, local metres (x east, y north when ``frame`` is set).
    frame
        The local frame, or None when the input was local metres.
    """

    region: Polygon
    frame: GeoFrame | None

    def summary(self) -> dict[str, Any]:
        """``summary.json`` fields: the CRS, the origin and the region's area (m^2)."""
        geo = {"crs": LOCAL, "origin": None} if self.frame is None else self.frame.as_dict()
        return {"geo": geo, "region_area_m2": float(self.region.area)}


def check_lon_lat(lon: Any, lat: Any, where: str) -> None:
    """Refuse a longitude outside [-180, 180] or a latitude outside [-90, 90] (degrees)."""
    for label, value, bound in (("longitude", lon, 180.0), ("latitude", lat, 90.0)):
        ok = isinstance(value, int | float) and not isinstance(value, bool)
        if not (ok and math.isfinite(value) and -bound <= value <= bound):
            raise InputError(
                f"{where}: got {label} {value!r:.30}, expected {-bound:g}..{bound:g} degrees "
                "(WGS84 longitude/latitude as RFC 7946 says; a file in metres needs "
                "--crs local or a crs member naming its projection)"
            )


def load_geo_region(
    source: str | Path, crs: str | None = None, alt_m: float | None = None
) -> GeoRegion:
    """Read a region file (see :func:`~skyquill.coverage.regions.load_region`) and project it.

    Parameters
    ----------
    source
        A GeoJSON file, a WKT file or a WKT string.
    crs
        None: what the file says (GeoJSON: its ``crs`` member, else WGS84;
        WKT: local metres). ``"local"``: local metres. ``"wgs84"``, or any CRS
        pyproj accepts (``"EPSG:32633"``): the GeoJSON's positions are in it.
    alt_m
        Altitude of the ground at the origin above mean sea level, m, if known.

    Returns
    -------
    GeoRegion
        The polygon in local metres, and the frame (None for local input).

    Raises
    ------
    InputError
        For an unknown CRS, coordinates out of range for longitude/latitude, a
        CRS asked for WKT, and everything :func:`load_region` refuses.
    """
    chosen = None if crs is None else _parse_crs(crs)
    projector = _Projector(chosen, alt_m)
    region = load_region(source, project=projector)
    if not projector.called and isinstance(chosen, pyproj.CRS):
        raise InputError(
            f"crs: got {crs!r} for a WKT region, expected none or 'local' (WKT carries no CRS "
            "and is read as local metres; convert the field to GeoJSON to give one)"
        )
    return GeoRegion(region, projector.frame)


#: The parsed ``crs`` argument: LOCAL, or a pyproj CRS.
_Chosen = str | pyproj.CRS


def _parse_crs(text: str, name: str = "crs") -> _Chosen:
    """``local``, ``wgs84`` (EPSG:4326 in lon/lat order) or a CRS pyproj accepts."""
    if not isinstance(text, str):
        raise InputError(f"{name}: got {text!r:.40}, expected 'local', 'wgs84' or e.g. EPSG:32633")
    lowered = text.strip().lower()
    if lowered == LOCAL:
        return LOCAL
    if lowered in (WGS84, "crs84"):
        return pyproj.CRS.from_epsg(4326)
    try:
        parsed = pyproj.CRS.from_user_input(text.strip())
    except CRSError:
        raise InputError(
            f"{name}: got {text[:80]!r}, expected 'local', 'wgs84' or a CRS pyproj knows "
            "(e.g. EPSG:32633)"
        ) from None
    if not (parsed.is_geographic or parsed.is_projected):
        raise InputError(
            f"{name}: got {text[:80]!r} ({parsed.type_name}), expected a geographic or a "
            "projected 2-D CRS"
        )
    return parsed


def _file_crs(data: Any, name: str) -> _Chosen:
    """The legacy ``"crs"`` member (``{"type": "name", "properties": {"name": ...}}``) or WGS84."""
    member = data.get("crs") if isinstance(data, dict) else None
    if member is None:
        return pyproj.CRS.from_epsg(4326)
    props = member.get("properties") if isinstance(member, dict) else None
    text = props.get("name") if isinstance(props, dict) else None
    if not (isinstance(member, dict) and member.get("type") == "name" and isinstance(text, str)):
        raise InputError(
            f"{name}: crs: got {repr(member)[:60]}, expected {{'type': 'name', 'properties': "
            "{'name': 'EPSG:...'}} or no crs member (WGS84)"
        )
    return _parse_crs(text, f"{name}: crs.properties.name")


class _Projector:
    """The ``project`` hook of :func:`load_region`: GeoJSON in a CRS to local metres.

    It records the frame it made (``frame``) and whether it was called at all
    (a WKT region never calls it).
    """

    def __init__(self, chosen: _Chosen | None, alt_m: float | None) -> None:
        self.chosen = chosen
        self.alt_m = alt_m
        self.frame: GeoFrame | None = None
        self.called = False

    def __call__(self, data: Any, name: str) -> Any:
        self.called = True
        check_depth(data, name, "a GeoJSON Polygon")
        crs = self.chosen if self.chosen is not None else _file_crs(data, name)
        if isinstance(crs, str):  # LOCAL
            return data
        positions = list(_positions(data, ""))
        if not positions or any(len(p) != 2 for _, p in positions):
            # nothing to project, or a z: load_region names what is wrong
            return data
        xy = np.array([p[:2] for _, p in positions], dtype=float)
        if crs.is_geographic:
            for where, p in positions:
                check_lon_lat(p[0], p[1], f"{name}: {where}")
        self.frame = _frame(crs, xy, self.alt_m)
        x, y = self.frame.transformer_from(crs).transform(xy[:, 0], xy[:, 1], errcheck=True)
        _check_extent(np.hypot(x, y).max(), crs, name)
        local = iter(np.column_stack([x, y]).tolist())
        out = _mapped(copy.deepcopy(data), lambda p: [*next(local), *p[2:]])
        if isinstance(out, dict):
            out.pop("crs", None)
        return out


def _check_extent(reach_m: float, crs: pyproj.CRS, name: str) -> None:
    """Refuse a field reaching beyond :data:`MAX_COORDINATE_M` from its centre.

    Most often a file in local metres read as longitude/latitude degrees (a
    10 m square becomes a 1,100 km one): the message says how to read it as metres.
    """
    if not reach_m <= MAX_COORDINATE_M:
        raise InputError(
            f"{name}: got a field reaching {reach_m / 1e3:,.0f} km from its centre in "
            f"{crs.name}, expected at most {MAX_COORDINATE_M / 1e3:g} km; coordinates in "
            "local metres need --crs local (RFC 7946 GeoJSON is longitude/latitude)"
        )


def _frame(crs: pyproj.CRS, xy: FloatArray, alt_m: float | None) -> GeoFrame:
    """The frame centred on the middle of the positions' bounding box (in ``crs``).

    Centred, the frame's scale error at the field's far corner is smallest.
    """
    centre = 0.5 * (xy.min(axis=0) + xy.max(axis=0))
    to_wgs84 = pyproj.Transformer.from_crs(crs, "EPSG:4326", always_xy=True)
    lon, lat = to_wgs84.transform(centre[0], centre[1], errcheck=True)
    name = crs.to_string()
    return GeoFrame(float(lon), float(lat), alt_m, "EPSG:4326" if crs.equals("EPSG:4326") else name)


def _is_position(node: Any) -> bool:
    return (
        isinstance(node, list)
        and len(node) >= 2
        and all(isinstance(v, int | float) and not isinstance(v, bool) for v in node)
    )


def _walk(node: Any, where: str) -> Iterator[tuple[str, Any, list[Any]]]:
    """Every coordinate array in ``node`` (geometry, Feature, FeatureCollection, collection)."""
    if not isinstance(node, dict):
        return
    if "coordinates" in node:
        yield where, node, node["coordinates"]
    for key in _GEOMETRY_KEYS:
        child = node.get(key)
        if isinstance(child, dict):
            yield from _walk(child, f"{where}.{key}")
        elif isinstance(child, list):
            for i, item in enumerate(child):
                yield from _walk(item, f"{where}.{key}[{i}]")


def _positions(data: Any, where: str) -> Iterator[tuple[str, list[Any]]]:
    """Every position (a list of >= 2 JSON numbers), with its path, in document order."""

    def leaves(node: Any, path: str) -> Iterator[tuple[str, list[Any]]]:
        if _is_position(node):
            yield path, node
        elif isinstance(node, list):
            for i, item in enumerate(node):
                yield from leaves(item, f"{path}[{i}]")

    for owner, _, coords in _walk(data, where):
        # e.g. "features[0].geometry.coordinates[0][3]": where a vertex is in the file
        yield from leaves(coords, f"{owner.lstrip('.')}.coordinates".lstrip("."))


def _mapped(data: Any, fn: Callable[[list[Any]], list[Any]]) -> Any:
    """``data`` with every position replaced by ``fn(position)``, in :func:`_positions` order.

    Anything that is not a position (a string, a nested mistake) is left for
    :func:`load_region` to refuse with its own message.
    """

    def mapped(node: Any) -> Any:
        if _is_position(node):
            return fn(node)
        if isinstance(node, list):
            return [mapped(item) for item in node]
        return node

    for _, owner, coords in _walk(data, ""):
        owner["coordinates"] = mapped(coords)
    return data


def plan_frame(plan: Path) -> GeoFrame | None:
    """The geographic frame a plan directory's ``summary.json`` records (``geo``), or None.

    None for a plan in local metres, a single trajectory file, or a directory
    without a summary: the exports that need an origin then say so.
    """
    summary = plan / "summary.json" if plan.is_dir() else None
    if summary is None or not summary.is_file():
        return None
    data = read_json_file(summary, "skyquill's summary.json")  # a regular file, strictly
    geo = data.get("geo") if isinstance(data, dict) else None
    if not isinstance(geo, dict) or geo.get("origin") is None:
        return None
    return GeoFrame.from_dict(geo, f"{summary.name}: geo")
