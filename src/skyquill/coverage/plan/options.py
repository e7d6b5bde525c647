"""The options of a coverage plan: the pattern, the swath, the limits and the budget."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from skyquill.coverage.deadline import (
    DEFAULT_TIME_LIMIT_S,
    check_time_limit,
)
from skyquill.coverage.paths import (
    ContourMode,
    DriftMode,
)
from skyquill.errors import InputError
from skyquill.limits import VehicleLimits
from skyquill.targets import UploadTarget
from skyquill.validation import as_float, as_int

Pattern = Literal["spiral", "zigzag", "zigzag-stop", "zigzag-jerk"]


PATTERNS: tuple[Pattern, ...] = ("spiral", "zigzag", "zigzag-stop", "zigzag-jerk")


CONTOUR_MODES: tuple[ContourMode, ...] = ("offset", "homothetic")


DRIFT_MODES: tuple[DriftMode, ...] = ("step", "lap")


@dataclass(frozen=True)
class CoverageOptions:
    """What to cover with and how.

    Attributes
    ----------
    width : float
        Coverage diameter (swath), m.
    limits : VehicleLimits
        ``vmax`` is the speed; acceleration and jerk are held either as norms
        (``amax``, ``jmax``: the default) or per axis (``amax_axis``,
        ``jmax_axis``: paper 001's limits), both the same kind.
    pattern : {"spiral", "zigzag", "zigzag-stop", "zigzag-jerk"}
        ``"zigzag-jerk"``: straight lanes joined by turns that are Ruckig's
        time-optimal motions under the limits (:mod:`~skyquill.coverage.jerk_zigzag`;
        ``epsilon`` is its lane spacing, ``delta`` and ``perimeter`` do not
        apply; tuned, it picks the lanes' direction, insets and turn depth).
    contours : {"offset", "homothetic"}
        Spiral rings: true inward offsets, or the paper's shrink (eq. 1-3).
    drift : {"step", "lap"}
        Spiral laps: whole rings joined by a step, or the paper's eq. 4 drift
        (which needs an extra undrifted outer lap; see
        :func:`~skyquill.coverage.paths.spiral_control_points`).
    epsilon : float
        Density factor in (0, 1]: rings and sweep lines ``epsilon * width``
        apart (more overlap, fewer gaps at corners, longer path).
    perimeter : bool
        Zigzag patterns: start with a lap around the region (sweeps the
        slivers that sweep-line ends leave along slanted sides).
    delta : float
        Distance of the corner control points from each corner, m (smaller:
        sharper corners, more coverage, slower).
    rate : float
        Setpoint rate, Hz (the control period of §2.2 is ``1 / rate``).
    altitude : float
        Flight height above the ground written to the setpoints, m, > 0.
    grid : int or None
        Speed-LP grid points; ``None`` picks them from the path length.
    norm_sides : int
        The acceleration and jerk norms are held in the speed LP by the
        inscribed regular polygon of this many sides (even, >= 4;
        ``norm_sides`` of :func:`~skyquill.coverage.speed.plan_speed`; 16 is
        within 2 % of the circle) and measured as norms.
    target : UploadTarget or None
        A vehicle's upload budget (:data:`skyquill.targets.TARGETS`): the
        planned path is then re-fitted into its uploads, degree-7 pieces flown
        rest to rest between uploads (:mod:`skyquill.coverage.target`).
    time_limit : float
        Wall-time budget of one plan (all of :func:`plan_tuned`'s trials
        together), s, > 0: the plan is returned within it (plus one step), or
        an ``InfeasibleError`` with family ``"time_limit"`` names the step it
        stopped at; a budget below the estimate (:data:`PLANNING_S_PER_M`
        times the estimated path length) is refused before any work.
    """

    width: float = 2.0
    limits: VehicleLimits = field(default_factory=lambda: VehicleLimits(3.0, 5.0, 3.0))
    pattern: Pattern = "spiral"
    contours: ContourMode = "offset"
    drift: DriftMode = "step"
    epsilon: float = 1.0
    perimeter: bool = False
    delta: float = 0.5
    rate: float = 50.0
    altitude: float = 2.0
    grid: int | None = None
    norm_sides: int = 16
    target: UploadTarget | None = None
    time_limit: float = DEFAULT_TIME_LIMIT_S

    def __post_init__(self) -> None:
        for name in ("width", "delta", "rate"):
            as_float(name, getattr(self, name), positive=True)
        _check_limits(self.limits)
        if as_float("altitude", self.altitude) <= 0.0:
            raise InputError(
                f"altitude: got {self.altitude:g} m, expected a height above the ground, > 0"
            )
        if self.pattern not in PATTERNS:
            raise InputError(f"pattern: got {self.pattern!r}, expected one of {PATTERNS}")
        if self.contours not in CONTOUR_MODES:
            raise InputError(f"contours: got {self.contours!r}, expected one of {CONTOUR_MODES}")
        if self.drift not in DRIFT_MODES:
            raise InputError(f"drift: got {self.drift!r}, expected one of {DRIFT_MODES}")
        if not 0.0 < as_float("epsilon", self.epsilon) <= 1.0:
            raise InputError(f"epsilon: got {self.epsilon!r}, expected a value in (0, 1]")
        if self.grid is not None:
            as_int("grid", self.grid, low=3, high=20_000)
        sides = as_int("norm_sides", self.norm_sides, low=4, high=1024)
        if sides % 2:
            raise InputError(f"norm_sides: got {sides}, expected an even integer from 4 to 1024")
        check_time_limit(self.time_limit)
        if self.target is not None and not isinstance(self.target, UploadTarget):
            name = type(self.target).__name__
            raise InputError(f"target: got {name}, expected an UploadTarget or None")

    @property
    def per_axis(self) -> bool:
        """Whether acceleration and jerk are per-axis bounds (else norms)."""
        return self.limits.amax is None

    @property
    def vmax(self) -> float:
        """Speed limit, m/s."""
        assert self.limits.vmax is not None  # checked at construction
        return self.limits.vmax

    @property
    def amax(self) -> float:
        """Acceleration limit (the norm, or per axis), m/s^2."""
        value = self.limits.amax_axis if self.per_axis else self.limits.amax
        assert value is not None  # checked at construction
        return value

    @property
    def jmax(self) -> float:
        """Jerk limit (the norm, or per axis), m/s^3."""
        value = self.limits.jmax_axis if self.per_axis else self.limits.jmax
        assert value is not None  # checked at construction
        return value

    @property
    def limit_norm_sides(self) -> int | None:
        """The LP's polygon for the norms, or None when the limits are per axis."""
        return None if self.per_axis else self.norm_sides


def _check_limits(limits: VehicleLimits) -> None:
    """The limits the speed LP can hold: a speed, and acceleration and jerk of one kind."""
    if not isinstance(limits, VehicleLimits):
        raise InputError(f"limits: got {type(limits).__name__}, expected VehicleLimits")
    if limits.vmax is None:
        raise InputError("limits.vmax: got None, expected the speed limit (m/s)")
    norms = (limits.amax is not None, limits.jmax is not None)
    axes = (limits.amax_axis is not None, limits.jmax_axis is not None)
    if not (norms == (True, True) and axes == (False, False)) and not (
        norms == (False, False) and axes == (True, True)
    ):
        raise InputError(
            f"limits: got amax={limits.amax}, jmax={limits.jmax}, amax_axis="
            f"{limits.amax_axis}, jmax_axis={limits.jmax_axis}; expected the acceleration and "
            "the jerk both as norms (amax, jmax) or both per axis (amax_axis, jmax_axis)"
        )
