"""The one protocol every exporter implements, and what they share.

An exporter takes the named trajectories of a plan (one per drone, any kind),
writes its files, reads them back the way its consumer does and reports the
largest difference from the trajectories it was given: what is verified is
what is delivered.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from skyquill.colors import check_rgb
from skyquill.coverage.geo import GeoFrame
from skyquill.errors import InputError
from skyquill.io.trajectory_json import PlannedTrajectory, pen_down
from skyquill.trajectory import Trajectory, dense_times
from skyquill.trajectory.window import time_window
from skyquill.validation import as_float
from skyquill.verify import verify

#: A drone's name (the stem of its trajectory file) and its planned trajectory.
NamedPlan = tuple[str, PlannedTrajectory]
#: The largest relative excess over the plan's limits a delivered file may show, per
#: derivative order (issue 26: speed and acceleration at most 1 %, jerk at most 5 % over,
#: what a consumer's grid rounding cannot avoid); beyond it an export refits or refuses.
ALLOWED_EXCESS = {1: 0.01, 2: 0.01, 3: 0.05}
#: Below this relative excess a delivered file meets a limit: float rounding of the read-back
#: (float32 polynomials on a Crazyflie round a limit the plan touches up by ~1.2e-7).
EXACT_TOLERANCE = 1e-6
#: Names of the limited derivative orders in summaries.
ORDER_NAMES = {1: "speed", 2: "acceleration", 3: "jerk"}


@dataclass(frozen=True)
class ExportOptions:
    """What an export may be asked for.

    Attributes
    ----------
    rate_hz
        Sample rate of the sampled formats, Hz.
    light_rgb
        The light colour while the pen is down (Skybrush formats), three integers 0..255;
        the light is off while the pen is up.
    origin
        The plan's geographic frame (``summary.json``'s ``geo``), or None for a plan in
        local metres: px4-global needs it, skyc records it as the show's location.
    """

    rate_hz: float = 100.0
    light_rgb: tuple[int, int, int] = (255, 255, 255)
    origin: GeoFrame | None = None

    def __post_init__(self) -> None:
        as_float("rate_hz", self.rate_hz, positive=True)
        object.__setattr__(self, "light_rgb", check_rgb("light_rgb", self.light_rgb))
        if self.origin is not None and not isinstance(self.origin, GeoFrame):
            raise InputError(
                f"origin: got {type(self.origin).__name__}, expected a GeoFrame or None"
            )


@dataclass(frozen=True)
class ExportReport:
    """What an exporter wrote and how well its consumer will reproduce the plan.

    Attributes
    ----------
    format
        The exporter's name.
    files
        Every file written, in flight order.
    exact
        Whether the format holds the trajectory exactly (up to float rounding).
    max_error_m
        Largest distance between the trajectory read back from the files (as
        the consumer reads them) and the plan, over dense samples, m.
    message
        One sentence for the command line.
    details
        Format-specific numbers (pieces, uploads, rate, segments, ...).
    delivered
        Per drone, the check of what its consumer will fly
        (:func:`check_delivered`).
    """

    format: str
    files: tuple[Path, ...]
    exact: bool
    max_error_m: float
    message: str
    details: dict[str, Any] = field(default_factory=dict)
    delivered: tuple[DeliveredCheck, ...] = ()

    @property
    def as_played(self) -> AsPlayed:
        """The verdict over every drone's delivered check."""
        return AsPlayed.of(self.delivered)

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: ``<out file name>.summary.json``."""
        return {
            "format": self.format,
            "files": [str(f) for f in self.files],
            "exact": self.exact,
            "max_error_m": self.max_error_m,
            "message": self.message,
            **self.details,
            "as_played": self.as_played.as_dict(),
            "delivered": [d.as_dict() for d in self.delivered],
        }


@dataclass(frozen=True)
class DeliveredCheck:
    """One drone's exported trajectory as its consumer will fly it, checked.

    Attributes
    ----------
    drone
        The drone's name.
    max_error_m
        Largest distance from the plan over dense samples, m.
    pen_down_max_error_m
        The same over the pen-down windows only (0 when the plan has none), m.
    limit_excess
        Largest relative excess over the plan's limits found by the dense
        check of the read-back (0 when every limit holds).
    limits
        Per limit: label, largest value, relative excess (``Verification.limits_report``).
    excess_by_order
        The largest relative excess of the speed, acceleration and jerk limits (0 for an
        order without a limit).
    """

    drone: str
    max_error_m: float
    pen_down_max_error_m: float
    limit_excess: float
    limits: tuple[dict[str, Any], ...]
    excess_by_order: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @property
    def within_allowed(self) -> bool:
        """Whether every order's excess is within :data:`ALLOWED_EXCESS`."""
        return all(e <= ALLOWED_EXCESS[n] for n, e in enumerate(self.excess_by_order, start=1))

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {
            "drone": self.drone,
            "max_error_m": self.max_error_m,
            "pen_down_max_error_m": self.pen_down_max_error_m,
            "limit_excess": self.limit_excess,
            "excess": {ORDER_NAMES[n]: e for n, e in enumerate(self.excess_by_order, start=1)},
            "within_allowed": self.within_allowed,
            "limits": list(self.limits),
        }


@dataclass(frozen=True)
class AsPlayed:
    """The verdict on an export's files as their consumer plays them, over every drone.

    Attributes
    ----------
    excess
        The largest relative excess of the speed, acceleration and jerk limits.
    """

    excess: tuple[float, float, float]

    @classmethod
    def of(cls, delivered: Sequence[DeliveredCheck]) -> AsPlayed:
        """The worst of ``delivered`` per order."""
        worst = np.max([d.excess_by_order for d in delivered], axis=0) if delivered else [0.0] * 3
        return cls((float(worst[0]), float(worst[1]), float(worst[2])))

    @property
    def exact(self) -> bool:
        """Every limit met (up to float rounding, :data:`EXACT_TOLERANCE`)."""
        return max(self.excess) <= EXACT_TOLERANCE

    @property
    def within_allowed(self) -> bool:
        """Every limit met or over by no more than :data:`ALLOWED_EXCESS`."""
        return all(e <= ALLOWED_EXCESS[n] for n, e in enumerate(self.excess, start=1))

    @property
    def verdict(self) -> str:
        """``every limit met``, ``within the grid's tolerance`` or ``limits exceeded``."""
        if self.exact:
            return "every limit met"
        return "within the delivery tolerance" if self.within_allowed else "limits exceeded"

    def describe(self) -> str:
        """One phrase for a message: the verdict and, unless exact, the excess per order."""
        if self.exact:
            return "every limit met"
        over = ", ".join(
            f"{ORDER_NAMES[n]} +{100 * e:.2f} % (allowed {100 * ALLOWED_EXCESS[n]:g} %)"
            for n, e in enumerate(self.excess, start=1)
            if e > EXACT_TOLERANCE
        )
        return f"{self.verdict}: {over}"

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: ``summary.json``'s ``as_played``."""
        return {
            "verdict": self.verdict,
            "every_limit_met": self.exact,
            "within_allowed": self.within_allowed,
            "relative_excess": {ORDER_NAMES[n]: e for n, e in enumerate(self.excess, start=1)},
            "allowed_relative_excess": {ORDER_NAMES[n]: a for n, a in ALLOWED_EXCESS.items()},
        }


def check_delivered(
    drone: str, planned: PlannedTrajectory, back: Trajectory, orders: Sequence[int] = (1, 2, 3)
) -> DeliveredCheck:
    """Check ``back`` (the export read back with its consumer's arithmetic) against the plan.

    The dense limit check runs on ``back`` itself, so a limit broken by the
    format's rounding or resampling shows here; the distances are measured at
    the plan's dense times (a file whose clock ends a rounding early is held
    at its end). ``orders``: the derivatives the format holds (a linear
    interpolation's acceleration is impulses: only its speed means something);
    the others are reported but do not count in ``excess_by_order``.
    """
    t = dense_times(planned.trajectory.breakpoints)
    back_p = back.evaluate(np.minimum(t, back.duration))
    error = np.linalg.norm(planned.trajectory.evaluate(t) - back_p, axis=1)
    down = pen_down(t, planned.pen_windows_s).astype(bool)
    check = verify(back, planned.limits, guaranteed=False)
    return DeliveredCheck(
        drone,
        float(error.max()),
        float(error[down].max()) if down.any() else 0.0,
        check.max_excess,
        tuple(check.limits_report()),
        (
            check.excess(1) if 1 in orders else 0.0,
            check.excess(2) if 2 in orders else 0.0,
            check.excess(3) if 3 in orders else 0.0,
        ),
    )


class Exporter(Protocol):
    """A format: a name, its file suffix, a line of help, and the export itself."""

    @property
    def name(self) -> str: ...

    @property
    def suffix(self) -> str: ...

    @property
    def help(self) -> str: ...

    def __call__(
        self, plans: Sequence[NamedPlan], out: Path, options: ExportOptions
    ) -> ExportReport: ...


def mission_plan(planned: PlannedTrajectory) -> PlannedTrajectory:
    """The mission part of ``planned`` on its own clock, with its pen windows moved along."""
    phases = planned.flight()
    start, end = phases.mission_s
    if end <= start:
        raise InputError(
            f"plan: got a mission of no length (at {start:.2f} s), expected a flight between "
            "two rests in the air"
        )
    windows = tuple(
        (max(a, start) - start, min(b, end) - start)
        for a, b in planned.pen_windows_s
        if b >= start and a <= end
    )
    colors = tuple(
        c
        for (a, b), c in zip(planned.pen_windows_s, planned.pen_rgb, strict=False)
        if b >= start and a <= end
    )
    return PlannedTrajectory(
        time_window(planned.trajectory, start, end), windows, planned.limits, colors
    )


def target(out: Path, name: str, several: bool, suffix: str) -> Path:
    """The file for drone ``name``: ``out`` itself, or ``<out stem>_<name><suffix>`` for several."""
    return out.with_name(f"{out.stem}_{name}{suffix}") if several else out.with_suffix(suffix)
