"""Fly a skyquill trajectory in RotorPy, a full rigid-body multirotor simulator.

RotorPy (``pip install 'skyquill[rotorpy]'``) integrates the 6-DoF rigid body
with first-order motor dynamics, rotor drag, induced inflow and translational
lift. It is an *independent* check of skyquill's own simulator: a different
vehicle model, a different inner loop, and (optionally) its own geometric
SE(3) position controller.

What this adapter does, and the choices it makes:

* **Trajectory.** :class:`RotorPyTrajectory` presents a skyquill
  :class:`~skyquill.trajectory.Trajectory` as the flat outputs RotorPy asks
  for (``x, x_dot, x_ddot, x_dddot, x_ddddot`` (3,) in the world frame,
  ``yaw, yaw_dot, yaw_ddot``; see ``rotorpy/trajectories/hover_traj.py``).
  Time is clamped to ``[0, duration]`` -- RotorPy asks for ``update(np.inf)``
  to learn where the flight ends. A 2-D trajectory is flown in the horizontal
  plane ``z = hover_height_m`` (1 m by default). Yaw is held at 0: the brush
  needs no heading (paper 000 §5).
* **Vehicle.** ``"px4_sihsim_quadx"`` (default): RotorPy's PX4 SIH quad-X
  preset, 1.0 kg, 0.17 m arms, thrust-to-weight 2.04, the preset closest to
  skyquill's ~1 kg vehicle. That preset sets no attitude gains, and RotorPy's
  fall-backs for its ``cmd_acc`` inner loop (``kp_att = 3000``,
  ``kd_att = 360`` 1/s^2 and 1/s) are unstable at a 100 Hz zero-order hold
  (``kd_att * dt = 3.6 > 2``: the motors chatter between their limits at
  almost every step and the vehicle drifts by metres), so the
  Hummingbird's gains are filled in (``kp_att = 544``, ``kd_att = 46.64``:
  a critically damped attitude loop at 23 rad/s, the 25 rad/s of paper 000;
  ``SE3Control`` reads the same two gains).
  ``"hummingbird"``: RotorPy's default vehicle (AscTec Hummingbird, 0.5 kg,
  thrust-to-weight 10, with its full aerodynamic model). Aerodynamics are on
  (RotorPy's default), wind off, ground contact off.
* **Controllers.** ``"se3"``: RotorPy's own ``SE3Control`` (Lee et al. 2010)
  commanding motor speeds. An :class:`~skyquill.sim.controllers.OuterLoop`
  (RPT, cascade PID) runs through RotorPy's ``cmd_acc`` control abstraction,
  see :class:`RotorPyOuterLoop`. Its feed-forward is the caller's to match
  to this vehicle: :class:`~skyquill.sim.controllers.RPTController`'s
  defaults compensate skyquill's own vehicle (1/25 s lag, 0.3 1/s linear
  drag); the PX4 preset's attitude loop lags about ``2 / sqrt(kp_att)``
  = 0.086 s and it has only quadratic frame drag. On a 0.5 m writing circle
  the RMSE is 5.4 cm with the defaults, 2.3 cm with the paper's law as
  printed (``lag_s=0, drag_per_mass=0``) and 0.7 cm with
  ``lag_s=0.086, drag_per_mass=0`` (``tests/sim/test_rotorpy_adapter.py``).
  :func:`matched_rpt` builds that matched RPT from a vehicle's parameters
  (``skyquill fly --sim rotorpy`` flies it as ``rpt``); on a 1 m circle at
  500 Hz it tracks to 1.2 mm where ``SE3Control`` gets 8.5 mm and the
  skyquill-tuned defaults 56 mm.
* **Sensing.** Controllers see the true state (``use_mocap=False``).
  RotorPy's default IMU and motion-capture models still draw noise from
  NumPy's *global* generator; its state is saved and restored around the run,
  so a call leaves no trace in it and flights are deterministic.
"""

from __future__ import annotations

import importlib
import logging
import math
import time
from collections.abc import Mapping
from typing import Any, Literal

import numpy as np
from scipy.spatial.transform import Rotation

from skyquill.errors import InputError, SolverError
from skyquill.sim.bounds import check_rate, check_steps
from skyquill.sim.controllers import OuterLoop, RPTAxisGains, RPTController
from skyquill.sim.result import Flight
from skyquill.trajectory import Trajectory
from skyquill.validation import FloatArray, as_float

log = logging.getLogger(__name__)

#: Height (m, world z up) at which a 2-D trajectory is flown.
HOVER_HEIGHT_M = 1.0

#: Attitude gains (1/s^2, 1/s) filled into a RotorPy preset that has none:
#: the Hummingbird preset's values (see the module docstring).
ATTITUDE_GAINS: dict[str, float] = {"kp_att": 544.0, "kd_att": 46.64}

#: z design parameters of :func:`matched_rpt`: the paper's, poles twice as fast
#: (``k_p`` 20 1/s^2, ``k_d`` 6 1/s, near ``SE3Control``'s 15 and 9). In
#: ``cmd_acc`` RotorPy projects the commanded thrust vector on the *actual* body
#: z axis, which lags the command while the vehicle tilts: a vertical-thrust
#: deficit the paper's z loop (2.1 rad/s) leaves as a 44 mm height error on the
#: CLI's spiral (13 mm with these).
MATCHED_Z = RPTAxisGains(epsilon=0.5, omega_n=2.089, zeta=0.66, k_i=0.23)

VehicleName = Literal["px4_sihsim_quadx", "hummingbird"]
_VEHICLE_MODULES: dict[str, str] = {
    "px4_sihsim_quadx": "rotorpy.vehicles.px4_sihsim_quadx_params",
    "hummingbird": "rotorpy.vehicles.hummingbird_params",
}

#: A RotorPy flat-output or control dictionary.
RotorPyDict = dict[str, Any]

_INSTALL_HINT = "RotorPy is not installed: pip install 'skyquill[rotorpy]'"


class RotorPyTrajectory:
    """A skyquill trajectory as a RotorPy trajectory object.

    Parameters
    ----------
    trajectory
        Any :class:`~skyquill.trajectory.Trajectory` with ``dim`` 2 or 3,
        positions in metres, world frame z up.
    hover_height_m
        World z (m) at which a 2-D trajectory is flown; ignored in 3-D.
    """

    def __init__(self, trajectory: Trajectory, hover_height_m: float = HOVER_HEIGHT_M) -> None:
        _check_trajectory(trajectory)
        self.trajectory = trajectory
        self.duration = float(trajectory.duration)
        self.hover_height_m = as_float("hover_height_m", hover_height_m)

    def derivatives(self, t: FloatArray, order: int) -> FloatArray:
        """The ``order``-th derivative in 3-D at times ``t`` (clamped to the duration).

        Parameters
        ----------
        t
            Times, shape (N,), s; values outside ``[0, duration]`` (``inf``
            included) are clamped to it.
        order
            0 for position (m), 1 velocity (m/s), 2 acceleration (m/s^2), ...

        Returns
        -------
        numpy.ndarray, shape (N, 3)
            World frame, z up. For a 2-D trajectory z is ``hover_height_m``
            (position) or 0 (derivatives).
        """
        times = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        values = np.asarray(self.trajectory.evaluate(times, order), dtype=float)
        if values.shape[1] == 3:
            return values
        z = np.full(times.size, self.hover_height_m if order == 0 else 0.0)
        return np.column_stack([values, z])

    def update(self, t: float) -> RotorPyDict:
        """RotorPy's flat outputs at time ``t`` s (clamped to ``[0, duration]``).

        Returns
        -------
        dict
            ``x`` (m), ``x_dot`` (m/s), ``x_ddot`` (m/s^2), ``x_dddot``
            (m/s^3), ``x_ddddot`` (m/s^4), each shape (3,), world frame z up;
            ``yaw`` (rad), ``yaw_dot`` (rad/s), ``yaw_ddot`` (rad/s^2), all 0.
        """
        times = np.array([min(max(float(t), 0.0), self.duration)])
        keys = ("x", "x_dot", "x_ddot", "x_dddot", "x_ddddot")
        flat: RotorPyDict = {k: self.derivatives(times, n)[0] for n, k in enumerate(keys)}
        flat.update(yaw=0.0, yaw_dot=0.0, yaw_ddot=0.0)
        return flat


class RotorPyOuterLoop:
    """A skyquill outer loop as a RotorPy controller, through ``cmd_acc``.

    RotorPy's ``cmd_acc`` is the *mass-normalised thrust vector* in the world
    frame, gravity included: ``Multirotor.get_cmd_motor_speeds`` takes
    ``F_des = control['cmd_acc'] * self.mass`` (``rotorpy/vehicles/
    multirotor.py`` line 454 in RotorPy 3.0.0), projects it on the body z
    axis for the collective thrust and points the body z axis along it (yaw
    reference ``[1, 0, 0]``), exactly the ``F_des / m`` of its SE3 controller,
    which contains ``+ g e_z``. So with the outer loop's kinematic command
    ``a_cmd`` (gravity excluded) this sends ``cmd_acc = a_cmd + g e_z``
    (``g`` = RotorPy's 9.81 m/s^2). The vehicle's drag is not compensated
    here: that is the outer loop's business (feed-forward, integral action).

    Parameters
    ----------
    loop
        The outer loop; stepped with ``dt`` = time since the previous call
        (0 at the first), the reference up to jerk and the true state.
    vehicle
        The ``rotorpy.vehicles.multirotor.Multirotor`` being flown (built with
        ``control_abstraction="cmd_acc"``); used to report the motor speeds,
        thrust and moment it will derive from the command.
    """

    def __init__(self, loop: OuterLoop, vehicle: Any) -> None:
        self.loop = loop
        self.vehicle = vehicle
        self._last_t: float | None = None

    def update(self, t: float, state: RotorPyDict, flat_output: RotorPyDict) -> RotorPyDict:
        """RotorPy's control dictionary for the present state.

        Parameters
        ----------
        t
            Time, s.
        state
            RotorPy state: ``x`` (3,) m, ``v`` (3,) m/s, ``q`` (4,) ``[i, j, k, w]``
            body-to-world, ``w`` (3,) rad/s body frame, ...
        flat_output
            :meth:`RotorPyTrajectory.update` output.

        Returns
        -------
        dict
            Every key RotorPy's own controllers fill: ``cmd_acc`` (3,) m/s^2
            (the command that is flown), ``cmd_motor_speeds`` (4,) rad/s
            (before the vehicle's clipping), ``cmd_motor_thrusts`` (4,) N,
            ``cmd_thrust`` N, ``cmd_moment`` (3,) N m, ``cmd_q`` (4,) the
            attitude the inner loop steers to; ``cmd_w`` and ``cmd_v``
            (unused by ``cmd_acc``) are 0 and the reference velocity.
        """
        dt = 0.0 if self._last_t is None else float(t) - self._last_t
        self._last_t = float(t)
        a_cmd = np.asarray(
            self.loop.acceleration(
                dt,
                np.asarray(flat_output["x"], dtype=float),
                np.asarray(flat_output["x_dot"], dtype=float),
                np.asarray(flat_output["x_ddot"], dtype=float),
                np.asarray(state["x"], dtype=float),
                np.asarray(state["v"], dtype=float),
                np.asarray(flat_output["x_dddot"], dtype=float),
            ),
            dtype=float,
        )
        if a_cmd.shape != (3,) or not np.all(np.isfinite(a_cmd)):
            raise SolverError(
                f"outer loop {self.loop.name!r} returned {a_cmd!r} at t = {float(t):.3f} s, "
                "expected a finite acceleration of shape (3,)"
            )
        cmd_acc = a_cmd + np.array([0.0, 0.0, float(self.vehicle.g)])
        control: RotorPyDict = {
            "cmd_acc": cmd_acc,
            "cmd_w": np.zeros(3),
            "cmd_v": np.asarray(flat_output["x_dot"], dtype=float),
            "cmd_q": _attitude_quaternion(cmd_acc),
        }
        # Exactly what Multirotor.step will compute from this command.
        speeds = np.asarray(self.vehicle.get_cmd_motor_speeds(state, control), dtype=float)
        thrusts = float(self.vehicle.k_eta) * np.sign(speeds) * speeds**2
        wrench = np.asarray(self.vehicle.f_to_TM, dtype=float) @ thrusts
        control.update(
            cmd_motor_speeds=speeds,
            cmd_motor_thrusts=thrusts,
            cmd_thrust=float(wrench[0]),
            cmd_moment=wrench[1:],
        )
        return control


def fly_rotorpy(
    trajectory: Trajectory,
    controller: Literal["se3"] | OuterLoop = "se3",
    rate_hz: float = 100.0,
    start_at_reference: bool = True,
    *,
    vehicle: VehicleName | Mapping[str, Any] = "px4_sihsim_quadx",
    hover_height_m: float = HOVER_HEIGHT_M,
) -> Flight:
    """Fly ``trajectory`` in RotorPy and return the closed-loop :class:`Flight`.

    Parameters
    ----------
    trajectory
        Reference, ``dim`` 2 or 3, metres, world frame z up, ``[0, duration]`` s.
        A 2-D trajectory is flown at ``z = hover_height_m``.
    controller
        ``"se3"`` for RotorPy's ``SE3Control`` (motor-speed commands), or an
        :class:`~skyquill.sim.controllers.OuterLoop` (e.g.
        :class:`~skyquill.sim.controllers.RPTController`) flown through
        RotorPy's ``cmd_acc`` abstraction (:class:`RotorPyOuterLoop`). The
        outer loop is reset first.
    rate_hz
        Simulation and control rate, Hz (RotorPy's ``sim_rate``; commands are
        held for ``1 / rate_hz`` s, the rigid body is integrated by RK45), within
        the range and step budget of :mod:`skyquill.sim.bounds`.
    start_at_reference
        Start at rest, level, motors at hover speed, at the reference's start
        position (``True``) or at the world origin ``(0, 0, 0)`` (``False``,
        a step response onto the reference).
    vehicle
        ``"px4_sihsim_quadx"`` (1.0 kg, default) or ``"hummingbird"``
        (0.5 kg), see the module docstring, or a RotorPy ``quad_params``
        mapping. Missing ``kp_att`` / ``kd_att`` are filled from
        :data:`ATTITUDE_GAINS`.
    hover_height_m
        World z (m) of a 2-D trajectory.

    Returns
    -------
    Flight
        Sampled at RotorPy's steps, ``t`` shape (N,) from 0 to the first step
        at or after ``duration`` (the reference holds its end beyond it);
        ``p, v`` the true state, ``p_ref, v_ref`` the reference, (N, 3).
        ``a_cmd`` (N, 3), m/s^2, gravity excluded: RotorPy's commanded
        mass-normalised thrust vector ``cmd_acc`` minus ``g e_z`` -- for
        ``"se3"`` that is exactly SE3Control's
        ``-K_p e_p - K_d e_v + a_ref`` (its ``F_des / m - g e_z``), for an
        outer loop it is the loop's own output. ``thrust`` (N,), N: the
        commanded collective thrust ``m cmd_acc . b3`` (before motor
        clipping). ``tilt`` (N,), rad: the *commanded* tilt, the angle
        between ``cmd_acc`` (the desired body z axis) and world z.
        ``saturations``: ``"motor_speed_max"`` / ``"motor_speed_min"``, the
        number of control steps at which some commanded motor speed lay
        beyond the vehicle's limits and was clipped by RotorPy.
        ``controller`` is ``"se3"`` or the outer loop's ``name``; ``sim`` is
        ``"rotorpy"``; ``wall_time_s`` covers RotorPy's run only.

    Raises
    ------
    ImportError
        RotorPy is not installed.
    InputError
        Bad trajectory, controller, rate or vehicle.
    SolverError
        The outer loop returned a non-finite command, or RotorPy lost the
        vehicle (stopped the flight for going faster than 100 m/s or
        spinning faster than 100 rad/s, or its state became non-finite).
        A flight that merely tracks badly is returned, not raised.
    """
    try:
        from rotorpy.controllers.quadrotor_control import SE3Control
        from rotorpy.environments import Environment
        from rotorpy.vehicles.multirotor import Multirotor
    except ImportError as exc:
        raise ImportError(_INSTALL_HINT) from exc

    reference = RotorPyTrajectory(trajectory, hover_height_m)
    rate = check_rate(rate_hz)
    check_steps(reference.duration, rate)  # RotorPy keeps every step's state
    outer = _check_controller(controller)
    params = _vehicle_params(vehicle)

    n_rotors = int(params["num_rotors"])
    hover_speed = _hover_speed(params)
    start = reference.update(0.0)["x"] if start_at_reference else np.zeros(3)
    initial_state = {
        "x": np.array(start, dtype=float),
        "v": np.zeros(3),
        "q": np.array([0.0, 0.0, 0.0, 1.0]),  # [i, j, k, w], level, yaw 0
        "w": np.zeros(3),
        "wind": np.zeros(3),
        "rotor_speeds": np.full(n_rotors, hover_speed),
    }
    if outer is None:
        quad = Multirotor(
            params, initial_state=initial_state, control_abstraction="cmd_motor_speeds"
        )
        rotorpy_controller: Any = SE3Control(params)
        name = "se3"
    else:
        quad = Multirotor(params, initial_state=initial_state, control_abstraction="cmd_acc")
        outer.reset()
        rotorpy_controller = RotorPyOuterLoop(outer, quad)
        name = str(outer.name)
    env = Environment(
        vehicle=quad, controller=rotorpy_controller, trajectory=reference, sim_rate=rate
    )

    # RotorPy's sensors draw from the legacy global generator: leave it as found.
    rng_state = np.random.get_state()  # noqa: NPY002
    t0 = time.perf_counter()
    try:
        result = env.run(t_final=reference.duration, terminate=False)
    finally:
        np.random.set_state(rng_state)  # noqa: NPY002
    wall = time.perf_counter() - t0

    t = np.asarray(result["time"], dtype=float)
    state, control = result["state"], result["control"]
    exit_status = result["exit"]
    if getattr(exit_status, "name", None) != "TIMEOUT" or not np.all(
        np.isfinite(state["x"]) & np.isfinite(state["v"])
    ):
        # RotorPy's speed and spin checks do not catch NaN states: check them too.
        raise SolverError(
            f"RotorPy lost the vehicle at t = {t[-1]:.3f} s of {reference.duration:.3f} s "
            f"with controller {name!r}: {getattr(exit_status, 'value', exit_status)}"
        )
    cmd_acc = np.asarray(control["cmd_acc"], dtype=float).reshape(t.size, 3)
    speeds = np.asarray(control["cmd_motor_speeds"], dtype=float).reshape(t.size, -1)
    lift = np.linalg.norm(cmd_acc, axis=1)
    cos_tilt = np.divide(cmd_acc[:, 2], lift, out=np.ones(t.size), where=lift > 0.0)
    saturations = {
        "motor_speed_max": int(np.any(speeds > float(params["rotor_speed_max"]), axis=1).sum()),
        "motor_speed_min": int(np.any(speeds < float(params["rotor_speed_min"]), axis=1).sum()),
    }
    log.debug("rotorpy: %s, %.3f s simulated in %.3f s wall", name, t[-1], wall)
    return Flight(
        t=t,
        p_ref=reference.derivatives(t, 0),
        v_ref=reference.derivatives(t, 1),
        p=np.asarray(state["x"], dtype=float).reshape(t.size, 3),
        v=np.asarray(state["v"], dtype=float).reshape(t.size, 3),
        a_cmd=cmd_acc - np.array([0.0, 0.0, float(quad.g)]),
        thrust=np.asarray(control["cmd_thrust"], dtype=float).reshape(t.size),
        tilt=np.arccos(np.clip(cos_tilt, -1.0, 1.0)),
        saturations=saturations,
        controller=name,
        sim="rotorpy",
        wall_time_s=wall,
    )


def matched_rpt(vehicle: VehicleName | Mapping[str, Any] = "px4_sihsim_quadx") -> RPTController:
    """RPT whose feed-forward and z loop match a RotorPy vehicle.

    :class:`~skyquill.sim.controllers.RPTController`'s defaults compensate
    skyquill's own vehicle; flown in RotorPy they over- or under-compensate
    and the error grows several-fold (module docstring). Here the two
    feed-forward terms come from the RotorPy vehicle instead:

    * ``lag_s = 2 / sqrt(kp_att)``: RotorPy's ``cmd_acc`` attitude loop is
      ``kp_att e_R + kd_att e_w`` with ``kd_att = 2 sqrt(kp_att)`` in the
      presets (critically damped), whose equivalent first-order lag is
      ``2 zeta / w_n = 2 / sqrt(kp_att)``. The motor lag ``tau_m`` is left
      out: adding it to the lag was measured to track worse (13 mm against
      2.3 mm on a 1 m circle with the PX4 preset).
    * ``drag_per_mass = k_d n omega_hover / m``: RotorPy's rotor drag is
      ``-k_d omega v`` per rotor in the rotor plane (``Multirotor``'s
      ``rotor_drag_matrix``), linear in the airspeed at hover rotor speed
      ``omega_hover``. The quadratic frame drag (``c_Dx``, ``c_Dy``) is
      negligible at writing speed and is left to the integrator.
    * z design :data:`MATCHED_Z` (x and y keep the paper's): RotorPy's
      thrust-projection loss while tilting needs a stiffer height loop.

    Parameters
    ----------
    vehicle
        As for :func:`fly_rotorpy`: a preset name or a ``quad_params`` mapping.

    Returns
    -------
    RPTController
        ``lag_s`` in s, ``drag_per_mass`` in 1/s; 0.086 s and 0 for the PX4
        preset, 0.086 s and 0.45 1/s for the Hummingbird. On a 1 m circle at
        100 Hz: 1.6 mm (PX4; SE3 8.5 mm) and 5.6 mm (Hummingbird; SE3 23 mm).

    Raises
    ------
    ImportError
        ``vehicle`` is a preset name and RotorPy is not installed.
    InputError
        Bad vehicle, or its ``kp_att`` is not a positive number.
    """
    params = _vehicle_params(vehicle)
    kp_att = as_float("vehicle.kp_att", params["kp_att"], positive=True)
    rotor_drag = as_float("vehicle.k_d", params.get("k_d", 0.0), nonneg=True)
    drag_per_mass = rotor_drag * int(params["num_rotors"]) * _hover_speed(params)
    return RPTController(
        z=MATCHED_Z,
        lag_s=2.0 / math.sqrt(kp_att),
        drag_per_mass=drag_per_mass / float(params["mass"]),
    )


def _hover_speed(params: Mapping[str, Any]) -> float:
    """Rotor speed (rad/s) at which the rotors together hold the vehicle's weight."""
    weight = float(params["mass"]) * 9.81
    return math.sqrt(weight / (int(params["num_rotors"]) * float(params["k_eta"])))


def _check_trajectory(trajectory: Any) -> None:
    if not isinstance(trajectory, Trajectory):
        raise InputError(
            f"trajectory: got {type(trajectory).__name__}, expected a skyquill Trajectory "
            "(duration, dim, evaluate, sample)"
        )
    if trajectory.dim not in (2, 3):
        raise InputError(f"trajectory: got dim {trajectory.dim}, expected 2 or 3")
    as_float("trajectory.duration", trajectory.duration, positive=True)


def _check_controller(controller: Any) -> OuterLoop | None:
    if isinstance(controller, str):
        if controller != "se3":
            raise InputError(f"controller: got {controller!r}, expected 'se3' or an OuterLoop")
        return None
    if not all(hasattr(controller, a) for a in ("acceleration", "reset", "name")):
        raise InputError(
            f"controller: got {type(controller).__name__}, expected 'se3' or an OuterLoop "
            "(name, reset(), acceleration(dt, p_ref, v_ref, a_ref, p, v, j_ref))"
        )
    loop: OuterLoop = controller
    return loop


def _vehicle_params(vehicle: VehicleName | Mapping[str, Any]) -> dict[str, Any]:
    if isinstance(vehicle, str):
        if vehicle not in _VEHICLE_MODULES:
            raise InputError(
                f"vehicle: got {vehicle!r}, expected one of {sorted(_VEHICLE_MODULES)} "
                "or a RotorPy quad_params mapping"
            )
        try:
            module = importlib.import_module(_VEHICLE_MODULES[vehicle])
        except ImportError as exc:
            raise ImportError(_INSTALL_HINT) from exc
        preset: Mapping[str, Any] = module.quad_params
    elif isinstance(vehicle, Mapping):
        preset = vehicle
    else:
        raise InputError(
            f"vehicle: got {type(vehicle).__name__}, expected a preset name or a mapping"
        )
    required = ("mass", "num_rotors", "k_eta", "rotor_speed_min", "rotor_speed_max")
    missing = [k for k in required if k not in preset]
    if missing:
        raise InputError(f"vehicle: quad_params lacks {missing}, expected RotorPy's keys")
    return {**ATTITUDE_GAINS, **preset}


def _attitude_quaternion(cmd_acc: FloatArray) -> FloatArray:
    """``[i, j, k, w]`` of the attitude RotorPy's ``cmd_acc`` loop steers to.

    Body z along ``cmd_acc``, body x in the plane of ``[1, 0, 0]`` (yaw 0),
    as ``Multirotor.get_cmd_motor_speeds`` builds it.
    """
    norm = float(np.linalg.norm(cmd_acc))
    if norm == 0.0:
        return np.array([0.0, 0.0, 0.0, 1.0])
    b3 = cmd_acc / norm
    b2 = np.cross(b3, np.array([1.0, 0.0, 0.0]))
    b2_norm = float(np.linalg.norm(b2))
    if b2_norm == 0.0:  # thrust along world x: no yaw reference, as in RotorPy (NaN there)
        return np.array([0.0, 0.0, 0.0, 1.0])
    b2 = b2 / b2_norm
    b1 = np.cross(b2, b3)
    return np.asarray(Rotation.from_matrix(np.column_stack([b1, b2, b3])).as_quat(), dtype=float)
