"""Which colour each drone's light shows in each of its pen windows.

A light-painting plan gives every pen window (one per stroke) a colour from a palette,
either one colour per drone (drone ``i`` takes ``palette[i % len(palette)]``) or one per
stroke (the strokes numbered across the drones in order, stroke ``k`` takes
``palette[k % len(palette)]``). The colours travel with the plan in ``trajectory.json``
(``PlannedTrajectory.pen_rgb``) to the Skybrush exports.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Literal

from skyquill.colors import RGB, check_rgb
from skyquill.errors import InputError

ColorBy = Literal["drone", "stroke"]
COLOR_BY: tuple[ColorBy, ...] = ("drone", "stroke")


def window_palette(
    windows_per_drone: Sequence[int], palette: Sequence[RGB], by: str = "drone"
) -> list[tuple[RGB, ...]]:
    """Each drone's colour per window, from ``palette`` given out per drone or per stroke.

    Parameters
    ----------
    windows_per_drone
        How many pen windows each drone has.
    palette
        At least one colour, three integers 0..255 each.
    by
        ``"drone"`` or ``"stroke"``.

    Raises
    ------
    InputError
        An empty palette, a bad colour, or another ``by``.
    """
    if by not in COLOR_BY:
        raise InputError(f"color_by: got {by!r}, expected one of {', '.join(COLOR_BY)}")
    if not palette:
        raise InputError("palette: got no colour, expected at least one")
    colors = [check_rgb(f"palette[{i}]", c) for i, c in enumerate(palette)]
    out: list[tuple[RGB, ...]] = []
    stroke = 0
    for drone, count in enumerate(windows_per_drone):
        if by == "drone":
            out.append((colors[drone % len(colors)],) * count)
        else:
            out.append(tuple(colors[(stroke + k) % len(colors)] for k in range(count)))
        stroke += count
    return out
