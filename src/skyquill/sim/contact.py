"""The writing board: a compliant contact for the brush tip, and the ink it leaves.

Paper 000's brush rides on a linear bearing, so pressing it into the board
moves the bearing rather than the vehicle: the normal force on the vehicle is
a soft spring-damper, and friction along the board is small but not zero.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skyquill.validation import FloatArray, as_float


@dataclass(frozen=True)
class Board:
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
    """

    height_m: float
    stiffness_n_per_m: float = 200.0
    damping_ns_per_m: float = 5.0
    friction: float = 0.2
    enabled: bool = True

    def __post_init__(self) -> None:
        as_float("height_m", self.height_m)
        as_float("stiffness_n_per_m", self.stiffness_n_per_m, positive=True)
        as_float("damping_ns_per_m", self.damping_ns_per_m, nonneg=True)
        as_float("friction", self.friction, nonneg=True)

    def force(self, tip: FloatArray, tip_velocity: FloatArray) -> tuple[FloatArray, bool]:
        """Force on the vehicle (3,), N, and whether the tip touches.

        Friction is regularised below 1 mm/s so that it does not chatter.
        """
        depth = self.height_m - float(tip[2])
        if depth <= 0.0:
            return np.zeros(3), False
        if not self.enabled:
            return np.zeros(3), True
        normal = max(0.0, self.stiffness_n_per_m * depth - self.damping_ns_per_m * tip_velocity[2])
        slide = np.array([tip_velocity[0], tip_velocity[1], 0.0])
        speed = float(np.hypot(slide[0], slide[1]))
        friction = -self.friction * normal * slide / max(speed, 1e-3)
        return np.array([friction[0], friction[1], normal]), True
