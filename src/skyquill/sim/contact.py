"""The writing board: a compliant contact for the brush tip, and the ink it leaves.

Paper 000's brush rides on a linear bearing, so pressing it into the board
moves the bearing rather than the vehicle: the normal force on the vehicle is
a soft spring-damper, and friction along the board is small but not zero.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skyquill.errors import InputError
from skyquill.validation import FloatArray, as_float


@dataclass(frozen=True)
class ContactBoard:
    """A horizontal board at ``height_m`` (the paper's set-up).

    Attributes
    ----------
    height_m
        Board surface height, world z, m.
    stiffness_n_per_m
        Normal stiffness of brush + bearing, N/m.
    damping_ns_per_m
        Normal damping, N s/m (only pushes, never pulls).
    friction
        Coulomb coefficient along the surface.
    enabled
        ``False`` keeps the ink but applies no force (the contact switched off).
    thickness_m
        The board is a slab this thick: a tip deeper than that is under the
        board, not pressing on it (a drone taking off from the floor below a
        table does not touch it).
    extent
        ``(x_min, x_max, y_min, y_max)`` of the surface, m; ``None``: unbounded.
    """

    height_m: float
    stiffness_n_per_m: float = 200.0
    damping_ns_per_m: float = 5.0
    friction: float = 0.2
    enabled: bool = True
    thickness_m: float = 0.05
    extent: tuple[float, float, float, float] | None = None

    def __post_init__(self) -> None:
        as_float("height_m", self.height_m)
        as_float("stiffness_n_per_m", self.stiffness_n_per_m, positive=True)
        as_float("damping_ns_per_m", self.damping_ns_per_m, nonneg=True)
        as_float("friction", self.friction, nonneg=True)
        as_float("thickness_m", self.thickness_m, positive=True)
        if self.extent is not None:
            x0, x1, y0, y1 = (as_float("extent", v) for v in self.extent)
            if not (x0 < x1 and y0 < y1):
                raise InputError(
                    f"extent: got {self.extent!r}, expected (x_min, x_max, y_min, y_max) "
                    "with min < max"
                )

    def force(self, tip: FloatArray, tip_velocity: FloatArray) -> tuple[FloatArray, bool]:
        """Force on the vehicle (3,), N, and whether the tip touches.

        Friction is regularised below 1 mm/s so that it does not chatter.
        """
        depth = self.height_m - float(tip[2])
        if not 0.0 < depth <= self.thickness_m or not self._over(tip):
            return np.zeros(3), False
        if not self.enabled:
            return np.zeros(3), True
        normal = max(0.0, self.stiffness_n_per_m * depth - self.damping_ns_per_m * tip_velocity[2])
        slide = np.array([tip_velocity[0], tip_velocity[1], 0.0])
        speed = float(np.hypot(slide[0], slide[1]))
        friction = -self.friction * normal * slide / max(speed, 1e-3)
        return np.array([friction[0], friction[1], normal]), True

    def _over(self, tip: FloatArray) -> bool:
        if self.extent is None:
            return True
        x0, x1, y0, y1 = self.extent
        return bool(x0 <= tip[0] <= x1 and y0 <= tip[1] <= y1)
