"""Cross-check of the reduced contact model against the closed-loop simulator.

:class:`~skyquill.painting.mission.ContactModel` says when the IMU sees a touch (first sample
with ``|a_y| > 0.25 g``) and how far the bumper is squeezed by then, from a damped spring alone.
Here the same approach is flown by :func:`skyquill.sim.simulate` -- thrust and attitude lags,
drag, the RPT outer loop still pulling the vehicle towards a reference that runs on into the
wall -- against the same bumper on a vertical wall, and the IMU is read from the simulated
velocity. Agreement of detection delay and squeeze (to a few milliseconds and a millimetre)
is what justifies leaving the simulator out of the per-dot mission loop.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from skyquill.painting.mission import ContactModel, G
from skyquill.sim.contact import ContactBoard
from skyquill.validation import FloatArray


@dataclass(frozen=True)
class WallBumper(ContactBoard):
    """A vertical wall ``y = wall_y_m`` with a spring-damper bumper, as a simulator contact.

    It reuses :class:`~skyquill.sim.contact.ContactBoard`'s stiffness and damping fields and
    replaces the horizontal board's force by one along ``-y`` (only pushing, never pulling).
    """

    wall_y_m: float = 0.0

    def force(self, tip: FloatArray, tip_velocity: FloatArray) -> tuple[FloatArray, bool]:
        """Force on the vehicle (3,), N, and whether the tool touches the wall."""
        depth = float(tip[1]) - self.wall_y_m
        if depth <= 0.0:
            return np.zeros(3), False
        normal = max(
            0.0, self.stiffness_n_per_m * depth + self.damping_ns_per_m * float(tip_velocity[1])
        )
        return np.array([0.0, -normal, 0.0]), True


def simulated_touch(
    model: ContactModel | None = None,
    *,
    approach_speed_mps: float = 0.2,
    rate_hz: float = 1000.0,
) -> dict[str, Any]:
    """Fly one approach into the wall with the simulator; compare with ``model.detect``.

    The reference runs at ``approach_speed_mps`` along ``+y`` from 0.3 m in front of the wall
    to 0.2 m behind it; the wall is at ``y = 0``; the tool is at the centre of mass. IMU noise
    is left out on both sides so that the comparison is exact and deterministic.

    Returns
    -------
    dict
        ``touch_speed_mps`` (speed at first contact), and for ``sim`` and ``model``:
        ``delay_s`` (touch to detection) and ``squeeze_m`` (bumper compression at detection).
    """
    from skyquill.sim import RPTController, simulate
    from skyquill.sim.vehicle import Quadrotor
    from skyquill.trajectory import SplineTrajectory

    model = model or ContactModel()
    zeta, k, m = model.damping_ratio, model.stiffness_n_per_m, model.mass_kg
    bumper = WallBumper(
        height_m=0.0,
        stiffness_n_per_m=k,
        damping_ns_per_m=2.0 * zeta * math.sqrt(k * m),
        wall_y_m=0.0,
    )
    n_ctrl, degree, y0, y1 = 40, 3, -0.3, 0.2
    ctrl = np.column_stack(
        [np.zeros(n_ctrl), np.linspace(y0, y1, n_ctrl), np.ones(n_ctrl)]
    )  # fmt: skip
    # interior speed of a clamped uniform spline with equally spaced control points
    duration = (y1 - y0) * (n_ctrl - degree) / ((n_ctrl - 1) * approach_speed_mps)
    flight = simulate(
        SplineTrajectory(ctrl, degree, duration),
        Quadrotor(mass_kg=m, brush_length_m=0.0),
        RPTController(),
        rate_hz=rate_hz,
        board=bumper,
    )
    touching = np.flatnonzero(flight.p[:, 1] > 0.0)
    first = int(touching[0])
    dt = float(flight.t[1] - flight.t[0])
    a_y = np.append(np.diff(flight.v[:, 1]) / dt, 0.0)  # the acceleration applied at each step
    step = max(1, round(rate_hz / model.imu_rate_hz))
    left = np.flatnonzero(flight.p[first:, 1] <= 0.0)  # the first bounce ends the episode
    end = first + int(left[0]) if left.size else flight.t.size
    samples = np.arange(first, end, step)
    over = samples[np.abs(a_y[samples]) > model.threshold_g * G]
    speed = float(flight.v[first, 1])
    quiet = ContactModel(
        mass_kg=m,
        stiffness_n_per_m=k,
        damping_ratio=zeta,
        imu_rate_hz=model.imu_rate_hz,
        imu_noise_g=0.0,
        threshold_g=model.threshold_g,
    )
    # same IMU sampling as above: the first sample at the first simulator step in contact
    phase = float(flight.p[first, 1]) / max(speed, 1e-9)
    detected, delay, squeeze = quiet.detect(speed, 1.0, np.random.default_rng(0), phase_s=phase)
    if detected:
        delay -= phase  # both delays counted from that first sample
    return {
        "touch_speed_mps": speed,
        "sim": {
            "detected": bool(over.size),
            "delay_s": float(flight.t[over[0]] - flight.t[first]) if over.size else 0.0,
            "squeeze_m": float(flight.p[over[0], 1]) if over.size else 0.0,
        },
        "model": {"detected": detected, "delay_s": delay, "squeeze_m": squeeze},
    }
