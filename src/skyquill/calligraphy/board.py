"""Writing surfaces: where the strokes go in the world, and which way is "up" off them.

A board maps 2-D stroke coordinates (metres, y up, origin at the bottom-left of
the character) to 3-D positions in the world frame (z up), and says how to
leave it between strokes. A board is a plane with an origin and three
orthonormal axes, the rows of :attr:`Board.axes` (world frame): ``e_u`` (the writing's x),
``e_v`` (the writing's y) and the normal ``n = e_u x e_v`` towards the
vehicle's (or the audience's) side.

* ``"horizontal"``: a table at ``origin[2]``, ``e_u = x``, ``e_v = y``,
  ``n = z`` (paper 000: the brush hangs below the vehicle);
* ``"wall"``: the vertical plane ``y = origin[1]``, ``e_u = x``, ``e_v = z``,
  ``n = -y``, written on from ``-y`` with a brush held ahead;
* ``"sky"``: light painting, a plane in the air with any pose, no contact.
  Vertical and facing the audience at ``-y`` by default (like a wall); turned
  by ``yaw_deg`` about the world z and leaning back from vertical by
  ``tilt_deg`` (its top away from the audience). The pen is the vehicle's
  light, so the tip is the vehicle's position.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from skyquill.errors import InputError
from skyquill.validation import FloatArray, as_array, as_float

#: Highest lift accepted, m: the brush only has to clear the surface (default
#: 5 cm), every lift is flown twice per stroke and sampled every centimetre,
#: and a lift of metres is a unit error (1000 once hung the planner).
MAX_LIFT_M = 1.0
#: Steepest lean of a sky board from vertical, degrees (either way). At 90 the
#: plane is horizontal: the audience in front sees it edge-on, and its "up"
#: direction no longer rises, so the bottom-edge height means nothing.
MAX_TILT_DEG = 80.0
#: The board kinds.
BOARD_KINDS = ("horizontal", "wall", "sky")

BoardKind = Literal["horizontal", "wall", "sky"]


@dataclass(frozen=True)
class Board:
    """A flat writing surface.

    Attributes
    ----------
    kind
        ``"horizontal"``, ``"wall"`` or ``"sky"`` (module docstring).
    origin
        World position (3,) of the character box's bottom-left corner, m.
    lift_m
        How far the pen leaves the surface between strokes, m: in
        ``(0, MAX_LIFT_M]`` for a contact board; ``[0, MAX_LIFT_M]`` for a sky
        board, where 0 (:func:`sky_board`'s default) keeps the transits in the
        plane.
    yaw_deg
        Sky board: turn about the world z, degrees in ``[-180, 180]``;
        positive turns its face from ``-y`` towards ``+x``. 0 otherwise.
    tilt_deg
        Sky board: lean back from vertical, degrees within
        ``±MAX_TILT_DEG`` (negative leans towards the audience). 0 otherwise.
    """

    kind: BoardKind = "horizontal"
    origin: FloatArray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    lift_m: float = 0.05
    yaw_deg: float = 0.0
    tilt_deg: float = 0.0

    def __post_init__(self) -> None:
        if self.kind not in BOARD_KINDS:
            raise InputError(
                f"board kind: got {self.kind!r}, expected 'horizontal', 'wall' or 'sky'"
            )
        object.__setattr__(self, "origin", as_array("board origin", self.origin, shape=(3,)))
        lift = as_float("lift_m", self.lift_m, nonneg=True)
        if lift == 0.0 and self.has_contact:
            raise InputError(
                f"lift_m: got 0 m on a {self.kind} board, expected > 0 (the brush must "
                "leave the surface between strokes)"
            )
        if lift > MAX_LIFT_M:
            raise InputError(
                f"lift_m: got {self.lift_m:g} m, expected at most {MAX_LIFT_M:g} m (the brush "
                "only clears the surface between strokes)"
            )
        yaw = as_float("yaw_deg", self.yaw_deg)
        tilt = as_float("tilt_deg", self.tilt_deg)
        if self.kind != "sky" and (yaw != 0.0 or tilt != 0.0):
            raise InputError(
                f"yaw_deg, tilt_deg: got {yaw:g}, {tilt:g} on a {self.kind} board, expected 0 "
                "(only a sky board takes a pose)"
            )
        if not -180.0 <= yaw <= 180.0:
            raise InputError(f"yaw_deg: got {yaw:g}, expected -180 to 180 degrees")
        if abs(tilt) > MAX_TILT_DEG:
            raise InputError(
                f"tilt_deg: got {tilt:g}, expected -{MAX_TILT_DEG:g} to {MAX_TILT_DEG:g} "
                "degrees from vertical"
            )

    @property
    def has_contact(self) -> bool:
        """Whether a brush touches the board (not a sky board: its pen is the light)."""
        return self.kind != "sky"

    @property
    def axes(self) -> FloatArray:
        """Rows ``e_u``, ``e_v``, ``n`` (3, 3), world frame: the writing's x and y, the normal."""
        if self.kind == "horizontal":
            return np.eye(3)
        yaw, tilt = math.radians(self.yaw_deg), math.radians(self.tilt_deg)
        e_u = np.array([math.cos(yaw), math.sin(yaw), 0.0])
        facing = np.array([math.sin(yaw), -math.cos(yaw), 0.0])  # horizontal, to the audience
        # Leaning back moves the top away from the audience: "up" tips by -facing.
        e_v = math.cos(tilt) * np.array([0.0, 0.0, 1.0]) - math.sin(tilt) * facing
        return np.vstack([e_u, e_v, np.cross(e_u, e_v)])

    @property
    def normal(self) -> FloatArray:
        """Unit vector from the surface towards the vehicle's side (3,)."""
        return np.asarray(self.axes[2])

    def to_world(self, uv: FloatArray) -> FloatArray:
        """Stroke coordinates (K, 2), m, to tip positions on the surface (K, 3), m."""
        uv = np.asarray(uv, dtype=float)
        return np.asarray(self.origin + uv @ self.axes[:2])

    def to_board(self, p: FloatArray) -> FloatArray:
        """World points (K, 3) to (u, v, height above the surface) (K, 3)."""
        return np.asarray((np.asarray(p, dtype=float) - self.origin) @ self.axes.T)


def sky_board(
    origin: FloatArray, yaw_deg: float = 0.0, tilt_deg: float = 0.0, lift_m: float = 0.0
) -> Board:
    """A sky board (light painting) at ``origin`` (3,), m, with its pose, degrees.

    ``lift_m`` defaults to 0: between strokes the light is off and nothing
    needs clearing, so the transits stay in the plane. That keeps the whole
    drawing part of the flight on the plane (the plane cost holds all of it),
    never brings a drone towards the audience, and keeps neighbouring boards
    on one plane as far apart as the layout put them.
    """
    return Board("sky", origin, lift_m, yaw_deg, tilt_deg)
