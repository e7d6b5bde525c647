"""``path.geojson``: the flown path and the covered area in WGS84 longitude/latitude, for a GIS.

An RFC 7946 FeatureCollection (no ``crs`` member: lon/lat degrees is the
standard's only CRS) of

* LineString features of the flown path, one per run of equal pen state
  (``"pen": true`` where the spray is on), with their times and lengths;
* the covered area (the swath swept by the pen-down path within the field) as
  a Polygon or MultiPolygon feature, ``"kind": "covered"``, with its area in m^2;
* the field itself, ``"kind": "region"``.

Lines are simplified in the local frame to :data:`SIMPLIFY_M` before they are
mapped to lon/lat (a 5 km path at 50 Hz is 85k points; straight lanes need two).
:func:`check_path_geojson` reads the file back with shapely and pyproj and
measures it against the plan.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from shapely.geometry import LineString, MultiPolygon, mapping, shape
from shapely.geometry.base import BaseGeometry

from skyquill.coverage.geo import GeoFrame
from skyquill.errors import InputError
from skyquill.io.atomic import write_json
from skyquill.io.json_read import parse_json
from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.trajectory import dense_times
from skyquill.validation import FloatArray

#: Largest distance of a written line from the flown path, m (the simplification).
SIMPLIFY_M = 0.005
#: Decimal places of the written degrees: 1e-9 deg is 0.1 mm on the ground.
DEGREE_DIGITS = 9


@dataclass(frozen=True)
class PathGeoJsonCheck:
    """``path.geojson`` read back and measured against the plan.

    Attributes
    ----------
    lines
        LineString features read back (pen runs).
    max_error_m
        Largest distance from a dense sample of the planned path (horizontal)
        to the read-back line of the same pen state, m.
    covered_area_m2
        Area of the read-back covered feature, projected back to the local frame, m^2.
    covered_area_error
        Its relative difference from the covered area of the plan.
    """

    lines: int
    max_error_m: float
    covered_area_m2: float
    covered_area_error: float

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready, for ``summary.json``."""
        return {
            "lines": self.lines,
            "max_error_m": self.max_error_m,
            "covered_area_m2": self.covered_area_m2,
            "covered_area_error": self.covered_area_error,
        }


def path_geojson(
    frame: GeoFrame, planned: PlannedTrajectory, covered: BaseGeometry, region: BaseGeometry
) -> dict[str, Any]:
    """The FeatureCollection of the module docstring.

    Parameters
    ----------
    frame
        The local frame the plan is in.
    planned
        The flight (x east, y north, z up; m) and its pen windows (s).
    covered, region
        The covered area and the field, local metres.
    """
    t, xy, pen = _dense(planned)
    features = [
        _feature(
            _to_geo(frame, LineString(xy[a:b]).simplify(SIMPLIFY_M)),
            {
                "kind": "path",
                "pen": bool(pen[a]),
                "start_s": float(t[a]),
                "end_s": float(t[b - 1]),
                "length_m": float(LineString(xy[a:b]).length),
            },
        )
        for a, b in _runs(pen)
    ]
    covered = _polygonal(covered)
    features.append(_feature(_to_geo(frame, covered), _area("covered", covered)))
    features.append(_feature(_to_geo(frame, region), _area("region", region)))
    return {"type": "FeatureCollection", "features": features}


def write_path_geojson(
    path: Path,
    frame: GeoFrame,
    planned: PlannedTrajectory,
    covered: BaseGeometry,
    region: BaseGeometry,
) -> PathGeoJsonCheck:
    """Write :func:`path_geojson` to ``path`` (atomically), read it back, check it."""
    write_json(path, path_geojson(frame, planned, covered, region))
    return check_path_geojson(path, frame, planned, covered)


def read_path_geojson(
    path: Path, frame: GeoFrame
) -> tuple[list[tuple[bool, LineString]], BaseGeometry]:
    """The pen runs (pen state, line) and the covered area of a ``path.geojson``, local metres.

    Reads with shapely and maps lon/lat back through pyproj (``frame``).
    """
    data = parse_json(path.read_bytes(), path.name, "a skyquill path.geojson")
    features = data.get("features") if isinstance(data, dict) else None
    if not isinstance(features, list):
        raise InputError(f"{path.name}: got no features list, expected a FeatureCollection")
    lines: list[tuple[bool, LineString]] = []
    covered: BaseGeometry | None = None
    for f in features:
        props, geometry = f.get("properties", {}), _to_local(frame, shape(f["geometry"]))
        if props.get("kind") == "path":
            assert isinstance(geometry, LineString)
            lines.append((bool(props["pen"]), geometry))
        elif props.get("kind") == "covered":
            covered = geometry
    if covered is None:
        raise InputError(f"{path.name}: got no covered feature, expected one")
    return lines, covered


def check_path_geojson(
    path: Path, frame: GeoFrame, planned: PlannedTrajectory, covered: BaseGeometry
) -> PathGeoJsonCheck:
    """Read ``path`` back (:func:`read_path_geojson`) and measure it against the plan."""
    lines, back_covered = read_path_geojson(path, frame)
    _, xy, pen = _dense(planned)
    error = 0.0
    for state in (False, True):
        mine = xy[pen == state]
        if mine.size:
            union = shapely.union_all([line for p, line in lines if p == state])
            error = max(error, float(shapely.distance(shapely.points(mine), union).max()))
    area = float(back_covered.area)
    return PathGeoJsonCheck(
        len(lines), error, area, abs(area - covered.area) / max(covered.area, 1e-12)
    )


def _dense(planned: PlannedTrajectory) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Dense times (s), horizontal positions (N, 2) (m) and pen states (N,) of the plan."""
    traj = planned.trajectory
    # the last breakpoint may pass the duration by a rounding, and leave the last pen window
    t = np.minimum(dense_times(traj.breakpoints), traj.duration)
    pen = planned.pen(t).astype(bool) if planned.pen_windows_s else np.zeros(t.size, dtype=bool)
    return t, traj.evaluate(t)[:, :2], pen


def _runs(pen: FloatArray) -> list[tuple[int, int]]:
    """``(start, stop)`` index ranges of equal pen state; each run keeps its neighbour's
    first sample, so consecutive lines meet."""
    edges = np.flatnonzero(np.diff(pen.astype(int))) + 1
    starts = np.concatenate([[0], edges])
    stops = np.concatenate([edges + 1, [pen.size]])
    # a last run of one sample borrows its predecessor's last one: a line needs two points
    return [(int(min(a, b - 2)), int(b)) for a, b in zip(starts, stops, strict=True)]


def _polygonal(geometry: BaseGeometry) -> BaseGeometry:
    """A Polygon or MultiPolygon: an intersection can also hold lines and points of no area."""
    if geometry.geom_type in ("Polygon", "MultiPolygon"):
        return geometry
    parts = [p for p in shapely.get_parts(geometry) if p.geom_type == "Polygon"]
    return MultiPolygon(parts)


def _area(kind: str, geometry: BaseGeometry) -> dict[str, Any]:
    return {"kind": kind, "area_m2": float(geometry.area)}


def _feature(geometry: BaseGeometry, properties: dict[str, Any]) -> dict[str, Any]:
    return {"type": "Feature", "geometry": mapping(geometry), "properties": properties}


def _to_geo(frame: GeoFrame, geometry: BaseGeometry) -> BaseGeometry:
    """Local metres to lon/lat degrees, rounded to :data:`DEGREE_DIGITS`."""

    def fn(xy: FloatArray) -> FloatArray:
        lon, lat = frame.to_geo(xy[:, 0], xy[:, 1])
        return np.asarray(np.round(np.column_stack([lon, lat]), DEGREE_DIGITS), dtype=float)

    return shapely.transform(geometry, fn)


def _to_local(frame: GeoFrame, geometry: BaseGeometry) -> BaseGeometry:
    def fn(lonlat: FloatArray) -> FloatArray:
        return np.column_stack(frame.to_local(lonlat[:, 0], lonlat[:, 1]))

    return shapely.transform(geometry, fn)
