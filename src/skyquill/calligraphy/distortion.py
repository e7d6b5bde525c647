"""How a light painting looks from off-axis: distortion seen from the side (paper 003 §5.3).

The audience of a sky board does not all stand on its normal. Paper 003's Fig. 8
shows the same drawing at 0°, 55° and 90° about the board's vertical axis: a
path that leaves the plane is drawn out of shape when seen from the side. Here
the views are orthographic: a camera turned by ``angle`` about the board's
``e_v`` sees a point at board coordinates ``(u, v, h)`` (``h`` off the plane)
at image coordinates ``(u cos(angle) + h sin(angle), v)``. The distortion is
the image-plane distance of the light path (pen-on samples) from the intended
strokes, both projected; at 90° it is the out-of-plane deviation ``|h|``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from skyquill.calligraphy.board import Board
from skyquill.errors import InputError
from skyquill.geometry import polyline_distance
from skyquill.validation import FloatArray, as_float

if TYPE_CHECKING:
    from skyquill.calligraphy.mission import Mission

#: Paper 003 Fig. 8's views about the board's vertical axis, degrees.
VIEW_ANGLES_DEG = (0.0, 55.0, 90.0)


@dataclass(frozen=True)
class ViewDistortion:
    """The light path against the strokes in one orthographic view.

    Attributes
    ----------
    angle_deg
        The camera's turn about the board's vertical axis from its normal, degrees.
    max_m, rms_m
        Largest and root-mean-square image-plane distance of the pen-on samples
        from the projected strokes, m.
    """

    angle_deg: float
    max_m: float
    rms_m: float

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready numbers, mm."""
        return {
            "angle_deg": self.angle_deg,
            "max_mm": 1e3 * self.max_m,
            "rms_mm": 1e3 * self.rms_m,
        }


def project(p_B: FloatArray, angle_deg: float) -> FloatArray:
    """Board coordinates (K, 3) ``(u, v, h)`` to image coordinates (K, 2), m, at ``angle_deg``."""
    a = math.radians(as_float("angle_deg", angle_deg))
    p = np.asarray(p_B, dtype=float)
    return np.column_stack([p[:, 0] * math.cos(a) + p[:, 2] * math.sin(a), p[:, 1]])


def view_distortion(
    paths_W: Sequence[FloatArray],
    strokes_W: Sequence[FloatArray],
    board: Board,
    angle_deg: float,
) -> ViewDistortion:
    """Distortion of the light paths against their strokes seen at ``angle_deg``.

    Parameters
    ----------
    paths_W
        Pen-on samples of each stroke's light path, world frame, each (K, 3), m.
    strokes_W
        The intended strokes, world frame, each (J, 3), m, J >= 2, one per path.
    board
        The plane the strokes are drawn on.
    angle_deg
        View about the board's vertical axis, degrees (0: from the front).

    Returns
    -------
    ViewDistortion
    """
    if len(paths_W) != len(strokes_W) or not paths_W:
        raise InputError(
            f"paths_W: got {len(paths_W)} paths for {len(strokes_W)} strokes, expected one "
            "per stroke and at least one"
        )
    gaps = []
    for path, stroke in zip(paths_W, strokes_W, strict=True):
        image = project(board.to_board(path), angle_deg)
        intended = project(board.to_board(stroke), angle_deg)
        gaps.append(polyline_distance(image, intended))
    every = np.concatenate(gaps)
    return ViewDistortion(float(angle_deg), float(every.max()), float(np.sqrt(np.mean(every**2))))


def mission_distortion(
    mission: Mission,
    angles_deg: Sequence[float] = VIEW_ANGLES_DEG,
    samples_per_stroke: int = 400,
) -> tuple[ViewDistortion, ...]:
    """:func:`view_distortion` of a writing mission's pen-down path at each of ``angles_deg``."""
    paths = [mission.tip(np.linspace(t0, t1, samples_per_stroke)) for t0, t1 in mission.pen_windows]
    strokes = list(mission.strokes_world)
    return tuple(view_distortion(paths, strokes, mission.board, a) for a in angles_deg)
