"""Fly a trajectory in closed loop: :func:`simulate`."""

from __future__ import annotations

import math
import time
from collections import deque

import numpy as np

from skyquill.errors import InputError
from skyquill.sim.bounds import check_rate, check_steps
from skyquill.sim.contact import ContactBoard
from skyquill.sim.controllers import OuterLoop, RPTController
from skyquill.sim.disturbances import Disturbances, WindField
from skyquill.sim.result import Flight
from skyquill.sim.vehicle import GRAVITY, Conversion, Quadrotor, thrust_command
from skyquill.trajectory import Trajectory, sample_times
from skyquill.validation import FloatArray

E_Z = np.array([0.0, 0.0, 1.0])


def _reference(traj: Trajectory, t: FloatArray) -> tuple[FloatArray, ...]:
    """Position, velocity, acceleration and jerk references (N, 3); 2-D plans fly at z = 0."""

    def as3(x: FloatArray) -> FloatArray:
        return x if x.shape[1] == 3 else np.column_stack([x, np.zeros(x.shape[0])])

    if traj.dim not in (2, 3):
        raise InputError(f"trajectory: got {traj.dim} axes, expected 2 or 3")
    return tuple(as3(traj.evaluate(t, order)) for order in range(4))


def simulate(
    trajectory: Trajectory,
    vehicle: Quadrotor | None = None,
    controller: OuterLoop | None = None,
    disturbances: Disturbances | None = None,
    rng: np.random.Generator | None = None,
    *,
    rate_hz: float = 500.0,
    board: ContactBoard | None = None,
    conversion: Conversion = "exact",
) -> Flight:
    """Fly ``trajectory`` with ``controller`` on ``vehicle`` and record everything.

    Parameters
    ----------
    trajectory
        Reference (position, velocity and acceleration are fed forward), z-up.
    vehicle
        :class:`Quadrotor` (default parameters if ``None``).
    controller
        Outer loop; a fresh :class:`RPTController` if ``None``. It is reset first.
    disturbances
        Wind, gusts, measurement noise and latency (none if ``None``).
    rng
        The only source of randomness; required when gusts or noise are set.
    rate_hz
        Control and integration rate, Hz, within
        [:data:`~skyquill.sim.bounds.MIN_RATE_HZ`, :data:`~skyquill.sim.bounds.MAX_RATE_HZ`].
    board
        Writing board; the brush-tip trace in contact is returned as ``ink``.
    conversion
        Acceleration-to-thrust map: ``"exact"`` or paper 000's ``"linear"`` G_c.

    Returns
    -------
    Flight
        Time series, errors and saturation counts.

    Raises
    ------
    InputError
        A rate out of range, or more than :data:`~skyquill.sim.bounds.MAX_SIM_STEPS`
        steps (refused before anything is allocated).
    """
    vehicle = vehicle or Quadrotor()
    controller = controller or RPTController()
    dist = disturbances or Disturbances()
    rate = check_rate(rate_hz)
    check_steps(trajectory.duration, rate)  # before any per-step array exists
    random = dist.gust_std_mps > 0 or dist.position_noise_m > 0 or dist.velocity_noise_mps > 0
    if random and not isinstance(rng, np.random.Generator):
        raise InputError(
            f"rng: got {rng!r}, expected a numpy.random.Generator when gusts or noise are set"
        )
    generator = rng if rng is not None else np.random.default_rng(0)  # unused without noise
    t = sample_times(trajectory.duration, rate)
    p_ref, v_ref, a_ref, j_ref = _reference(trajectory, t)
    return _fly(
        t,
        (p_ref, v_ref, a_ref, j_ref),
        vehicle,
        controller,
        dist,
        rng=generator,
        board=board,
        conversion=conversion,
    )


def _fly(
    t: FloatArray,
    refs: tuple[FloatArray, ...],
    vehicle: Quadrotor,
    controller: OuterLoop,
    dist: Disturbances,
    *,
    rng: np.random.Generator,
    board: ContactBoard | None,
    conversion: Conversion,
) -> Flight:
    start = time.perf_counter()
    p_ref, v_ref, a_ref, j_ref = refs
    n = t.size
    dt = float(t[1] - t[0]) if n > 1 else 1e-3
    m, c_d, length = vehicle.mass_kg, vehicle.drag_per_mass, vehicle.brush_length_m
    lag_thrust = 1.0 - math.exp(-vehicle.thrust_bandwidth * dt)
    lag_att = 1.0 - math.exp(-vehicle.attitude_bandwidth * dt)
    wind = WindField(dist, dt, rng)
    delay = round(dist.latency_s / dt)
    history: deque[tuple[FloatArray, FloatArray]] = deque(maxlen=delay + 1)
    controller.reset()

    p, v = p_ref[0].copy(), np.zeros(3)
    thrust, b3 = vehicle.hover_thrust_n, E_Z.copy()
    out_p, out_v, out_a = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3))
    out_thrust, out_tilt = np.empty(n), np.empty(n)
    saturations = {"thrust_max": 0, "thrust_min": 0, "tilt": 0}
    ink: list[FloatArray] = []
    stroke: list[FloatArray] = []
    for i in range(n):
        out_p[i], out_v[i] = p, v
        history.append(
            (
                p + dist.position_noise_m * rng.standard_normal(3) if dist.position_noise_m else p,
                v + dist.velocity_noise_mps * rng.standard_normal(3)
                if dist.velocity_noise_mps
                else v,
            )
        )
        p_meas, v_meas = history[0]
        a_cmd = controller.acceleration(dt, p_ref[i], v_ref[i], a_ref[i], p_meas, v_meas, j_ref[i])
        cmd = thrust_command(vehicle, a_cmd, conversion)
        for name in cmd.saturated:
            saturations[name] += 1
        out_a[i], out_thrust[i], out_tilt[i] = a_cmd, cmd.thrust, cmd.tilt
        # Plant over one step, commands held.
        air = wind.step()
        thrust += lag_thrust * (cmd.thrust - thrust)
        b3 = b3 + lag_att * (cmd.direction - b3)
        b3 /= math.sqrt(b3 @ b3)
        force = thrust * b3
        if board is not None:
            tip = p - length * b3
            contact, touching = board.force(tip, v)
            force = force + contact
            if touching:
                stroke.append(tip)
            elif stroke:
                ink.append(np.array(stroke))
                stroke = []
        acc = force / m - GRAVITY * E_Z - c_d * (v - air)
        v_new = v + acc * dt
        p = p + 0.5 * (v + v_new) * dt
        v = v_new
    if stroke:
        ink.append(np.array(stroke))
    return Flight(
        t=t,
        p_ref=p_ref,
        v_ref=v_ref,
        p=out_p,
        v=out_v,
        a_cmd=out_a,
        thrust=out_thrust,
        tilt=out_tilt,
        saturations=saturations,
        controller=controller.name,
        sim="skyquill",
        wall_time_s=time.perf_counter() - start,
        ink=tuple(ink),
    )
