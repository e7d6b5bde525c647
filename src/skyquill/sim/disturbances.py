"""Disturbances: wind (constant plus gusts), measurement noise and latency.

Randomness comes only from the ``np.random.Generator`` handed to
:func:`skyquill.sim.simulate`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from skyquill.validation import FloatArray, as_array, as_float


@dataclass(frozen=True)
class Disturbances:
    """What the world does to the flight.

    Attributes
    ----------
    wind_mps
        Constant wind velocity, world frame, shape (3,), m/s.
    gust_std_mps
        Standard deviation of the gust velocity per axis, m/s: a first-order
        Gauss-Markov process (the low-frequency part of a Dryden model).
    gust_time_constant_s
        Correlation time of the gusts, s.
    position_noise_m
        Standard deviation of the position measurement per axis, m
        (motion capture: about 1e-3).
    velocity_noise_mps
        Standard deviation of the velocity estimate per axis, m/s.
    latency_s
        Age of the measurement the controller sees, s (rounded to steps).
    """

    wind_mps: FloatArray = field(default_factory=lambda: np.zeros(3))
    gust_std_mps: float = 0.0
    gust_time_constant_s: float = 1.0
    position_noise_m: float = 0.0
    velocity_noise_mps: float = 0.0
    latency_s: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "wind_mps", as_array("wind_mps", self.wind_mps, shape=(3,)))
        for name in ("gust_std_mps", "position_noise_m", "velocity_noise_mps", "latency_s"):
            as_float(name, getattr(self, name), nonneg=True)
        as_float("gust_time_constant_s", self.gust_time_constant_s, positive=True)


class WindField:
    """Wind velocity over time: constant plus an Ornstein-Uhlenbeck gust per axis."""

    def __init__(self, disturbances: Disturbances, dt: float, rng: np.random.Generator) -> None:
        self.mean = disturbances.wind_mps
        self.gust = np.zeros(3)
        decay = math.exp(-dt / disturbances.gust_time_constant_s)
        self.decay = decay
        self.kick = disturbances.gust_std_mps * math.sqrt(1.0 - decay**2)
        self.rng = rng

    def step(self) -> FloatArray:
        """Advance one step; the wind velocity (3,), m/s."""
        if self.kick > 0.0:
            self.gust = self.decay * self.gust + self.kick * self.rng.standard_normal(3)
        return np.asarray(self.mean + self.gust)
