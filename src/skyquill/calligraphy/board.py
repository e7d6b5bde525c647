"""Writing surfaces: where the strokes go in the world, and which way is "up" off them.

A board maps 2-D stroke coordinates (metres, y up, origin at the bottom-left of
the character) to 3-D brush-tip positions in the world frame (z up), and says
how to lift the brush off it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from skyquill.errors import InputError
from skyquill.validation import FloatArray, as_array, as_float

#: Highest lift accepted, m: the brush only has to clear the surface (default
#: 5 cm), every lift is flown twice per stroke and sampled every centimetre,
#: and a lift of metres is a unit error (1000 once hung the planner).
MAX_LIFT_M = 1.0


@dataclass(frozen=True)
class Board:
    """A flat writing surface.

    Attributes
    ----------
    kind
        ``"horizontal"``: a table-like board at height ``height_m`` (paper
        000's set-up: the brush hangs below the vehicle and writes downwards);
        ``"wall"``: a vertical wall, the plane ``y = origin[1]``, written on
        from ``-y``.
    origin
        World position (3,) of the character box's bottom-left corner, m.
    lift_m
        How far the brush leaves the surface between strokes, m, in
        ``(0, MAX_LIFT_M]``.
    """

    kind: Literal["horizontal", "wall"] = "horizontal"
    origin: FloatArray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    lift_m: float = 0.05

    def __post_init__(self) -> None:
        if self.kind not in ("horizontal", "wall"):
            raise InputError(f"board kind: got {self.kind!r}, expected 'horizontal' or 'wall'")
        object.__setattr__(self, "origin", as_array("board origin", self.origin, shape=(3,)))
        if as_float("lift_m", self.lift_m, positive=True) > MAX_LIFT_M:
            raise InputError(
                f"lift_m: got {self.lift_m:g} m, expected at most {MAX_LIFT_M:g} m (the brush "
                "only clears the surface between strokes)"
            )

    @property
    def normal(self) -> FloatArray:
        """Unit vector from the surface towards the vehicle's side (3,)."""
        return (
            np.array([0.0, 0.0, 1.0]) if self.kind == "horizontal" else np.array([0.0, -1.0, 0.0])
        )

    def to_world(self, uv: FloatArray) -> FloatArray:
        """Stroke coordinates (K, 2), m, to tip positions on the surface (K, 3), m."""
        uv = np.asarray(uv, dtype=float)
        if self.kind == "horizontal":
            return self.origin + np.column_stack([uv[:, 0], uv[:, 1], np.zeros(len(uv))])
        return self.origin + np.column_stack([uv[:, 0], np.zeros(len(uv)), uv[:, 1]])

    def to_board(self, p: FloatArray) -> FloatArray:
        """World points (K, 3) to (u, v, height above the surface) (K, 3)."""
        q = np.asarray(p, dtype=float) - self.origin
        if self.kind == "horizontal":
            return q
        return np.column_stack([q[:, 0], q[:, 2], -q[:, 1]])
