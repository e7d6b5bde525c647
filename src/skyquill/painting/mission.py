"""A simulated dot-painting mission with contact-driven estimation (paper 002 §2-5).

Reduced model, not the closed-loop simulator -- and why
-------------------------------------------------------
What decides where a dot lands is (a) where the drone *believes* it is (onboard localization
with noise and drift), (b) where it really is when it waits in front of the dot (placement
``delta``/``gamma`` of ``R_rho`` in ``R_w``, and the position controller's hover error), (c)
the direction it approaches in (its yaw, which the estimate sets), and (d) where that ray meets
the real wall. The estimate is fed by one number set per dot: the believed position when the
IMU says "contact". This module keeps exactly these, per dot, in closed form:

* waiting point ``Q* = P* - Delta * y_b`` (the paper writes ``P* - [0, Delta, 0]`` in
  ``R_rho``; once the yaw follows ``-gamma_hat`` (eq. 12) the drone approaches along its body
  ``y``, so the offset is taken along body ``y`` too -- otherwise the approach would miss
  ``P*`` by ``Delta sin(gamma_hat)``, 10 cm at 10 deg);
* hover error at the waiting point (Gaussian, ``tracking_std_m`` per axis; the paper's
  ground-truth runs without estimation at gamma = 0 show ~5 cm RMSE, which is this error);
* approach along body ``y`` at ``approach_speed_mps`` until the ray meets the wall
  (:meth:`Wall.hit`); contact is a spring-damper bumper (``ContactModel``) whose deceleration
  the IMU samples at ``imu_rate_hz`` with noise; contact is *detected* at the first sample
  with ``|a_y| > 0.25 g`` (``a_y`` is the normal deceleration times the cosine between body
  ``y`` and the wall normal). A soft or slow or oblique touch may never cross the threshold:
  a missed contact (painted, not measured). The dot is where the tool touched; the measured
  contact is the believed position at the detection sample (the bumper is compressed by then);
* retreat to ``Q*``; a landing when the next dot would exceed the battery (``battery_s``,
  ~8 min in §3.3), which resets the localization drift but keeps the estimate;
* flight time from the transit, approach and retreat speeds plus a settling time per dot.

The full simulator (``skyquill.sim``) would add the attitude loop's transients during the
approach, which the estimate never sees (it only sees the contact position) and which the hover
error above stands for. Running it for every dot (140 dots x 5 cases x 9 set-ups x 10 seeds)
would cost minutes per table for no change in what is measured, so it is left out of the loop;
:mod:`skyquill.painting.crosscheck` flies the simulator into the same bumper and finds the same
detection (same IMU sample, squeeze within 0.01 mm, from 0.13 to 0.35 m/s; both miss a
0.07 m/s touch).

Injected faults for the robustness study: ``false_contact_rate`` (the IMU fires before the
wall -- a gust, a propeller-wash bump -- at a uniform distance short of it; no dot painted,
a wrong contact measured) and ``missed_contact_rate`` (the touch is not detected; the dot is
painted, nothing is measured, the drone pushes to the end of its travel).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from skyquill.errors import InputError
from skyquill.painting.dots import check_dots
from skyquill.painting.estimate import (
    Estimator,
    NoEstimator,
    Plan,
    RigidEstimator,
    SegmentEstimator,
    UpdateMode,
    line_params,
)
from skyquill.painting.joint import JointEstimator, WallFit
from skyquill.painting.order import order_dots
from skyquill.painting.wall import Placement, Wall, rot2
from skyquill.validation import FloatArray, as_float

G = 9.81
EstimatorName = Literal["none", "svd", "robust", "joint"]
ESTIMATORS: tuple[EstimatorName, ...] = ("none", "svd", "robust", "joint")
WallModel = Literal["auto", "flat", "segments"]


@dataclass(frozen=True)
class Localization:
    """Onboard localization error: white noise plus a random-walk drift (reset at landing).

    Attributes
    ----------
    name
        ``"truth"`` or ``"onboard"`` (or anything, for reports).
    noise_m
        White noise on each reported coordinate, standard deviation, m.
    drift_m_per_sqrt_s
        Position drift, random walk per axis, m / sqrt(s) (PTAM-like visual odometry drifts
        centimetres per minute, §3.3).
    yaw_drift_rad_per_sqrt_s
        Heading drift, random walk, rad / sqrt(s).
    """

    name: str = "truth"
    noise_m: float = 0.0
    drift_m_per_sqrt_s: float = 0.0
    yaw_drift_rad_per_sqrt_s: float = 0.0

    def __post_init__(self) -> None:
        as_float("noise_m", self.noise_m, nonneg=True)
        as_float("drift_m_per_sqrt_s", self.drift_m_per_sqrt_s, nonneg=True)
        as_float("yaw_drift_rad_per_sqrt_s", self.yaw_drift_rad_per_sqrt_s, nonneg=True)

    @classmethod
    def named(cls, name: str) -> Localization:
        """``"truth"`` (perfect) or ``"onboard"`` (1 cm noise, 4 mm/sqrt(s), 0.02 deg/sqrt(s)).

        With the onboard values the drift reaches ~9 cm (1 sigma per axis) after the 8 minutes
        between two landings: the order of the paper's PTAM-minus-GT RMSE gap (Table 1).
        """
        if name == "truth":
            return cls("truth")
        if name == "onboard":
            return cls("onboard", 0.01, 0.004, math.radians(0.02))
        raise InputError(f"--localization: got {name!r}, expected 'onboard' or 'truth'")


@dataclass(frozen=True)
class ContactModel:
    """The tool's bumper against the wall and the IMU that watches it.

    Attributes
    ----------
    mass_kg
        Vehicle mass (AR.Drone 2.0 with hull: ~0.42 kg).
    stiffness_n_per_m
        Bumper stiffness along the wall normal, N/m.
    damping_ratio
        Bumper damping ratio (< 1).
    imu_rate_hz
        IMU sample rate, Hz.
    imu_noise_g
        Accelerometer noise (vibration), standard deviation, g.
    threshold_g
        Detection threshold on ``|a_y|`` (paper §3.2: 0.25 g).
    """

    mass_kg: float = 0.42
    stiffness_n_per_m: float = 400.0
    damping_ratio: float = 0.3
    imu_rate_hz: float = 200.0
    imu_noise_g: float = 0.03
    threshold_g: float = 0.25

    def __post_init__(self) -> None:
        for name in ("mass_kg", "stiffness_n_per_m", "imu_rate_hz", "threshold_g"):
            as_float(name, getattr(self, name), positive=True)
        as_float("imu_noise_g", self.imu_noise_g, nonneg=True)
        zeta = as_float("damping_ratio", self.damping_ratio, nonneg=True)
        if zeta >= 1.0:
            raise InputError(f"damping_ratio: got {zeta:g}, expected a value in [0, 1)")

    def detect(
        self,
        speed_mps: float,
        cos_incidence: float,
        rng: np.random.Generator,
        *,
        phase_s: float | None = None,
    ) -> tuple[bool, float, float]:
        """Simulate one touch: ``(detected, delay_s, compression_m)`` at detection.

        The bumper is a damped spring from the touch until it lets go (half a damped period):
        ``x(t) = v / w_d exp(-zeta w0 t) sin(w_d t)``, deceleration ``(k x + c x') / m``. The
        IMU samples it at a random phase (or ``phase_s`` after the touch); ``a_y`` is that
        deceleration times ``cos_incidence`` plus noise.
        """
        w0 = math.sqrt(self.stiffness_n_per_m / self.mass_kg)
        wd = w0 * math.sqrt(1.0 - self.damping_ratio**2)
        dt = 1.0 / self.imu_rate_hz
        first = rng.uniform(0.0, dt) if phase_s is None else phase_s
        t = first + np.arange(0.0, math.pi / wd, dt)
        decay = np.exp(-self.damping_ratio * w0 * t)
        x = speed_mps / wd * decay * np.sin(wd * t)
        xdot = speed_mps * decay * (np.cos(wd * t) - self.damping_ratio * w0 / wd * np.sin(wd * t))
        c = 2.0 * self.damping_ratio * w0 * self.mass_kg
        decel = (self.stiffness_n_per_m * x + c * xdot) / self.mass_kg
        a_y = decel * cos_incidence + rng.normal(0.0, self.imu_noise_g * G, t.size)
        over = np.flatnonzero(np.abs(a_y) > self.threshold_g * G)
        if over.size == 0:
            return False, 0.0, 0.0
        i = int(over[0])
        return True, float(t[i]), float(x[i])


@dataclass(frozen=True)
class MissionConfig:
    """Speeds, distances and fault rates of a mission (defaults: an AR.Drone-like vehicle).

    Attributes
    ----------
    waiting_distance_m
        ``Delta``: the waiting point is this far from the dot, along body ``y``, m.
    nominal_distance_m
        ``d``: the operator is told to put the drone this far in front of the wall's origin;
        the estimators start from ``delta0 = [0, -d, 0]``, ``gamma0 = 0`` (eq. 2).
    approach_speed_mps, transit_speed_mps, retreat_speed_mps
        Speeds of the velocity-controlled approach, the transit between waiting points and the
        retreat, m/s.
    settle_s
        Time to stabilise at each waiting point before the approach, s.
    battery_s
        Flight time between two landings, s (§3.3: ~8 minutes).
    tracking_std_m
        Hover error of the position controller per axis, m.
    max_travel_factor
        The approach gives up after ``max_travel_factor * Delta`` without a detected contact.
    probe
        Touch an extra point far from the first dot before it (§4.1), for the flat-wall
        estimators; it is not painted.
    probe_spacing_m
        The joint estimator's probing pass: before the first dot, touch the wall without
        painting every ``probe_spacing_m`` across the drawing's width (at its mid-height),
        so that the first dot is painted with the wall and the placement already known.
        0: no probing pass.
    false_contact_rate, missed_contact_rate
        Probability per approach of a false detection before the wall / of no detection.
    contact
        The bumper and IMU model.
    max_acceleration_mps2, max_jerk_mps3
        Norm limits of the flight's trajectory (:mod:`skyquill.painting.flight`): every
        leg is a straight time-optimal move at its speed above within them.
    """

    waiting_distance_m: float = 0.6
    nominal_distance_m: float = 1.1
    approach_speed_mps: float = 0.2
    transit_speed_mps: float = 0.5
    retreat_speed_mps: float = 0.4
    settle_s: float = 3.0
    battery_s: float = 480.0
    tracking_std_m: float = 0.03
    max_travel_factor: float = 2.0
    probe: bool = True
    probe_spacing_m: float = 0.4
    false_contact_rate: float = 0.0
    missed_contact_rate: float = 0.0
    contact: ContactModel = field(default_factory=ContactModel)
    max_acceleration_mps2: float = 1.0
    max_jerk_mps3: float = 5.0

    def __post_init__(self) -> None:
        for name in (
            "waiting_distance_m",
            "nominal_distance_m",
            "approach_speed_mps",
            "transit_speed_mps",
            "retreat_speed_mps",
            "battery_s",
            "max_acceleration_mps2",
            "max_jerk_mps3",
        ):
            as_float(name, getattr(self, name), positive=True)
        as_float("settle_s", self.settle_s, nonneg=True)
        as_float("probe_spacing_m", self.probe_spacing_m, nonneg=True)
        as_float("tracking_std_m", self.tracking_std_m, nonneg=True)
        if as_float("max_travel_factor", self.max_travel_factor) <= 1.0:
            raise InputError(
                f"max_travel_factor: got {self.max_travel_factor:g}, expected a number > 1"
            )
        for name in ("false_contact_rate", "missed_contact_rate"):
            rate = as_float(name, getattr(self, name))
            if not 0.0 <= rate < 1.0:
                raise InputError(f"{name}: got {rate:g}, expected a probability in [0, 1)")

    @property
    def prior(self) -> Placement:
        """The nominal placement ``([0, -d, 0], 0)`` the estimators start from."""
        return Placement(np.array([0.0, -self.nominal_distance_m, 0.0]), 0.0)


@dataclass(frozen=True)
class MissionResult:
    """What a mission did and how well.

    Attributes
    ----------
    reference
        The dots asked for, ``(x_w, z_w)``, shape (N, 2), m, input order.
    target_w
        What each dot should be, shape (N, 3), m, ``R_w``: ``(x, wall depth, z)`` (the
        front-view reference, eq. 15) or the foot of the normal onto the wall (fresco).
    painted_w
        Where each dot was painted (the tool's touch point), shape (N, 3), m, ``R_w``; NaN
        for a dot never painted (false contact or wall not reached).
    errors_m
        Painting error per dot, shape (N,), m (NaN if not painted): in the front view
        ``(x, z)`` for ``update="depth"``, the 3-D distance on the wall for ``"normal"``.
    aim_errors_m
        The estimate's own share of each dot's error, shape (N,), m: where the dot would
        land if the drone flew its plan exactly -- no hover error, no localization drift or
        noise -- measured like ``errors_m`` (NaN if that ray misses the wall within reach).
    order
        Indices into ``reference`` in painting order, shape (N,).
    history
        Per approach (K of them, probe included): ``t_s``, ``dot`` (-1 for the probe),
        ``gamma_hat_rad``, ``delta_hat_w`` (K, 3), ``yaw_rad``, ``error_m``, ``measured``
        (bool) and ``landing`` (bool, a landing happened before it).
    contacts_w
        True positions at each measured contact, shape (M, 3), m, ``R_w``.
    lines_rho
        The segment estimator's lines ``[a, b, x_lo, x_hi]`` in ``R_rho``, shape (L, 4).
    path_w
        The true path, shape (K + 1, 3), m, ``R_w``: home, then where each leg ends
        (hover points, contacts, returns, home again).
    leg_kinds
        What each of the K legs is: ``"transit"``, ``"approach"`` or ``"retreat"``.
    """

    reference: FloatArray
    target_w: FloatArray
    painted_w: FloatArray
    errors_m: FloatArray
    aim_errors_m: FloatArray
    order: np.ndarray
    flight_time_s: float
    landings: int
    contacts: int
    false_contacts: int
    missed_contacts: int
    unsafe_waits: int
    estimate: Placement
    truth: Placement
    history: dict[str, np.ndarray]
    contacts_w: FloatArray
    lines_rho: FloatArray
    wall: Wall
    estimator: str
    localization: str
    update: str
    transit_m: float
    path_w: FloatArray
    leg_kinds: tuple[str, ...]
    battery_s: float
    wall_fit: WallFit | None = None

    @property
    def painted(self) -> np.ndarray:
        """Mask of the dots that were painted, shape (N,)."""
        return np.isfinite(self.errors_m)

    @property
    def rmse_m(self) -> float:
        """Root mean square painting error over the painted dots, m (NaN if none)."""
        e = self.errors_m[self.painted]
        return float(np.sqrt(np.mean(e**2))) if e.size else math.nan

    @property
    def max_error_m(self) -> float:
        """Largest painting error, m (NaN if nothing was painted)."""
        e = self.errors_m[self.painted]
        return float(e.max()) if e.size else math.nan

    @property
    def aim_rmse_m(self) -> float:
        """Root mean square of :attr:`aim_errors_m` over the dots it exists for, m."""
        e = self.aim_errors_m[np.isfinite(self.aim_errors_m)]
        return float(np.sqrt(np.mean(e**2))) if e.size else math.nan

    @property
    def aim_max_error_m(self) -> float:
        """Largest of :attr:`aim_errors_m`, m."""
        e = self.aim_errors_m[np.isfinite(self.aim_errors_m)]
        return float(e.max()) if e.size else math.nan

    @property
    def probes(self) -> int:
        """Approaches that painted nothing on purpose (§4.1's point, the probing pass)."""
        return int(np.count_nonzero(self.history["dot"] < 0))

    @property
    def battery_use(self) -> float:
        """Flight time in batteries (``flight_time_s / battery_s``): 2.4 is two and a half."""
        return self.flight_time_s / self.battery_s

    def summary(self) -> dict[str, Any]:
        """The JSON-able summary (``summary.json``)."""

        def pose(p: Placement) -> dict[str, Any]:
            return {"gamma_deg": p.gamma_deg, "delta_m": [float(v) for v in p.delta_w]}

        return {
            "rmse_m": self.rmse_m,
            "max_error_m": self.max_error_m,
            "aim_rmse_m": self.aim_rmse_m,
            "aim_max_error_m": self.aim_max_error_m,
            "n_dots": len(self.reference),
            "painted_dots": int(self.painted.sum()),
            "flight_time_s": self.flight_time_s,
            "battery_use": self.battery_use,
            "transit_m": self.transit_m,
            "landings": self.landings,
            "probes": self.probes,
            "contacts": self.contacts,
            "false_contacts": self.false_contacts,
            "missed_contacts": self.missed_contacts,
            "unsafe_waits": self.unsafe_waits,
            "estimate": pose(self.estimate),
            "truth": pose(self.truth),
            "estimator": self.estimator,
            "localization": self.localization,
            "update": self.update,
            "wall_angles_deg": [math.degrees(a) for a in self.wall.angles_rad],
            "wall_fit": None if self.wall_fit is None else self.wall_fit.summary(),
        }


def make_estimator(
    name: str,
    prior: Placement,
    *,
    segments: bool,
    update: UpdateMode = "depth",
    localization: Localization | None = None,
) -> Estimator:
    """``none`` / ``svd`` / ``robust`` (paper 002: with ``segments`` the line model of §5) or
    ``joint`` (placement and wall together, :mod:`skyquill.painting.joint`)."""
    if name not in ESTIMATORS:
        raise InputError(f"--estimator: got {name!r}, expected one of {', '.join(ESTIMATORS)}")
    if name == "none":
        return NoEstimator(prior)
    if name == "joint":
        spec = localization or Localization()
        return JointEstimator(
            prior,
            update=update,
            noise_m=spec.noise_m,
            drift_m_per_sqrt_s=spec.drift_m_per_sqrt_s,
        )
    if segments:
        return SegmentEstimator(prior, update=update, robust=name == "robust")
    return RigidEstimator(prior, robust=name == "robust")


def check_on_wall(
    dots: FloatArray, wall: Wall, *, name: str = "dots", wall_name: str = "the wall"
) -> None:
    """InputError naming ``name`` (and ``wall_name``) if a dot lies outside the wall's extent."""
    x0, x1 = wall.x_range_m
    outside = (
        (dots[:, 0] < x0) | (dots[:, 0] > x1) | (dots[:, 1] < 0) | (dots[:, 1] > wall.height_m)
    )
    if outside.any():
        i = int(np.flatnonzero(outside)[0])
        raise InputError(
            f"{name}: got {int(outside.sum())} dot(s) outside the wall, the first (row {i + 1}) "
            f"at x={dots[i, 0]:g}, z={dots[i, 1]:g} m; expected {x0:g} <= x <= {x1:g} and "
            f"0 <= z <= {wall.height_m:g} m ({wall_name})"
        )


class _Flight:
    """The drone's state along the mission: clocks, drift, counters, records."""

    def __init__(
        self,
        *,
        wall: Wall,
        truth: Placement,
        loc: Localization,
        config: MissionConfig,
        rng: np.random.Generator,
    ) -> None:
        self.wall, self.truth, self.loc, self.cfg, self.rng = wall, truth, loc, config, rng
        # Each approach draws its hover error, IMU noise, faults and localization noise from
        # its own stream, keyed by the dot (or probe) it is for: the same dot gets the same
        # draws whatever the estimator, the order or the probes before it, so that two
        # missions differ by what they decide, not by which dot drew which luck (common random
        # numbers). The drift, a function of the time flown, stays on ``rng``.
        self.base = int(rng.integers(2**62))
        self.t = 0.0  # flight time, s
        self.t_air = 0.0  # since the last take-off, s
        self.drift = np.zeros(3)
        self.yaw_drift = 0.0
        self.pos_rho = np.zeros(3)  # believed position; home is the origin of R_rho
        self.transit_m = 0.0
        self.landings = self.contacts = self.false_contacts = self.missed = self.unsafe = 0
        self.contacts_w: list[FloatArray] = []
        # The true path, for the flight's trajectory: where each leg ends and what it is.
        self.path_w: list[FloatArray] = [truth.to_w(np.zeros(3))]
        self.leg_kinds: list[str] = []

    def _reach(self, where_w: FloatArray, kind: str) -> None:
        self.path_w.append(np.asarray(where_w, dtype=float).copy())
        self.leg_kinds.append(kind)

    def fly(self, seconds: float) -> None:
        """Advance both clocks and the localization drift."""
        self.t += seconds
        self.t_air += seconds
        root = math.sqrt(seconds)
        self.drift += self.rng.normal(0.0, self.loc.drift_m_per_sqrt_s * root, 3)
        self.yaw_drift += self.rng.normal(0.0, self.loc.yaw_drift_rad_per_sqrt_s * root)

    def transit(self, to_rho: FloatArray) -> None:
        """Straight flight from the believed position to ``to_rho``."""
        dist = float(np.linalg.norm(to_rho - self.pos_rho))
        self.transit_m += dist
        self.fly(dist / self.cfg.transit_speed_mps)
        self.pos_rho = to_rho.copy()
        self._reach(self.truth.to_w(to_rho - self.drift), "transit")

    def land_if_needed(self, wait_rho: FloatArray) -> bool:
        """Land (and reset the drift) first if this dot would overrun the battery."""
        cfg = self.cfg
        travel = cfg.max_travel_factor * cfg.waiting_distance_m
        need = (
            float(np.linalg.norm(wait_rho - self.pos_rho)) / cfg.transit_speed_mps
            + cfg.settle_s
            + travel / cfg.approach_speed_mps
            + travel / cfg.retreat_speed_mps
            + float(np.linalg.norm(wait_rho)) / cfg.transit_speed_mps
        )
        if self.t_air == 0.0 or self.t_air + need <= cfg.battery_s:
            return False
        self.transit(np.zeros(3))
        self.landings += 1
        self.t_air = 0.0
        self.drift = np.zeros(3)  # §3.3: PTAM is reset on the ground; the estimate is kept
        self.yaw_drift = 0.0
        return True

    def touch(
        self, wait_rho: FloatArray, yaw_rad: float, key: tuple[int, int]
    ) -> tuple[FloatArray | None, FloatArray]:
        """Approach from ``wait_rho`` with yaw ``yaw_rad``; retreat. ``key``: (0, dot) or
        (1, probe), the approach's random stream.

        Returns
        -------
        measured_rho : numpy.ndarray (3,) or None
            The believed position at the detected contact (None: nothing detected).
        painted_w : numpy.ndarray (3,)
            The touch point on the wall (NaN if the tool never touched it).
        """
        cfg, rng = self.cfg, np.random.default_rng([self.base, *key])
        self.transit(wait_rho)
        self.fly(cfg.settle_s)
        # the drone holds the *believed* waiting point: truly it is off by the drift
        true_rho = wait_rho - self.drift + rng.normal(0.0, cfg.tracking_std_m, 3)
        start_w = self.truth.to_w(true_rho)
        heading = self.truth.gamma_rad + yaw_rad - self.yaw_drift
        u = rot2(heading) @ np.array([0.0, 1.0])
        hit = self.wall.hit(start_w[:2], u)
        travel_max = cfg.max_travel_factor * cfg.waiting_distance_m
        if hit < 0.05:
            self.unsafe += 1  # the waiting point is at or beyond the wall
        nan3 = np.full(3, np.nan)
        if cfg.false_contact_rate and rng.random() < cfg.false_contact_rate:
            short = rng.uniform(0.05, max(0.06, min(hit, travel_max) - 0.02))
            stop = max(min(hit, travel_max) - short, 0.0)
            self.false_contacts += 1
            return self._measure(start_w, u, stop, rng), nan3
        if hit > travel_max:  # nothing within reach (or parallel): give up, come back
            self.fly(travel_max / cfg.approach_speed_mps + travel_max / cfg.retreat_speed_mps)
            self._reach(np.array([*(start_w[:2] + travel_max * u), start_w[2]]), "approach")
            self._reach(start_w, "retreat")
            return None, nan3
        hit = max(hit, 0.0)  # touched on the way in: painted where the path met the wall
        painted = np.array([*(start_w[:2] + hit * u), start_w[2]])
        cos_inc = float(u @ self.wall.normal(np.array([painted[0]]))[0])
        detected, delay, squeeze = cfg.contact.detect(cfg.approach_speed_mps, cos_inc, rng)
        if not detected or (cfg.missed_contact_rate and rng.random() < cfg.missed_contact_rate):
            self.missed += 1  # the drone keeps pushing until the end of its travel
            self.fly(travel_max / cfg.approach_speed_mps + hit / cfg.retreat_speed_mps)
            self._reach(painted, "approach")  # the wall stops it where it touches
            self._reach(start_w, "retreat")
            return None, painted
        self.fly(delay)
        return self._measure(start_w, u, hit + squeeze, rng), painted

    def aim(self, wait_rho: FloatArray, yaw_rad: float) -> FloatArray:
        """Where the tool would touch flying the plan exactly, (3,), ``R_w`` (NaN: no wall).

        The drone truly at the believed waiting point, no hover error, heading truly as
        planned: what is left of the dot's error is the estimate's.
        """
        start_w = self.truth.to_w(wait_rho)
        u = rot2(self.truth.gamma_rad + yaw_rad) @ np.array([0.0, 1.0])
        hit = self.wall.hit(start_w[:2], u)
        if hit > self.cfg.max_travel_factor * self.cfg.waiting_distance_m:
            return np.full(3, np.nan)
        return np.array([*(start_w[:2] + max(hit, 0.0) * u), start_w[2]])

    def _measure(
        self, start_w: FloatArray, u: FloatArray, stop: float, rng: np.random.Generator
    ) -> FloatArray:
        """Contact detected after ``stop`` m of approach: record it and retreat."""
        where_w = np.array([*(start_w[:2] + stop * u), start_w[2]])
        self.fly(stop / self.cfg.approach_speed_mps)
        self.contacts += 1
        self.contacts_w.append(where_w)
        believed = self.truth.to_rho(where_w) + self.drift  # the drift at the contact
        measured = believed + rng.normal(0.0, self.loc.noise_m, 3)
        self.fly(stop / self.cfg.retreat_speed_mps)
        self._reach(where_w, "approach")
        self._reach(start_w, "retreat")
        return measured


def _probe_dot(dots: FloatArray, first: int) -> FloatArray:
    """§4.1's extra point: at the first dot's height, at the far horizontal end of the drawing."""
    x_first = dots[first, 0]
    lo, hi = dots[:, 0].min(), dots[:, 0].max()
    x_far = lo if abs(x_first - lo) >= abs(x_first - hi) else hi
    return np.array([x_far, 0.0, dots[first, 1]])


def probing_pass(dots: FloatArray, spacing_m: float) -> FloatArray:
    """Points to touch before painting: across the drawing's width every ``spacing_m`` (at
    least its two ends), at its mid-height, left to right; shape (P, 3), ``R_w`` (y = 0)."""
    lo, hi = float(dots[:, 0].min()), float(dots[:, 0].max())
    count = max(2, math.ceil((hi - lo) / spacing_m - 1e-9) + 1) if hi > lo else 1
    x = np.linspace(lo, hi, count)
    z = 0.5 * float(dots[:, 1].min() + dots[:, 1].max())
    return np.column_stack([x, np.zeros_like(x), np.full_like(x, z)])


def _target_w(dots: FloatArray, wall: Wall, update: str) -> FloatArray:
    """The ideal dot on the real wall: front projection (depth) or normal projection (fresco)."""
    x, z = dots[:, 0], dots[:, 1]
    if update == "depth":
        return np.column_stack([x, wall.depth(x), z])
    foot = wall.foot(np.column_stack([x, np.zeros_like(x)]))
    return np.column_stack([foot, z])


def _told(
    progress: Callable[[int, int], None] | None,
    flown: Callable[[FloatArray, Sequence[str]], None] | None,
    flight: _Flight,
    done: tuple[int, int],
    counted: int,
) -> int:
    """After a dot: ``progress`` told the dots ``done`` (of all), ``flown`` the legs recorded
    since the first ``counted``; the legs counted now."""
    if progress is not None:
        progress(*done)
    if flown is not None:
        flown(np.array(flight.path_w[counted:]), flight.leg_kinds[counted:])
    return len(flight.leg_kinds)


def run_mission(
    dots: FloatArray,
    *,
    wall: Wall,
    truth: Placement,
    estimator: str | Estimator = "svd",
    localization: str | Localization = "onboard",
    order: str = "paper",
    update: UpdateMode = "depth",
    wall_model: WallModel = "auto",
    config: MissionConfig | None = None,
    rng: np.random.Generator,
    progress: Callable[[int, int], None] | None = None,
    flown: Callable[[FloatArray, Sequence[str]], None] | None = None,
) -> MissionResult:
    """Paint ``dots`` on ``wall`` from a drone placed at ``truth``; estimate on line.

    Parameters
    ----------
    dots
        Reference dots ``(x_w, z_w)``, shape (N, 2), m; all on the wall.
    wall
        The real wall.
    truth
        The real placement ``(delta, gamma)`` of ``R_rho`` in ``R_w`` (unknown to the drone).
    estimator
        ``"none"``, ``"svd"`` (eq. 3-12, or eq. 13-15 on a segmented wall model) or
        ``"robust"``; or an :class:`Estimator` built by the caller (used as is, fresh).
    localization
        ``"onboard"``, ``"truth"`` or a :class:`Localization`.
    order
        ``"given"``, ``"paper"`` (right to left, top to bottom), ``"shortest"`` or
        ``"spread"`` (:mod:`skyquill.painting.order`).
    update
        Segment model only: ``"depth"`` (eq. 15) or ``"normal"`` (fresco).
    wall_model
        ``"flat"`` (rigid registration), ``"segments"`` (line per segment) or ``"auto"``
        (segments when the real wall has more than one).
    config
        Speeds, distances, faults; defaults to :class:`MissionConfig`.
    rng
        All randomness (hover error, IMU noise, drift, faults).
    progress
        Called as ``progress(done, total)`` after each dot.
    flown
        Called after each dot with the path points recorded since the last call (the
        first one repeated: (K + 1, 3), m) and their legs' kinds (K,); may raise to stop
        the mission (e.g. :class:`~skyquill.painting.flight.FlightClock`).
    """
    dots = check_dots("dots", dots)
    check_on_wall(dots, wall)
    cfg = config or MissionConfig()
    loc = (
        localization if isinstance(localization, Localization) else Localization.named(localization)
    )
    if update not in ("depth", "normal"):
        raise InputError(f"--update: got {update!r}, expected 'depth' or 'normal'")
    if wall_model not in ("auto", "flat", "segments"):
        raise InputError(f"wall_model: got {wall_model!r}, expected auto, flat or segments")
    segments = wall_model == "segments" or (wall_model == "auto" and wall.n_segments > 1)
    est = (
        estimator
        if isinstance(estimator, Estimator)
        else make_estimator(
            estimator, cfg.prior, segments=segments, update=update, localization=loc
        )
    )
    home_w = truth.to_w(np.zeros(3))
    probes = np.zeros((0, 3))
    if isinstance(est, JointEstimator) and cfg.probe_spacing_m > 0 and len(dots) > 1:
        probes = probing_pass(dots, cfg.probe_spacing_m)
    # after a probing pass the dots start in front of the take-off point, where a turned
    # estimate moves a dot least (the lever is the distance from the take-off point), and
    # move out as the contacts pin the placement down
    start_xz = np.array([home_w[0], probes[0, 2]]) if len(probes) else np.array([home_w[0], 0.0])
    route = order_dots(dots, order, start_xz=start_xz)
    flight = _Flight(wall=wall, truth=truth, loc=loc, config=cfg, rng=rng)
    painted = np.full((len(dots), 3), np.nan)
    aimed = np.full((len(dots), 3), np.nan)
    hist: dict[str, list[Any]] = {k: [] for k in _HISTORY_KEYS}
    target = _target_w(dots, wall, update)
    queue = [(-1, p) for p in probes]
    queue += [(int(i), np.array([dots[i, 0], 0.0, dots[i, 1]])) for i in route]
    if cfg.probe and isinstance(est, RigidEstimator) and len(dots) > 1:
        queue.insert(0, (-1, _probe_dot(dots, int(route[0]))))
    counted = 0  # legs handed to ``flown``
    for done, (i, ref_w) in enumerate(queue):
        est.tick(flight.landings, flight.t_air)
        plan, wait = _planned(est, ref_w, cfg)
        landed = flight.land_if_needed(wait)
        if landed:  # the localization was reset on the ground: plan again for the new flight
            est.tick(flight.landings, flight.t_air)
            plan, wait = _planned(est, ref_w, cfg)
        if i >= 0:
            aimed[i] = flight.aim(wait, plan.yaw_rad)
        key = (0, i) if i >= 0 else (1, done)
        measured, touch_w = flight.touch(wait, plan.yaw_rad, key)
        if measured is not None:
            est.tick(flight.landings, flight.t_air)
            est.update(ref_w, measured)
        if i >= 0:
            painted[i] = touch_w
        _record(
            hist, t=flight.t, dot=i, est=est, yaw=plan.yaw_rad, measured=measured, landed=landed
        )
        counted = _told(progress, flown, flight, (done + 1, len(queue)), counted)
    flight.transit(np.zeros(3))  # home for good
    errors = _errors(painted, target, update)
    aim_errors = _errors(aimed, target, update)
    dot_of = np.array(hist["dot"], dtype=int)
    hist["error_m"] = list(np.where(dot_of >= 0, errors[np.maximum(dot_of, 0)], np.nan))
    return MissionResult(
        reference=dots,
        target_w=target,
        painted_w=painted,
        errors_m=errors,
        aim_errors_m=aim_errors,
        order=route,
        flight_time_s=flight.t,
        landings=flight.landings,
        contacts=flight.contacts,
        false_contacts=flight.false_contacts,
        missed_contacts=flight.missed,
        unsafe_waits=flight.unsafe,
        estimate=est.placement,
        truth=truth,
        history={k: np.array(v) for k, v in hist.items()},
        contacts_w=np.array(flight.contacts_w, dtype=float).reshape(-1, 3),
        lines_rho=_lines_rho(est),
        wall=wall,
        estimator=est.name,
        localization=loc.name,
        update=update if isinstance(est, SegmentEstimator | JointEstimator) else "rigid",
        transit_m=flight.transit_m,
        path_w=np.array(flight.path_w),
        leg_kinds=tuple(flight.leg_kinds),
        battery_s=cfg.battery_s,
        wall_fit=est.fit if isinstance(est, JointEstimator) else None,
    )


def _planned(est: Estimator, ref_w: FloatArray, cfg: MissionConfig) -> tuple[Plan, FloatArray]:
    """The estimator's plan for ``ref_w`` and its waiting point ``Delta`` before the target."""
    plan = est.plan(ref_w)
    wait = plan.target_rho.copy()
    wait[:2] -= cfg.waiting_distance_m * plan.direction_rho
    return plan, wait


def _lines_rho(est: Estimator) -> FloatArray:
    """The wall lines an estimator holds, ``[a, b, x_lo, x_hi]`` in ``R_rho``, (L, 4)."""
    if isinstance(est, SegmentEstimator):
        return line_params(est.lines)
    if isinstance(est, JointEstimator):
        return est.lines_rho()
    return np.zeros((0, 4))


_HISTORY_KEYS = (
    "t_s",
    "dot",
    "gamma_hat_rad",
    "delta_hat_w",
    "yaw_rad",
    "error_m",
    "measured",
    "landing",
)


def _record(
    hist: dict[str, list[Any]],
    *,
    t: float,
    dot: int,
    est: Estimator,
    yaw: float,
    measured: FloatArray | None,
    landed: bool,
) -> None:
    """Append one approach to the history (the estimate *after* its update)."""
    p = est.placement
    values = (t, dot, p.gamma_rad, p.delta_w.copy(), yaw, math.nan, measured is not None, landed)
    for key, value in zip(_HISTORY_KEYS, values, strict=True):
        hist[key].append(value)


def _errors(painted: FloatArray, target: FloatArray, update: str) -> FloatArray:
    """Per-dot error: front view ``(x, z)`` for depth, 3-D on the wall for normal, m."""
    cols = [0, 2] if update == "depth" else [0, 1, 2]
    out: FloatArray = np.linalg.norm(painted[:, cols] - target[:, cols], axis=1)
    return out
