"""The quadrotor model: translational dynamics under collective thrust and tilt.

Frames: world ``W`` is z-up; the body z axis ``b3`` is the thrust direction.
Heading is constant (paper 000 §5: the brush does not need yaw), so the
attitude that matters is ``b3`` alone.

Model, per control step ``dt`` (zero-order hold on the commands):

* inner loops as first-order lags: ``b3`` towards the commanded direction at
  the attitude bandwidth (paper 000: 25 rad/s), thrust towards the commanded
  thrust at the motor bandwidth;
* ``m a = T b3 - m g e_z - m c_d (v - v_wind) + F_contact``;
* exact for piecewise-constant acceleration: ``v += a dt``,
  ``p += (v_old + v_new) dt / 2``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from skyquill.errors import InputError
from skyquill.validation import FloatArray, as_float

GRAVITY = 9.81  # m/s^2

Conversion = Literal["exact", "linear"]


@dataclass(frozen=True)
class Quadrotor:
    """Vehicle parameters (SI units). Defaults are close to paper 000's vehicle.

    Attributes
    ----------
    mass_kg
        About 1 kg.
    arm_m
        Motor-to-centre distance; 0.2 m is a 40 cm frame (10-inch props).
    thrust_to_weight
        Maximum collective thrust over weight.
    min_thrust_fraction
        Minimum thrust as a fraction of hover thrust (motors idle, not off).
    max_tilt_rad
        Tilt limit of the attitude command (35 deg).
    attitude_bandwidth
        Closed inner (attitude) loop bandwidth, rad/s (paper 000: 25).
    thrust_bandwidth
        Motor/thrust response bandwidth, rad/s.
    drag_per_mass
        Linear drag coefficient over mass, 1/s: ``F = -m c_d (v - v_wind)``.
    brush_length_m
        Distance from the centre of mass to the brush tip along ``-b3``.
    """

    mass_kg: float = 1.0
    arm_m: float = 0.2
    thrust_to_weight: float = 2.5
    min_thrust_fraction: float = 0.1
    max_tilt_rad: float = math.radians(35.0)
    attitude_bandwidth: float = 25.0
    thrust_bandwidth: float = 40.0
    drag_per_mass: float = 0.3
    brush_length_m: float = 0.3

    def __post_init__(self) -> None:
        for name in ("mass_kg", "arm_m", "attitude_bandwidth", "thrust_bandwidth"):
            as_float(name, getattr(self, name), positive=True)
        for name in ("drag_per_mass", "brush_length_m", "min_thrust_fraction"):
            as_float(name, getattr(self, name), nonneg=True)
        if as_float("thrust_to_weight", self.thrust_to_weight, positive=True) <= 1.0:
            raise InputError(
                f"thrust_to_weight: got {self.thrust_to_weight:g}, expected > 1 (it must hover)"
            )
        tilt = as_float("max_tilt_rad", self.max_tilt_rad, positive=True)
        if tilt >= math.pi / 2:
            raise InputError(f"max_tilt_rad: got {tilt:g}, expected < pi/2")

    @property
    def hover_thrust_n(self) -> float:
        """``m g``, N."""
        return self.mass_kg * GRAVITY

    @property
    def max_thrust_n(self) -> float:
        """Largest collective thrust, N."""
        return self.thrust_to_weight * self.hover_thrust_n

    @property
    def min_thrust_n(self) -> float:
        """Smallest collective thrust, N."""
        return self.min_thrust_fraction * self.hover_thrust_n


@dataclass
class ThrustCommand:
    """Collective thrust (N) and thrust direction (unit (3,)), with what was cut."""

    thrust: float
    direction: FloatArray
    tilt: float
    saturated: tuple[str, ...]


def thrust_command(
    vehicle: Quadrotor, a_cmd: FloatArray, conversion: Conversion = "exact"
) -> ThrustCommand:
    """Turn a kinematic acceleration command into thrust and attitude.

    ``"exact"`` (default): the thrust vector ``m (a_cmd + g e_z)``, its norm
    and direction; exact for any tilt. ``"linear"``: paper 000's ``G_c``
    (eq. 1-2), a small-angle map -- roll ``= a_y / g``, pitch ``= -a_x / g``
    (the 0.1019 = 1/g entries) and throttle proportional to ``g + a_z``; it
    drops the ``1/cos(tilt)`` the thrust needs to hold altitude while tilted,
    so the vehicle sags in z during aggressive horizontal motion. The exact
    map costs nothing more here, so it is the default; the linear one is kept
    to reproduce the paper.

    The tilt is limited to ``max_tilt_rad`` (keeping the vertical component)
    and the thrust to ``[min_thrust, max_thrust]``; each cut is reported in
    ``saturated``.
    """
    m, g = vehicle.mass_kg, GRAVITY
    saturated: list[str] = []
    if conversion == "exact":
        f = m * np.array([a_cmd[0], a_cmd[1], a_cmd[2] + g])
        if f[2] <= 1e-9:  # asks to accelerate down faster than gravity: no upward thrust
            f[2] = 1e-9
            saturated.append("thrust_min")
        thrust = float(np.linalg.norm(f))
        direction = f / thrust
    elif conversion == "linear":
        # G_c of paper 000 eq. (2) maps body accelerations in PX4's NED body
        # frame to roll/pitch with gain 1/g = 0.1019; in our z-up frame with
        # yaw 0 that is pitch = a_x / g, roll = -a_y / g, b3 = Ry(pitch) Rx(roll) e_z.
        pitch, roll = float(a_cmd[0]) / g, -float(a_cmd[1]) / g
        direction = np.array(
            [math.cos(roll) * math.sin(pitch), -math.sin(roll), math.cos(roll) * math.cos(pitch)]
        )
        thrust = m * (g + float(a_cmd[2]))
    else:
        raise InputError(f"conversion: got {conversion!r}, expected 'exact' or 'linear'")
    tilt = math.acos(max(-1.0, min(1.0, float(direction[2]))))
    if tilt > vehicle.max_tilt_rad:
        horizontal = math.hypot(direction[0], direction[1])
        scale = math.tan(vehicle.max_tilt_rad) / (horizontal / direction[2])
        direction = np.array([direction[0] * scale, direction[1] * scale, direction[2]])
        direction /= np.linalg.norm(direction)
        tilt = vehicle.max_tilt_rad
        saturated.append("tilt")
    if thrust > vehicle.max_thrust_n:
        thrust = vehicle.max_thrust_n
        saturated.append("thrust_max")
    elif thrust < vehicle.min_thrust_n:
        thrust = vehicle.min_thrust_n
        saturated.append("thrust_min")
    return ThrustCommand(thrust, direction, tilt, tuple(saturated))
