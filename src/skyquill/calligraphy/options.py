"""The knobs of a writing flight (:class:`WritingOptions`) and what they may be.

Checked when built: every value a writing flight is planned with
(:func:`~skyquill.calligraphy.mission.plan_writing`) is validated here once.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.brush import Brush
from skyquill.calligraphy.fidelity import GRAVITY
from skyquill.errors import InputError
from skyquill.limits import DerivativeLimit, VehicleLimits
from skyquill.targets import Strategy as TargetStrategy
from skyquill.targets import UploadTarget
from skyquill.validation import FloatArray, as_float, as_int

#: Character sizes accepted, m. Below 1 cm a character is narrower than a brush
#: stroke and its 1 % tolerance (0.1 mm) is finer than a quadrotor's position
#: estimate (motion capture: ~1 mm), so "within tolerance" would mean nothing;
#: above 20 m the route (sampled every TRANSIT_SPACING_M) and the flight grow
#: past a board and a battery: that is sky writing, not calligraphy.
SIZE_RANGE_M = (0.01, 20.0)
#: Weight of the plane-deviation cost on a sky board (paper 003 §5.3), per control
#: point active from the first stroke to the last, against the jerk cost and the
#: stroke samples' 1e4 each (~5 per knot span at 1 m/s). Measured
#: (bench/sky_distortion.py, bench/results/sky_distortion.json): on "light" on a
#: board at yaw 30°, tilt 20°, the largest distance off the plane falls from
#: 1.43 mm (0) to 1.28, 0.79, 0.34, 0.12 mm at 1e3, 1e4, 1e5, 1e6, with the same
#: flight time and in-plane fidelity; on paper 003's M with per-axis limits from
#: 48.8 mm to 30, 20, 5.8, 0.9 mm, but above 1e5 the M misses its vertices by
#: more (82.7 -> 84.8 mm): 1e5 keeps the drawing within a millimetre of the
#: plane without trading the strokes for it.
PLANE_WEIGHT = 1e5
#: The ways to fit a vehicle's upload budget (:mod:`skyquill.calligraphy.budget`).
TARGET_STRATEGIES: tuple[TargetStrategy, ...] = ("one-upload", "split")


@dataclass(frozen=True)
class WritingOptions:
    """Knobs of :func:`plan_writing` (SI units).

    Attributes
    ----------
    size_m
        The strokes' larger side is scaled to this, m, within
        :data:`SIZE_RANGE_M` (paper 000: 0.5 m boards).
    limits
        The vehicle's limits (``vmax`` the speed, ``amax`` and ``jmax`` the
        norms; per-axis boxes only as ``*_axis``).
    norm_sides
        ``None``: norms held exactly (second-order cones); an integer ``m``: by
        the inscribed polytope with ``m`` sides.
    tolerance_m
        Fidelity tolerance; ``None``: 1 % of ``size_m``.
    turning_threshold_m
        Split-and-merge threshold; ``None``: a quarter of the tolerance.
    data_weight, turning_weight, transit_weight, lift_weight
        Weights of the stroke samples, turning points, transit samples and
        (fitting the tip) the samples of the brush's lifts onto and off the
        board, against the jerk cost.
    knot_interval
        Seconds per knot span.
    degree
        Spline degree.
    brush
        The brush: its length (tip to vehicle, along the board normal when
        level), the bearing's travel and the pressing depth that sets the
        stroke width (:class:`~skyquill.calligraphy.brush.Brush`).
    follow
        What is fitted to the strokes on a horizontal board: ``"tip"`` (the
        default) the swung brush tip, which leaves the ink (module
        docstring); ``"path"`` the untilted tip, i.e. the vehicle's path
        offset by the brush (paper 000), which is faster to plan and leaves
        the ink up to a few centimetres off at these limits. A wall is
        always written by the path (the brush is not hanging there).
    resegment
        Time re-segmentation after the first feasible, faithful plan (paper
        000 §5.4): ``"fixed"`` keeps the total time, ``"free"`` lets it move
        at a time penalty that makes the initial total time stationary under
        uniform scaling (without a penalty the jerk cost falls for ever as
        time grows); ``"off"`` skips it.
    resegment_iterations
        Descent steps at most (each is one solve and one analytic gradient). The
        descent is quasi-Newton (L-BFGS): six of its steps leave a writing route's
        jerk cost ~1 % below the eight gradient steps (Barzilai-Borwein) that were
        the default before, in three quarters of the solves.
    stretch_factor, max_stretches
        Timing stretch when infeasible or unfaithful.
    best_effort
        Return the last plan even when its pen-down path is beyond the
        tolerance (``Mission.faithful`` is then False); by default that is an
        :class:`~skyquill.errors.InfeasibleError` with the measured deviation.
    target
        Plan for a vehicle's trajectory memory (``--target``): splines of the
        target's degree (``degree`` is then ignored), at most
        :attr:`~skyquill.targets.UploadTarget.max_pieces` knot spans per
        upload, uploads changed at rest with a hover between them
        (:mod:`skyquill.calligraphy.budget`). ``None``: one spline at
        ``knot_interval``.
    target_strategies
        The ways to fit ``target`` tried, in order (default
        :data:`TARGET_STRATEGIES`, cheapest flight first): ``"one-upload"`` and
        ``"split"``; one alone measures it (the budget benchmark).
    plane_weight
        On a sky board, the weight of paper 003's plane-deviation cost (§3.3.3,
        §5.3) that keeps the flight on the board's plane from the first stroke
        to the last, so the drawing is not distorted seen from the side
        (default :data:`PLANE_WEIGHT`); 0 disables it. Unused on other boards.
    """

    size_m: float = 0.5
    limits: VehicleLimits = field(default_factory=lambda: VehicleLimits(1.0, 2.0, 10.0))
    norm_sides: int | None = None
    tolerance_m: float | None = None
    turning_threshold_m: float | None = None
    data_weight: float = 1e4
    turning_weight: float = 1e5
    transit_weight: float = 1e2
    lift_weight: float = 1e4
    knot_interval: float = 0.05
    degree: int = 5
    brush: Brush = field(default_factory=Brush)
    follow: Literal["tip", "path"] = "tip"
    resegment: Literal["off", "fixed", "free"] = "fixed"
    resegment_iterations: int = 6
    stretch_factor: float = 1.25
    max_stretches: int = 8
    best_effort: bool = False
    target: UploadTarget | None = None
    target_strategies: tuple[TargetStrategy, ...] = TARGET_STRATEGIES
    plane_weight: float = PLANE_WEIGHT

    def __post_init__(self) -> None:
        if not isinstance(self.limits, VehicleLimits):
            raise InputError(f"limits: got {type(self.limits).__name__}, expected VehicleLimits")
        if not isinstance(self.brush, Brush):
            raise InputError(f"brush: got {type(self.brush).__name__}, expected Brush")
        if self.follow not in ("tip", "path"):
            raise InputError(f"follow: got {self.follow!r}, expected 'tip' or 'path'")
        if self.target is not None and not isinstance(self.target, UploadTarget):
            raise InputError(
                f"target: got {type(self.target).__name__}, expected UploadTarget or None"
            )
        strategies = tuple(self.target_strategies)
        if (
            not strategies
            or len(set(strategies)) < len(strategies)
            or not set(strategies) <= set(TARGET_STRATEGIES)
        ):
            raise InputError(
                f"target_strategies: got {strategies!r}, expected some of "
                f"{TARGET_STRATEGIES!r}, each once"
            )
        self.limits.timing_bounds()  # the route is timed with a speed and an acceleration
        for name in ("size_m", "knot_interval", "stretch_factor"):
            as_float(name, getattr(self, name), positive=True)
        weights = ("data_weight", "turning_weight", "transit_weight", "lift_weight", "plane_weight")
        for name in weights:
            as_float(name, getattr(self, name), nonneg=True)
        low, high = SIZE_RANGE_M
        if not low <= self.size_m <= high:
            raise InputError(
                f"size_m: got {self.size_m:g} m, expected {low:g} to {high:g} m (a character "
                "legible with a brush, within the position accuracy, on one board)"
            )
        for name in ("tolerance_m", "turning_threshold_m"):
            if getattr(self, name) is not None:
                as_float(name, getattr(self, name), positive=True)
        if self.norm_sides is not None:
            as_int("norm_sides", self.norm_sides, low=3, high=1024)
        as_int("degree", self.degree, low=3, high=7)
        # Each stretch and each descent step is one more solve (bounded work).
        as_int("max_stretches", self.max_stretches, low=0, high=50)
        as_int("resegment_iterations", self.resegment_iterations, low=0, high=100)
        if self.resegment not in ("off", "fixed", "free"):
            raise InputError(
                f"resegment: got {self.resegment!r}, expected 'off', 'fixed' or 'free'"
            )
        if self.stretch_factor <= 1.0:
            raise InputError(f"stretch_factor: got {self.stretch_factor:g}, expected > 1")

    @property
    def tolerance(self) -> float:
        """Fidelity tolerance, m."""
        return self.tolerance_m if self.tolerance_m is not None else 0.01 * self.size_m

    def derivative_limits(self) -> tuple[DerivativeLimit, ...]:
        """The vehicle limits in 3-D, as the engine imposes them."""
        return self.limits.derivative_limits(3, sides=self.norm_sides)

    def follows_tip(self, board: Board) -> bool:
        """Whether the swung tip is fitted on ``board`` (``follow="tip"``, horizontal, a brush)."""
        return self.follow == "tip" and board.kind == "horizontal" and self.brush.length_m > 0

    def tip_gain(self, board: Board) -> FloatArray | None:
        """The swung tip's acceleration gain ``(-L/g, -L/g, 0)``, s^2; ``None`` for the path."""
        if not self.follows_tip(board):
            return None
        c = -self.brush.length_m / GRAVITY
        return np.array([c, c, 0.0])
