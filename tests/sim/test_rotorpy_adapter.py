"""Flying skyquill trajectories in RotorPy (optional dependency)."""

from __future__ import annotations

import sys

import numpy as np
import pytest

pytest.importorskip("rotorpy")

from skyquill.errors import InputError, SolverError
from skyquill.limits import VehicleLimits
from skyquill.optimize.fit import FitOptions, fit_points
from skyquill.sim.controllers import PAPER_XY, CascadePID, RPTController
from skyquill.sim.rotorpy_adapter import (
    ATTITUDE_GAINS,
    MATCHED_Z,
    RotorPyTrajectory,
    fly_rotorpy,
    matched_rpt,
)
from skyquill.trajectory import SplineTrajectory
from skyquill.validation import FloatArray

G = 9.81
RADIUS_M = 0.25
OPTIONS = FitOptions(limits=VehicleLimits(1.0, 1.0, 5.0))


def writing_circle(dim: int = 3) -> SplineTrajectory:
    """A 0.5 m circle drawn at writing speed (3-D points at z = 1 m, or 2-D)."""
    th = np.linspace(0.0, 2.0 * np.pi, 41)
    pts = np.column_stack([RADIUS_M * np.cos(th), RADIUS_M * np.sin(th), np.ones_like(th)])
    return fit_points(pts[:, :dim], options=OPTIONS).result.trajectory


@pytest.fixture(scope="module")
def circle() -> SplineTrajectory:
    return writing_circle()


def test_se3_tracks_a_writing_circle(circle: SplineTrajectory) -> None:
    flight = fly_rotorpy(circle, "se3", rate_hz=100.0)
    n = flight.t.size
    assert flight.t[0] == 0.0 and flight.t[-1] >= circle.duration
    assert np.allclose(np.diff(flight.t), 0.01)
    for arr in (flight.p_ref, flight.v_ref, flight.p, flight.v, flight.a_cmd):
        assert arr.shape == (n, 3) and np.all(np.isfinite(arr))
    assert flight.thrust.shape == flight.tilt.shape == (n,)
    assert (flight.controller, flight.sim) == ("se3", "rotorpy")
    assert flight.saturations == {"motor_speed_max": 0, "motor_speed_min": 0}
    assert flight.rmse_m < 0.05  # measured 1.06 cm on the 1 kg PX4 preset
    assert flight.max_error_m < 0.08
    # 1 kg vehicle: the mean thrust holds the weight, the tilt stays near atan(amax / g).
    assert flight.thrust.mean() == pytest.approx(1.0 * G, rel=0.02)
    assert flight.tilt.max() < np.radians(10.0)


def test_se3_acceleration_is_its_pd_law_without_gravity(circle: SplineTrajectory) -> None:
    """a_cmd = cmd_acc - g e_z must equal SE3Control's PD + feed-forward, computed here."""
    flight = fly_rotorpy(circle, "se3")
    a_ref = circle.evaluate(np.minimum(flight.t, circle.duration), 2)
    kp, kd = np.array([6.5, 6.5, 15.0]), np.array([4.0, 4.0, 9.0])  # SE3Control's gains
    expected = kp * (flight.p_ref - flight.p) + kd * (flight.v_ref - flight.v) + a_ref
    assert np.allclose(flight.a_cmd, expected, atol=1e-9)


def test_rpt_flies_through_cmd_acc(circle: SplineTrajectory) -> None:
    # Default RPT: its feed-forward is tuned to skyquill's vehicle (1/25 s lag,
    # 0.3 1/s linear drag), which over-compensates the PX4 preset's drag.
    flight = fly_rotorpy(circle, RPTController(), rate_hz=100.0)
    assert flight.controller == "rpt"
    assert np.all(np.isfinite(flight.p))
    assert flight.rmse_m < 0.10  # measured 5.4 cm
    assert flight.saturations == {"motor_speed_max": 0, "motor_speed_min": 0}
    assert flight.thrust.mean() == pytest.approx(1.0 * G, rel=0.02)
    # The outer loop's own command is what is reported, gravity excluded.
    assert np.abs(flight.a_cmd).max() < 2.0


def test_rpt_matched_to_the_rotorpy_vehicle_tracks_to_millimetres(
    circle: SplineTrajectory,
) -> None:
    """With this vehicle's lag (critically damped attitude loop: 2 / sqrt(kp_att)) and no
    linear drag, RPT's feed-forward is right and the error drops to millimetres."""
    paper = fly_rotorpy(circle, RPTController(lag_s=0.0, drag_per_mass=0.0))
    assert paper.rmse_m < 0.05  # measured 2.3 cm: the paper's law as printed
    lag = 2.0 / np.sqrt(ATTITUDE_GAINS["kp_att"])
    matched = fly_rotorpy(circle, RPTController(lag_s=lag, drag_per_mass=0.0))
    assert matched.rmse_m < 0.015  # measured 0.7 cm
    assert matched.rmse_m < 0.5 * paper.rmse_m


@pytest.fixture(scope="module")
def loop_1m() -> SplineTrajectory:
    """A 1 m circle at writing speed (7.2 s), the loop of the issue."""
    th = np.linspace(0.0, 2.0 * np.pi, 61)
    pts = np.column_stack([0.5 * np.cos(th), 0.5 * np.sin(th), np.ones_like(th)])
    return fit_points(pts, options=OPTIONS).result.trajectory


def test_matched_rpt_reads_the_vehicle() -> None:
    """Lag 2 / sqrt(kp_att); linear drag = rotor drag k_d at hover speed, summed, over mass."""
    from rotorpy.vehicles.hummingbird_params import quad_params as hummingbird

    px4 = matched_rpt()
    assert px4.lag_s == pytest.approx(2.0 / np.sqrt(ATTITUDE_GAINS["kp_att"]))
    assert px4.drag_per_mass == 0.0  # the PX4 preset has no rotor drag
    hb = matched_rpt("hummingbird")
    m, k_eta, k_d = hummingbird["mass"], hummingbird["k_eta"], hummingbird["k_d"]
    omega_hover = np.sqrt(m * G / (4 * k_eta))
    assert hb.drag_per_mass == pytest.approx(4 * k_d * omega_hover / m)
    assert hb.drag_per_mass == pytest.approx(0.447, abs=1e-3)
    assert hb.lag_s == px4.lag_s  # the Hummingbird's kp_att is the one filled in
    assert np.allclose(px4.k_p, [PAPER_XY.gains()[1], PAPER_XY.gains()[1], MATCHED_Z.gains()[1]])


@pytest.mark.parametrize("vehicle", ["px4_sihsim_quadx", "hummingbird"])
def test_matched_rpt_tracks_a_1m_loop_as_well_as_se3(
    loop_1m: SplineTrajectory, vehicle: str
) -> None:
    """What ``skyquill fly --sim rotorpy`` flies by default, against RotorPy's own SE3."""
    se3 = fly_rotorpy(loop_1m, "se3", vehicle=vehicle)  # type: ignore[arg-type]
    rpt = fly_rotorpy(loop_1m, matched_rpt(vehicle), vehicle=vehicle)  # type: ignore[arg-type]
    skyquill_tuned = fly_rotorpy(loop_1m, RPTController(), vehicle=vehicle)  # type: ignore[arg-type]
    # Measured at 100 Hz (matched / se3 / skyquill-tuned): PX4 1.6 / 8.5 / 56 mm,
    # Hummingbird 5.6 / 23 / 16 mm.
    assert rpt.rmse_m <= 1.2 * se3.rmse_m
    assert rpt.rmse_m < 0.5 * skyquill_tuned.rmse_m
    assert rpt.saturations == {"motor_speed_max": 0, "motor_speed_min": 0}


def test_matched_rpt_names_a_bad_vehicle() -> None:
    from rotorpy.vehicles.px4_sihsim_quadx_params import quad_params

    with pytest.raises(InputError, match="vehicle: got 'x500'"):
        matched_rpt("x500")  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"vehicle\.kp_att: got -1"):
        matched_rpt({**quad_params, "kp_att": -1.0})


def test_outer_loop_is_reset_and_any_outer_loop_flies(circle: SplineTrajectory) -> None:
    pid = CascadePID(feed_forward=True)
    pid.integral = np.array([50.0, 50.0, 50.0])  # stale state must not leak into the flight
    flight = fly_rotorpy(circle, pid)
    assert flight.controller == "pid-ff"
    assert flight.rmse_m < 0.10


def test_hummingbird_preset(circle: SplineTrajectory) -> None:
    flight = fly_rotorpy(circle, RPTController(), vehicle="hummingbird")
    assert flight.rmse_m < 0.05  # measured 1.2 cm (its rotor drag is ~0.6 1/s)
    assert flight.thrust.mean() == pytest.approx(0.5 * G, rel=0.02)


def test_trajectory_clamps_time_including_inf(circle: SplineTrajectory) -> None:
    ref = RotorPyTrajectory(circle)
    end = ref.update(np.inf)
    start = ref.update(-1.0)
    p_end, p_start = circle.evaluate(np.array([circle.duration, 0.0]))
    assert np.allclose(end["x"], p_end) and np.allclose(start["x"], p_start)
    assert set(end) == {"x", "x_dot", "x_ddot", "x_dddot", "x_ddddot", "yaw", "yaw_dot", "yaw_ddot"}
    for key in ("x_dot", "x_ddot"):  # the fit ends at rest
        assert end[key].shape == (3,) and np.allclose(end[key], 0.0, atol=1e-9)
    mid = ref.update(0.5 * circle.duration)
    t_mid = np.array([0.5 * circle.duration])
    for order, key in enumerate(("x", "x_dot", "x_ddot", "x_dddot", "x_ddddot")):
        assert np.allclose(mid[key], circle.evaluate(t_mid, order)[0])


def test_2d_trajectory_flies_at_hover_height() -> None:
    flat = writing_circle(dim=2)
    ref = RotorPyTrajectory(flat, hover_height_m=1.5)
    assert ref.update(0.3)["x"][2] == 1.5 and ref.update(0.3)["x_dot"][2] == 0.0
    flight = fly_rotorpy(flat, "se3")
    assert np.allclose(flight.p_ref[:, 2], 1.0)
    assert np.allclose(flight.v_ref[:, 2], 0.0)
    assert flight.rmse_m < 0.05


def test_start_away_from_reference_is_a_step_response(circle: SplineTrajectory) -> None:
    flight = fly_rotorpy(circle, "se3", start_at_reference=False)
    assert np.allclose(flight.p[0], 0.0)
    assert flight.position_error[0] > 0.9
    assert flight.position_error[-1] < 0.05


def test_global_random_state_is_left_untouched(circle: SplineTrajectory) -> None:
    # The legacy global generator is what is tested (RotorPy's sensors draw from it).
    np.random.seed(1234)  # noqa: NPY002
    expected = np.random.random(4)  # noqa: NPY002
    np.random.seed(1234)  # noqa: NPY002
    fly_rotorpy(circle, "se3")
    assert np.array_equal(np.random.random(4), expected)  # noqa: NPY002


def test_rotorpy_fallback_attitude_gains_are_unusable_at_100_hz(
    circle: SplineTrajectory,
) -> None:
    """Why ATTITUDE_GAINS are filled in: RotorPy's fall-backs (3000, 360) chatter at 100 Hz."""
    from rotorpy.vehicles.px4_sihsim_quadx_params import quad_params

    assert "kp_att" not in quad_params and "kd_att" not in quad_params
    params = {**quad_params, "kp_att": 3000.0, "kd_att": 360.0}
    flight = fly_rotorpy(circle, RPTController(), vehicle=params)
    assert flight.saturations["motor_speed_max"] > 0.5 * flight.t.size  # reported, not hidden
    assert flight.rmse_m > 1.0


class NaNLoop:
    """An outer loop that breaks after its first step."""

    name = "nan"

    def reset(self) -> None:
        pass

    def acceleration(self, dt: float, *_: FloatArray) -> FloatArray:
        return np.full(3, np.nan) if dt > 0.0 else np.zeros(3)


def test_broken_outer_loop_raises(circle: SplineTrajectory) -> None:
    with pytest.raises(SolverError, match=r"outer loop 'nan' returned .* at t = 0\.010 s"):
        fly_rotorpy(circle, NaNLoop())  # type: ignore[arg-type]


def test_bad_arguments_are_named(circle: SplineTrajectory) -> None:
    with pytest.raises(InputError, match="controller: got 'lqr'"):
        fly_rotorpy(circle, "lqr")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="controller: got object"):
        fly_rotorpy(circle, object())  # type: ignore[arg-type]
    with pytest.raises(InputError, match="vehicle: got 'x500'"):
        fly_rotorpy(circle, vehicle="x500")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="rate_hz: got -5"):
        fly_rotorpy(circle, rate_hz=-5.0)
    with pytest.raises(InputError, match="trajectory: got ndarray"):
        fly_rotorpy(np.zeros((3, 3)))  # type: ignore[arg-type]


def test_missing_rotorpy_says_how_to_install(
    circle: SplineTrajectory, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "rotorpy.environments", None)  # import now fails
    with pytest.raises(ImportError, match=r"pip install 'skyquill\[rotorpy\]'"):
        fly_rotorpy(circle)


def test_rotorpy_refuses_a_flight_over_the_step_budget(circle: SplineTrajectory) -> None:
    long = SplineTrajectory(np.zeros((6, 3)), 5, 1e6)
    with pytest.raises(InputError, match=r"expected at most 2,000,000 steps"):
        fly_rotorpy(long)
    with pytest.raises(InputError, match=r"rate_hz: got 1e\+06 Hz, expected 50 to 10000 Hz"):
        fly_rotorpy(circle, rate_hz=1e6)
