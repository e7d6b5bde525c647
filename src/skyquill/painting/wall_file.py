"""Wall descriptions: a small TOML file saying what the wall looks like from above.

Three kinds, exactly one per file (wall frame: ``x`` along the wall, ``y`` into it, metres and
degrees; the wall at ``x = 0`` -- in front of the take-off point -- runs along ``x`` through the
origin, which is what makes the frame)::

    height = 4.0                       # optional, m (default 4)

    [[segment]]                        # plane pieces, left to right, end to end
    from = -4.0
    to = -0.6
    angle = -10                        # deg from x; positive recedes on the right
    [[segment]]
    from = -0.6
    to = 0.6
    angle = 0
    [[segment]]
    from = 0.6
    to = 4.0
    angle = 10

    # or
    extent = [-4.0, 4.0]               # optional for the two below (default [-4, 4])
    [cylinder]
    radius = 20.0                      # m; > 0 axis behind the wall, < 0 in front of it

    # or
    [recess]
    from = 0.6
    to = 1.4
    depth = 0.1
    side_angle = 60                    # optional, deg (default 60)

Reading checks and converts only; every refusal is an :class:`~skyquill.errors.InputError`
naming the file and the key: segments that overlap or leave a gap, an angle beyond 60 deg
(90 deg and beyond is not a wall the drone can face at all), unknown keys, malformed TOML.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from skyquill.errors import InputError
from skyquill.painting.wall import MAX_WALL_ANGLE_DEG, Wall
from skyquill.validation import known_keys

#: Largest wall file read, bytes (a wall of 1,000 segments is ~60 kB).
MAX_BYTES = 200_000
#: Most segments in a wall file.
MAX_SEGMENTS = 1000
#: Farthest a wall may reach from the take-off point along ``x`` or up, m.
MAX_EXTENT_M = 100.0
KINDS = ("segment", "cylinder", "recess")


def read_wall(path: str | Path) -> Wall:
    """Read the wall description at ``path`` (:func:`parse_wall`); errors name the file."""
    file = Path(path)
    if not file.is_file():
        raise InputError(f"--wall: got {str(file)!r}, expected an existing .toml wall file")
    size = file.stat().st_size
    if size > MAX_BYTES:
        raise InputError(
            f"--wall: got {size:,} bytes in {file.name}, expected at most {MAX_BYTES:,}"
        )
    try:
        text = file.read_bytes().decode("utf-8")
    except UnicodeDecodeError:
        raise InputError(f"--wall: got {file.name}, which is not UTF-8, expected TOML") from None
    try:
        return parse_wall(text)
    except InputError as exc:
        raise InputError(f"{file.name}: {exc}") from None


def parse_wall(text: str) -> Wall:
    """The wall described by the TOML ``text`` (the module docstring has the format)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"wall: got malformed TOML ({exc}), expected TOML") from None
    known_keys(data, "wall", ("height", "extent", *KINDS))
    kinds = [k for k in KINDS if k in data]
    if len(kinds) != 1:
        raise InputError(
            f"wall: got {' and '.join(kinds) if kinds else 'no shape'}, expected exactly one of "
            "[[segment]], [cylinder] or [recess]"
        )
    height = _number("height", data.get("height", 4.0), positive=True)
    if height > MAX_EXTENT_M:
        raise InputError(f"height: got {height:g} m, expected at most {MAX_EXTENT_M:g} m")
    if kinds[0] == "segment":
        if "extent" in data:
            raise InputError(
                "extent: got it with [[segment]], expected the segments' from and to alone"
            )
        return _segments(data["segment"], height)
    extent = _extent(data.get("extent", [-4.0, 4.0]))
    if kinds[0] == "cylinder":
        table = known_keys(data["cylinder"], "cylinder", ("radius",))
        radius = _number("cylinder.radius", table.get("radius"))
        try:
            return Wall.cylinder(radius, x_range_m=extent, height_m=height)
        except InputError as exc:
            raise InputError(f"cylinder.radius: {str(exc).split(': ', 1)[1]}") from None
    table = known_keys(data["recess"], "recess", ("from", "to", "depth", "side_angle"))
    return Wall.recess(
        _number("recess.from", table.get("from")),
        _number("recess.to", table.get("to")),
        _number("recess.depth", table.get("depth"), positive=True),
        side_deg=_number("recess.side_angle", table.get("side_angle", MAX_WALL_ANGLE_DEG)),
        x_range_m=extent,
        height_m=height,
    )


def _segments(raw: Any, height: float) -> Wall:
    """``[[segment]]`` tables, end to end and left to right, into a :class:`Wall`."""
    if not isinstance(raw, list) or not raw:
        raise InputError("[[segment]]: got none, expected a list of segments, left to right")
    if len(raw) > MAX_SEGMENTS:
        raise InputError(f"[[segment]]: got {len(raw)}, expected at most {MAX_SEGMENTS}")
    starts: list[float] = []
    ends: list[float] = []
    angles: list[float] = []
    for i, table in enumerate(raw):
        where = f"segment[{i}]"
        t = known_keys(table, where, ("from", "to", "angle"))
        lo, hi = _number(f"{where}.from", t.get("from")), _number(f"{where}.to", t.get("to"))
        angle = _number(f"{where}.angle", t.get("angle"))
        if abs(angle) > MAX_WALL_ANGLE_DEG:
            raise InputError(
                f"{where}.angle: got {angle:g} deg, expected within +-{MAX_WALL_ANGLE_DEG:g} deg "
                "(a segment at 90 deg or more is not a wall the drone can face)"
            )
        if not hi > lo:
            raise InputError(f"{where}.to: got {hi:g} m, expected more than its from ({lo:g} m)")
        if i and lo != ends[-1]:
            how = "overlaps" if lo < ends[-1] else "leaves a gap after"
            raise InputError(
                f"{where}.from: got {lo:g} m, which {how} segment[{i - 1}] (to = {ends[-1]:g} m); "
                "expected each segment to start where the one before ends"
            )
        for key, value in (("from", lo), ("to", hi)):
            if abs(value) > MAX_EXTENT_M:
                raise InputError(
                    f"{where}.{key}: got {value:g} m, expected within {MAX_EXTENT_M:g} m of x = 0"
                )
        starts.append(lo)
        ends.append(hi)
        angles.append(angle)
    if not starts[0] < 0.0 < ends[-1]:
        raise InputError(
            f"[[segment]]: got a wall from {starts[0]:g} to {ends[-1]:g} m, expected it to reach "
            "on both sides of x = 0 (the wall in front of the take-off point)"
        )
    holds = [i for i in range(len(starts)) if starts[i] <= 0.0 < ends[i]]
    if starts[holds[0]] == 0.0:
        raise InputError(
            f"segment[{holds[0]}].from: got 0 m, expected x = 0 inside a segment (the wall in "
            "front of the take-off point makes the wall frame; a corner there does not)"
        )
    if angles[holds[0]] != 0.0:
        raise InputError(
            f"segment[{holds[0]}].angle: got {angles[holds[0]]:g} deg for the segment holding "
            "x = 0, expected 0 (the wall in front of the take-off point makes the wall frame; "
            "a turned placement is --gamma)"
        )
    return Wall(np.radians(angles), np.array(ends[:-1]), (starts[0], ends[-1]), height)


def _extent(value: Any) -> tuple[float, float]:
    if not isinstance(value, list) or len(value) != 2:
        raise InputError(f"extent: got {value!r}, expected [x_min, x_max] in m")
    lo, hi = _number("extent[0]", value[0]), _number("extent[1]", value[1])
    if not -MAX_EXTENT_M <= lo < 0.0 < hi <= MAX_EXTENT_M:
        raise InputError(
            f"extent: got [{lo:g}, {hi:g}], expected x_min < 0 < x_max, within {MAX_EXTENT_M:g} m"
        )
    return lo, hi


def _number(where: str, value: Any, *, positive: bool = False) -> float:
    """A finite number (bools are not numbers); InputError naming ``where`` otherwise."""
    if value is None:
        raise InputError(f"{where}: got nothing, expected a number")
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InputError(f"{where}: got {value!r}, expected a number")
    number = float(value)
    if not math.isfinite(number) or (positive and number <= 0.0):
        raise InputError(
            f"{where}: got {value!r}, expected a {'positive' if positive else 'finite'} number"
        )
    if abs(number) > 1e6:
        raise InputError(f"{where}: got {value!r}, expected a number within 1e6")
    return number
