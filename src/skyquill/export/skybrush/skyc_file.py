"""Skybrush ``.skyc`` shows: write one, read one back and check its structure.

A ``.skyc`` file is a ZIP archive holding ``show.json`` (the structure Skybrush's loader
reads: skybrush-io/skybrush.js ``packages/show-format/src/types.ts``, ``validation.ts``)::

    {"version": 1,
     "environment": {"type": "indoor"},
     "meta": {"title": ...},
     "settings": {"validation": {"maxAltitude": ..., "maxVelocityXY": ..., ...}},
     "swarm": {"drones": [
         {"type": "generic",
          "settings": {"name": "drone1", "home": [x, y, z],
                       "trajectory": {"version": 1, "takeoffTime": 0.0,
                                      "points": [[t, [x, y, z], [[cx, cy, cz], ...]], ...]},
                       "lights": {"version": 1, "data": "<base64 bytecode>"},
                       "yawControl": {"version": 1, "setpoints": [[t, yaw_deg], ...],
                                      "autoYaw": false}}},
         ...]}}

Trajectory convention (Skybrush's ``TrajectorySpecification.iter_segments``):
``points[i] = [t_i, p(t_i), controls_i]`` is a keyframe at show time ``t_i`` (s) and
``controls_i`` are the inner Bézier control points of the segment that **ends** there; the
first keyframe has none, an empty list elsewhere is a straight segment, Skybrush Live plays
at most two (cubic). What a drone plays from it is :mod:`skyquill.export.skybrush.playback`;
:mod:`skyquill.export.skybrush.keyframes` builds keyframes on its ms and mm grid and
:mod:`skyquill.export.skybrush.lights` the light programs.

An outdoor show may propose where it is flown: ``"environment": {"type": "outdoor",
"location": {"origin": [lat_e7, lon_e7, amsl_mm], "orientation": deg}}`` (skybrush.js
``types.ts``, ``Location``; the integers as Skybrush Studio for Blender writes them,
skybrush-io/studio-blender ``src/modules/sbstudio/model/location.py``: latitude and
longitude in 1e-7 degrees, the optional altitude above mean sea level in mm, the
orientation of the show's X+ axis in degrees from north towards east).

``yawControl`` is read by Skybrush's "show pro" extension (skybrush-server
``src/flockwave/server/ext/mavlink/driver.py``, ``upload_show``); without it the server
warns and leaves the yaw to the drone. Frames and units: Skybrush's show frame is x, y
horizontal and z up, metres and seconds, which is skyquill's world frame.
"""

from __future__ import annotations

import itertools
import json
import math
import zipfile
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from skyquill.errors import InputError
from skyquill.export.skybrush import DEFLATE_LEVEL
from skyquill.export.skybrush.keyframes import Keyframes
from skyquill.export.skybrush.lights import lights_json, program_bytes
from skyquill.export.skybrush.playback import MAX_SEGMENT_S, played_show
from skyquill.io.atomic import atomic_path
from skyquill.io.json_read import collector_paused, parse_json
from skyquill.io.source import open_binary
from skyquill.trajectory import PiecewisePolynomial

#: Largest ``show.json`` read from an archive, bytes (checked before inflating it).
MAX_SHOW_BYTES = 256 * 2**20
#: Largest .skyc file read, bytes: compressed, the show.json of that size takes far less.
MAX_SKYC_BYTES = 256 * 2**20
#: Environments Skybrush knows.
ENVIRONMENTS = ("indoor", "outdoor")
#: Most control points of a segment Skybrush Live plays (cubic).
MAX_CONTROLS = 2
#: Keys of ``settings.validation`` Skybrush Live reads (skybrush-io/live
#: ``src/features/validation/selectors.ts``), all non-negative, m, m/s, m/s^2.
VALIDATION_KEYS = (
    "maxAltitude",
    "maxVelocityXY",
    "maxVelocityZ",
    "maxVelocityZUp",
    "maxAccelerationXY",
    "maxAccelerationZ",
    "maxAccelerationZUp",
    "minDistance",
)


@dataclass(frozen=True)
class SkycDrone:
    """One drone of a show.

    Attributes
    ----------
    name
        Its name in the show.
    keyframes
        Its trajectory on Skybrush's grid
        (:func:`~skyquill.export.skybrush.keyframes.skybrush_keyframes`).
    lights
        Its light program (bytecode), or ``None`` for none (Skybrush Live shows white).
    yaw_deg
        Its constant heading, degrees (the plans carry no yaw).
    """

    name: str
    keyframes: Keyframes
    lights: bytes | None = None
    yaw_deg: float = 0.0


def _drone_json(drone: SkycDrone) -> dict[str, Any]:
    points = drone.keyframes.points()
    end = points[-1][0]
    settings: dict[str, Any] = {
        "name": drone.name,
        "home": points[0][1],
        "trajectory": {"version": 1, "points": points, "takeoffTime": 0.0},
        "yawControl": {
            "version": 1,
            "setpoints": [[0.0, drone.yaw_deg], [end, drone.yaw_deg]],
            "autoYaw": False,
        },
    }
    if drone.lights is not None:
        settings["lights"] = lights_json(drone.lights)
    return {"type": "generic", "settings": settings}


def write_skyc(
    drones: Sequence[SkycDrone],
    path: str | Path,
    *,
    validation: Mapping[str, float] | None = None,
    title: str = "skyquill",
    location: Mapping[str, Any] | None = None,
) -> Path:
    """Write a Skybrush ``.skyc`` show (atomically) and return its path.

    Parameters
    ----------
    drones
        The drones, in show order.
    path
        Output file (conventionally ``*.skyc``).
    validation
        ``settings.validation`` (keys of :data:`VALIDATION_KEYS`), or ``None``.
    title
        Show title written to ``meta.title``.
    location
        ``environment.location`` (:func:`show_location`), or ``None``: an outdoor
        show with a location, else an indoor one.

    Raises
    ------
    InputError
        When ``drones`` is empty or the show does not pass :func:`validate_show`.
    """
    if isinstance(drones, SkycDrone) or len(drones) == 0:
        raise InputError("drones: got nothing, expected a non-empty sequence of SkycDrone")
    if not isinstance(title, str):
        raise InputError(f"title: got {type(title).__name__}, expected a string")
    with collector_paused():  # millions of small lists: no cycles among them
        show: dict[str, Any] = {
            "version": 1,
            "environment": {"type": "indoor"}
            if location is None
            else {"type": "outdoor", "location": dict(location)},
            "meta": {"title": title},
            "swarm": {"drones": [_drone_json(d) for d in drones]},
        }
        if validation is not None:
            show["settings"] = {"validation": dict(validation)}
        validate_show(show)  # what we write must pass our own reader
        file = Path(path)
        with (
            atomic_path(file) as tmp,
            zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED, compresslevel=DEFLATE_LEVEL) as archive,
        ):
            archive.writestr("show.json", json.dumps(show, allow_nan=False))
    return file


def show_location(
    lat_deg: float, lon_deg: float, amsl_m: float | None, orientation_deg: float
) -> dict[str, Any]:
    """``environment.location``: the show origin (WGS84) and the X+ axis' heading.

    Parameters
    ----------
    lat_deg, lon_deg
        The origin, degrees (stored as integers of 1e-7 degrees, about 1.1 cm).
    amsl_m
        Its altitude above mean sea level, m (stored in mm), or None (left out).
    orientation_deg
        Heading of the show's X+ axis, degrees clockwise from north (90: x east).
    """
    origin = [round(lat_deg * 1e7), round(lon_deg * 1e7)]
    if amsl_m is not None:
        origin.append(round(amsl_m * 1e3))
    return {"origin": origin, "orientation": round(float(orientation_deg), 3)}


def read_show_location(show: Mapping[str, Any]) -> tuple[float, float, float | None, float] | None:
    """``(lat_deg, lon_deg, amsl_m or None, orientation_deg)`` of a validated show, or None."""
    location = show["environment"].get("location")
    if location is None:
        return None
    origin = location["origin"]
    amsl = None if len(origin) < 3 else origin[2] / 1e3
    return origin[0] / 1e7, origin[1] / 1e7, amsl, float(location["orientation"])


def _check_location(location: Any) -> None:
    where = "show.json: environment.location"
    location = _obj(where, location)
    origin = location.get("origin")
    if not (
        isinstance(origin, list)
        and len(origin) in (2, 3)
        and all(isinstance(c, int) and not isinstance(c, bool) for c in origin)
        and abs(origin[0]) <= 900_000_000
        and abs(origin[1]) <= 1_800_000_000
    ):
        raise InputError(
            f"{where}.origin: got {origin!r:.60}, expected [lat_e7, lon_e7(, amsl_mm)]: "
            "integers of 1e-7 degrees within ±90/±180 (and mm)"
        )
    orientation = location.get("orientation")
    if not _is_number(orientation):
        raise InputError(
            f"{where}.orientation: got {orientation!r:.40}, expected the X+ axis' heading in "
            "degrees from north"
        )


def read_show_json(path: str | Path) -> dict[str, Any]:
    """Open a ``.skyc`` archive and return its validated ``show.json``.

    Raises
    ------
    InputError
        When the file is missing, not a ZIP (or a corrupt or encrypted one), has
        no ``show.json`` or one larger than :data:`MAX_SHOW_BYTES`, the JSON is
        malformed, not UTF-8 or nested too deep (:mod:`skyquill.io.json_read`),
        or :func:`validate_show` rejects it.
    """
    file = Path(path)
    if not file.exists():
        raise InputError(f"skyc file: got {str(file)!r}, expected an existing .skyc file")
    try:
        with (
            open_binary(file, "a .skyc show", max_bytes=MAX_SKYC_BYTES, name=file.name) as stream,
            zipfile.ZipFile(stream) as archive,
        ):
            if "show.json" not in archive.namelist():
                raise InputError(
                    f"{file.name}: got members {archive.namelist()[:10]}, expected a show.json"
                )
            # The size in the directory is checked before inflating: a ZIP bomb is
            # a few kilobytes that claim gigabytes.
            size = archive.getinfo("show.json").file_size
            if size > MAX_SHOW_BYTES:
                raise InputError(
                    f"{file.name}: show.json: got {size:,} bytes, expected at most "
                    f"{MAX_SHOW_BYTES:,}"
                )
            raw = archive.read("show.json")
    except InputError:
        raise
    except zipfile.BadZipFile:
        raise InputError(f"{file.name}: got a file that is not a ZIP, expected a .skyc") from None
    except (OSError, EOFError, RuntimeError, NotImplementedError, zlib.error) as exc:
        # encrypted members, unknown compression, a corrupt stream
        raise InputError(
            f"{file.name}: show.json cannot be extracted ({type(exc).__name__}: {exc}), "
            "expected a .skyc written by a show designer"
        ) from None
    show = parse_json(raw, f"{file.name}: show.json", "a Skybrush show object")
    validate_show(show)
    if not isinstance(show, dict):  # pragma: no cover - validate_show checked it
        raise InputError("show.json: expected an object")
    return show


def _is_number(x: Any) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x)


def _vec3(where: str, value: Any) -> list[float]:
    if not (isinstance(value, list) and len(value) == 3 and all(_is_number(c) for c in value)):
        raise InputError(f"{where}: got {value!r:.60}, expected [x, y, z] of finite numbers")
    return [float(c) for c in value]


def _obj(where: str, value: Any) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise InputError(f"{where}: got {type(value).__name__}, expected an object")
    return value


def _check_trajectory(where: str, traj: Any) -> None:
    traj = _obj(where, traj)
    if traj.get("version") != 1:
        raise InputError(f"{where}.version: got {traj.get('version')!r}, expected 1")
    takeoff = traj.get("takeoffTime", 0.0)
    if not _is_number(takeoff) or takeoff < 0:
        raise InputError(f"{where}.takeoffTime: got {takeoff!r}, expected a finite time >= 0 (s)")
    if "home" in traj:
        _vec3(f"{where}.home", traj["home"])
    points = traj.get("points")
    if not isinstance(points, list) or len(points) == 0:
        raise InputError(f"{where}.points: got {points!r:.60}, expected a non-empty list")
    if _well_formed(points):
        return
    prev_t: float | None = None
    for i, point in enumerate(points):
        here = f"{where}.points[{i}]"
        if not (isinstance(point, list) and len(point) == 3):
            raise InputError(f"{here}: got {point!r:.60}, expected [t, [x, y, z], [controls]]")
        t, pos, controls = point
        if not _is_number(t):
            raise InputError(f"{here}[0]: got {t!r}, expected a finite time (s)")
        # The server rounds every segment to whole ms (iter_segments): a step under half a
        # millisecond is a segment of no time, which it refuses.
        if prev_t is not None and not round(t - prev_t, 3) > 0:
            raise InputError(
                f"{here}[0]: got {t!r} after {prev_t!r}, expected increasing times at least "
                "1 ms apart (Skybrush rounds segments to ms)"
            )
        if prev_t is not None and round(t - prev_t, 3) > MAX_SEGMENT_S:
            raise InputError(
                f"{here}[0]: got a {t - prev_t:g} s segment, expected at most {MAX_SEGMENT_S:g} s"
            )
        _vec3(f"{here}[1]", pos)
        if not isinstance(controls, list):
            raise InputError(f"{here}[2]: got {controls!r:.60}, expected a list of [x, y, z]")
        if i == 0 and controls:
            raise InputError(f"{here}[2]: got {len(controls)} control point(s), expected none")
        if len(controls) > MAX_CONTROLS:
            raise InputError(
                f"{here}[2]: got {len(controls)} control points, expected at most {MAX_CONTROLS} "
                "(Skybrush Live plays linear, quadratic and cubic segments)"
            )
        for j, c in enumerate(controls):
            _vec3(f"{here}[2][{j}]", c)
        prev_t = float(t)


def _well_formed(points: list[Any]) -> bool:
    """Whether every keyframe passes the checks of :func:`_check_trajectory`, tested in bulk.

    The same rules over whole lists at a time (types by ``set(map(type, ...))``,
    ``math.isfinite`` mapped over the numbers, the server's ``round`` on every step): a
    thousand drones' 350,000 keyframes took seconds one field at a time. ``False`` when
    anything is off (or of an unusual type): the field by field loop then finds and
    names it.
    """
    if not all(type(p) is list and len(p) == 3 for p in points):
        return False
    times = [p[0] for p in points]
    controls = [p[2] for p in points]
    if points[0][2] != [] or not all(type(c) is list and len(c) <= MAX_CONTROLS for c in controls):
        return False
    vectors = [p[1] for p in points] + [c for each in controls for c in each]
    if not all(type(v) is list and len(v) == 3 for v in vectors):
        return False
    numbers = times + [x for v in vectors for x in v]
    if not set(map(type, numbers)) <= {int, float}:
        return False
    try:
        if not all(map(math.isfinite, numbers)):
            return False
    except OverflowError:  # an integer beyond the float range
        return False
    steps = [round(float(b) - float(a), 3) for a, b in itertools.pairwise(times)]
    return all(0 < step <= MAX_SEGMENT_S for step in steps)


def _check_yaw(where: str, yaw: Any) -> None:
    yaw = _obj(where, yaw)
    if yaw.get("version") != 1:
        raise InputError(f"{where}.version: got {yaw.get('version')!r}, expected 1")
    setpoints = yaw.get("setpoints")
    if not isinstance(setpoints, list) or not all(
        isinstance(p, list) and len(p) == 2 and all(_is_number(x) for x in p) for p in setpoints
    ):
        raise InputError(f"{where}.setpoints: got {setpoints!r:.60}, expected [[t, yaw_deg], ...]")
    if not isinstance(yaw.get("autoYaw", False), bool):
        raise InputError(f"{where}.autoYaw: got {yaw.get('autoYaw')!r}, expected true or false")


def _check_validation(settings: Any) -> None:
    if settings is None:
        return
    settings = _obj("show.json: settings", settings)
    validation = settings.get("validation")
    if validation is None:
        return
    validation = _obj("show.json: settings.validation", validation)
    for key, value in validation.items():
        if key in VALIDATION_KEYS and not (_is_number(value) and value >= 0):
            raise InputError(
                f"show.json: settings.validation.{key}: got {value!r:.40}, expected a number >= 0"
            )


def validate_show(show: Any) -> None:
    """Check a ``show.json`` object against the structure in the module docstring.

    Raises
    ------
    InputError
        Naming the path of the first bad field, e.g.
        ``show.json: swarm.drones[1].settings.trajectory.points[3][0]``.
    """
    show = _obj("show.json", show)
    if show.get("version") != 1:
        raise InputError(f"show.json: version: got {show.get('version')!r}, expected 1")
    env = _obj("show.json: environment", show.get("environment"))
    if env.get("type") not in ENVIRONMENTS:
        raise InputError(
            f"show.json: environment.type: got {env.get('type')!r}, expected one of {ENVIRONMENTS}"
        )
    if "location" in env:
        _check_location(env["location"])
    _check_validation(show.get("settings"))
    swarm = _obj("show.json: swarm", show.get("swarm"))
    drones = swarm.get("drones")
    if not isinstance(drones, list) or len(drones) == 0:
        raise InputError(f"show.json: swarm.drones: got {drones!r:.60}, expected a non-empty list")
    for i, drone in enumerate(drones):
        where = f"show.json: swarm.drones[{i}]"
        settings = _obj(f"{where}.settings", _obj(where, drone).get("settings"))
        _vec3(f"{where}.settings.home", settings.get("home"))
        _check_trajectory(f"{where}.settings.trajectory", settings.get("trajectory"))
        if "lights" in settings:
            program_bytes(f"{where}.settings.lights", settings["lights"])
        if "yawControl" in settings:
            _check_yaw(f"{where}.settings.yawControl", settings["yawControl"])


def show_trajectories(show: dict[str, Any]) -> list[PiecewisePolynomial]:
    """The drones' trajectories of a validated ``show.json`` as their firmware plays them.

    Skybrush's upload encoding and its firmware's evaluation
    (:mod:`skyquill.export.skybrush.playback`), on the firmware's clock (0 at the first segment).

    Returns
    -------
    list of PiecewisePolynomial
        One per drone, z-up, m.
    """
    return [played.trajectory() for played in played_show(show)]
