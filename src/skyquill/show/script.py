"""Show scripts: a TOML file of scenes (``docs/show-format.md``), read into typed scenes.

Reading only checks and converts (SI units, frames as documented); planning is
:mod:`skyquill.show.build`. Every unknown table, key or scene type is an
:class:`~skyquill.errors.InputError` that names it and lists the known ones.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from skyquill.colors import check_rgb, hex_rgb
from skyquill.errors import InputError
from skyquill.io.numbers import EXPECTED, is_literal
from skyquill.io.source import read_text
from skyquill.limits import VehicleLimits
from skyquill.show.geofence import Geofence, read_geofence
from skyquill.validation import FloatArray, as_array, as_float, as_int, known_keys

RGB = tuple[int, int, int]
#: Most drones in one show. The separation proof looks only at neighbours (sweep and
#: prune over space-time boxes), so planning, proving and writing grow about linearly
#: with the drones (bench/show.py: a thousand drones in about two minutes on two cores).
MAX_DRONES = 1000
#: Most scenes, and the longest a show may hold still in all (holds, formations' holds,
#: take-off and landing staggers), s: the CSVs and the check grow with the show's length.
MAX_SCENES = 64
MAX_HOLDING_S = 3600.0
#: Largest size, radius or spacing of a formation or writing, m, and highest altitude,
#: m (the show's check refuses a drone above 120 m; it is refused before planning here).
MAX_EXTENT_M = 1000.0
MAX_ALTITUDE_M = 120.0
#: Farthest a point of the script may be from the show's origin, m (Skybrush's units
#: stay within a few mm up to here).
MAX_COORDINATE_M = 10_000.0
#: Highest CSV rate, Hz.
MAX_RATE_HZ = 100.0
#: Largest script read, bytes.
MAX_BYTES = 1_000_000
#: Shapes a formation scene can take.
SHAPES = ("text", "svg", "grid", "circle")


@dataclass(frozen=True)
class Takeoff:
    """Every drone climbs straight up from its pad, row after row."""

    altitude_m: float = 3.0
    stagger_s: float = 1.0


@dataclass(frozen=True)
class FormationScene:
    """Fly into a formation and hold it, lit in ``color``.

    ``origin`` is the bottom-left corner of a text, SVG or grid on the vertical
    plane facing -y; ``center`` the centre of a circle.
    """

    shape: str
    hold_s: float
    color: RGB
    origin: FloatArray
    size_m: float = 20.0
    text: str = ""
    font: str = "futural"
    svg: Path | None = None
    columns: int = 10
    spacing_m: float | None = None
    radius_m: float = 10.0


@dataclass(frozen=True)
class WriteScene:
    """``drones`` drones write ``text`` on vertical boards, the others hold their place."""

    text: str
    color: RGB
    origin: FloatArray
    size_m: float = 2.0
    drones: int | None = None
    columns: int = 5
    font: str = "futural"


@dataclass(frozen=True)
class Hold:
    """Everyone holds where they are; lit in ``color`` if one is given."""

    duration_s: float
    color: RGB | None = None


@dataclass(frozen=True)
class Land:
    """Fly to the air above the pads, then descend row after row."""

    altitude_m: float = 3.0
    stagger_s: float = 1.0


Scene = Takeoff | FormationScene | WriteScene | Hold | Land


@dataclass(frozen=True)
class ShowScript:
    """A whole show: its drones, limits, safety distance and scenes.

    Attributes
    ----------
    drones
        Number of drones.
    safety_m
        Distance every two drones keep at all times, m.
    home_spacing_m
        Spacing of the take-off pads (a square grid on the ground), m.
    home_origin
        The first pad's ``(x, y)``, m.
    limits
        Speed, acceleration and jerk (norms) of every flight.
    rate_hz
        Sample rate of the CSV files, Hz.
    scenes
        Take-off first, landing last.
    base
        The folder the script's file names (an SVG) are relative to.
    geofence
        Where the drones may fly (``[show].geofence``: a GeoJSON or WKT file in the
        show's metres, :func:`~skyquill.show.geofence.read_geofence`), or ``None``.
    """

    drones: int
    safety_m: float
    home_spacing_m: float
    home_origin: FloatArray
    limits: VehicleLimits
    rate_hz: float
    scenes: tuple[Scene, ...]
    base: Path = field(default_factory=Path)
    geofence: Geofence | None = None


def _color(where: str, value: Any) -> RGB:
    """``[r, g, b]`` or ``"#rrggbb"``."""
    if isinstance(value, str):
        rgb = hex_rgb(value.removeprefix("#"))
        if rgb is None:
            raise InputError(f"{where}: got {value!r:.40}, expected '#rrggbb' or [r, g, b]")
        return rgb
    return check_rgb(where, value)


def _point(where: str, value: Any, n: int = 3) -> FloatArray:
    point = as_array(where, value, shape=(n,))
    if np.abs(point).max() > MAX_COORDINATE_M:
        raise InputError(
            f"{where}: got {point.tolist()}, expected coordinates within "
            f"{MAX_COORDINATE_M:g} m of the show's origin"
        )
    return point


def _number(where: str, value: Any, *, positive: bool = True) -> float:
    if isinstance(value, bool):
        raise InputError(f"{where}: got {value!r}, expected a number")
    return as_float(where, value, positive=positive, nonneg=not positive)


def _text(where: str, value: Any) -> str:
    if not isinstance(value, str) or not value.strip():
        raise InputError(f"{where}: got {value!r:.40}, expected a non-empty string")
    return value


def _takeoff(t: dict[str, Any], where: str) -> Takeoff:
    known_keys(t, where, ("type", "altitude", "stagger"))
    return Takeoff(
        _at_most(f"{where}.altitude", t.get("altitude", 3.0), MAX_ALTITUDE_M, "m"),
        _number(f"{where}.stagger", t.get("stagger", 1.0), positive=False),
    )


def _land(t: dict[str, Any], where: str) -> Land:
    known_keys(t, where, ("type", "altitude", "stagger"))
    return Land(
        _at_most(f"{where}.altitude", t.get("altitude", 3.0), MAX_ALTITUDE_M, "m"),
        _number(f"{where}.stagger", t.get("stagger", 1.0), positive=False),
    )


def _hold(t: dict[str, Any], where: str) -> Hold:
    known_keys(t, where, ("type", "duration", "color"))
    color = t.get("color")
    return Hold(
        _number(f"{where}.duration", t.get("duration", 1.0)),
        None if color is None else _color(f"{where}.color", color),
    )


FORMATION_KEYS = (
    "type", "shape", "hold", "color", "origin", "center", "size", "text", "font", "svg",
    "columns", "spacing", "radius",
)  # fmt: skip


def _formation(t: dict[str, Any], where: str, base: Path) -> FormationScene:
    known_keys(t, where, FORMATION_KEYS)
    shape = t.get("shape")
    if not isinstance(shape, str) or shape not in SHAPES:
        raise InputError(f"{where}.shape: got {shape!r}, expected one of {', '.join(SHAPES)}")
    place = "center" if shape == "circle" else "origin"
    if place not in t:
        raise InputError(f"{where}: got no {place!r}, expected [x, y, z] in m for a {shape}")
    text = _text(f"{where}.text", t.get("text")) if shape == "text" else ""
    svg = base / _text(f"{where}.svg", t.get("svg")) if shape == "svg" else None
    spacing = t.get("spacing")
    return FormationScene(
        shape=shape,
        hold_s=_number(f"{where}.hold", t.get("hold", 2.0), positive=False),
        color=_color(f"{where}.color", t.get("color", [255, 255, 255])),
        origin=_point(f"{where}.{place}", t[place]),
        size_m=_at_most(f"{where}.size", t.get("size", 20.0), MAX_EXTENT_M, "m"),
        text=text,
        font=str(t.get("font", "futural")),
        svg=svg,
        columns=as_int(f"{where}.columns", t.get("columns", 10), low=1),
        spacing_m=None
        if spacing is None
        else _at_most(f"{where}.spacing", spacing, MAX_EXTENT_M, "m"),
        radius_m=_at_most(f"{where}.radius", t.get("radius", 10.0), MAX_EXTENT_M, "m"),
    )


def _write(t: dict[str, Any], where: str) -> WriteScene:
    known_keys(t, where, ("type", "text", "color", "origin", "size", "drones", "columns", "font"))
    if "origin" not in t:
        raise InputError(f"{where}: got no 'origin', expected [x, y, z] in m (first board)")
    drones = t.get("drones")
    return WriteScene(
        text=_text(f"{where}.text", t.get("text")),
        color=_color(f"{where}.color", t.get("color", [255, 255, 255])),
        origin=_point(f"{where}.origin", t["origin"]),
        size_m=_at_most(f"{where}.size", t.get("size", 2.0), MAX_EXTENT_M, "m"),
        drones=None if drones is None else as_int(f"{where}.drones", drones, low=1),
        columns=as_int(f"{where}.columns", t.get("columns", 5), low=1),
        font=str(t.get("font", "futural")),
    )


_SCENES: dict[str, Callable[[dict[str, Any], str, Path], Scene]] = {
    "takeoff": lambda t, w, _: _takeoff(t, w),
    "formation": _formation,
    "write": lambda t, w, _: _write(t, w),
    "hold": lambda t, w, _: _hold(t, w),
    "land": lambda t, w, _: _land(t, w),
}


def _scene(t: Any, where: str, base: Path) -> Scene:
    if not isinstance(t, dict):
        raise InputError(f"{where}: got {type(t).__name__}, expected a table")
    kind = t.get("type")
    if not isinstance(kind, str) or kind not in _SCENES:
        raise InputError(f"{where}.type: got {kind!r}, expected one of {', '.join(_SCENES)}")
    return _SCENES[kind](t, where, base)


class _FloatError(ValueError):
    """A TOML float outside the one number grammar."""


def _plain_float(text: str) -> float:
    """A TOML float in the grammar of :mod:`skyquill.io.numbers`: no ``1_000.5``.

    TOML allows underscores between digits; every other reader refuses them, so a
    show script does too. ``nan`` and ``inf`` are read, and refused by the key's own
    range check, which names the key.
    """
    if not is_literal(text, non_finite=True):
        raise _FloatError(text)
    return float(text)


def parse_script(text: str, base: Path = Path()) -> ShowScript:
    """A show script from its TOML ``text``; files it names are relative to ``base``.

    Raises
    ------
    InputError
        Malformed TOML, an unknown table, key or scene type (naming it and
        listing the known ones), a value out of range, no take-off first or no
        landing last.
    """
    try:
        data = tomllib.loads(text, parse_float=_plain_float)
    except _FloatError as exc:
        raise InputError(f"show script: got the number {exc}, expected {EXPECTED}") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"show script: got malformed TOML ({exc}), expected TOML") from None
    known_keys(data, "show script", ("show", "limits", "scene"))
    show = known_keys(data.get("show", {}), "[show]", SHOW_KEYS)
    limits = known_keys(data.get("limits", {}), "[limits]", ("vmax", "amax", "jmax"))
    raw = data.get("scene", [])
    if not isinstance(raw, list) or not raw:
        raise InputError("[[scene]]: got none, expected a list of scenes, takeoff first")
    if len(raw) > MAX_SCENES:
        raise InputError(f"[[scene]]: got {len(raw)} scenes, expected at most {MAX_SCENES}")
    scenes = tuple(_scene(t, f"scene[{i}]", base) for i, t in enumerate(raw))
    _check_order(scenes)
    _check_work(scenes, show.get("drones"))
    safety = _number("[show].safety_distance", show.get("safety_distance", 3.0))
    return ShowScript(
        drones=as_int("[show].drones", show.get("drones"), low=1, high=MAX_DRONES),
        safety_m=safety,
        # CAPT: pads sqrt(2) x the safety distance apart leave for any formation in one wave.
        home_spacing_m=_number(
            "[show].home_spacing", show.get("home_spacing", math.sqrt(2.0) * safety)
        ),
        home_origin=_point("[show].home_origin", show.get("home_origin", [0.0, -10.0]), 2),
        limits=VehicleLimits(
            vmax=_number("[limits].vmax", limits.get("vmax", 3.0)),
            amax=_number("[limits].amax", limits.get("amax", 2.0)),
            jmax=_number("[limits].jmax", limits.get("jmax", 10.0)),
        ),
        rate_hz=_at_most("[show].rate", show.get("rate", 20.0), MAX_RATE_HZ, "Hz"),
        scenes=scenes,
        base=base,
        geofence=_geofence(show.get("geofence"), base),
    )


SHOW_KEYS = ("drones", "safety_distance", "home_spacing", "home_origin", "rate", "geofence")


def _geofence(value: Any, base: Path) -> Geofence | None:
    """``[show].geofence``: a file name relative to the script, read; ``None`` when absent."""
    if value is None:
        return None
    return read_geofence(base / _text("[show].geofence", value), "[show].geofence")


def _at_most(where: str, value: Any, high: float, unit: str) -> float:
    """A positive number at most ``high`` (``unit``); :class:`InputError` otherwise."""
    number = _number(where, value)
    if number > high:
        raise InputError(f"{where}: got {number:g} {unit}, expected at most {high:g} {unit}")
    return number


def _extent(where: str, value: Any) -> float:
    return _at_most(where, value, MAX_EXTENT_M, "m")


def _check_work(scenes: tuple[Scene, ...], drones: Any) -> None:
    """Refuse, before planning, a show that would hold still longer than :data:`MAX_HOLDING_S`.

    Take-off and landing hold each row of pads ``stagger`` s after the one before.
    """
    rows = math.isqrt(max(1, drones if isinstance(drones, int) else 1)) + 1
    holding = 0.0
    for scene in scenes:
        if isinstance(scene, Takeoff | Land):
            holding += scene.stagger_s * rows
        elif isinstance(scene, FormationScene):
            holding += scene.hold_s
        elif isinstance(scene, Hold):
            holding += scene.duration_s
    if holding > MAX_HOLDING_S:
        raise InputError(
            f"show script: got {holding:g} s of holding (holds, staggers), expected at most "
            f"{MAX_HOLDING_S:g} s in one show"
        )


def _check_order(scenes: tuple[Scene, ...]) -> None:
    if not isinstance(scenes[0], Takeoff):
        raise InputError(f"scene[0].type: got {_name(scenes[0])!r}, expected 'takeoff' first")
    if not isinstance(scenes[-1], Land):
        raise InputError(
            f"scene[{len(scenes) - 1}].type: got {_name(scenes[-1])!r}, expected 'land' last"
        )
    for i, s in enumerate(scenes[1:-1], start=1):
        if isinstance(s, Takeoff | Land):
            raise InputError(
                f"scene[{i}].type: got {_name(s)!r}, expected takeoff only first and land only last"
            )


def _name(scene: Scene) -> str:
    return {v: k for k, v in SCENE_TYPES.items()}[type(scene)]


SCENE_TYPES: dict[str, type] = {
    "takeoff": Takeoff,
    "formation": FormationScene,
    "write": WriteScene,
    "hold": Hold,
    "land": Land,
}


def load_script(path: Path) -> ShowScript:
    """Read the show script at ``path`` (:func:`parse_script`, files relative to it)."""
    file = Path(path)
    if not file.exists():
        raise InputError(f"SHOW: got {str(file)!r}, expected an existing .toml file")
    text = read_text(file, "a TOML show script", max_bytes=MAX_BYTES, name=file.name)
    try:
        return parse_script(text, file.parent)
    except InputError as exc:
        raise InputError(f"{file.name}: {exc}") from None
