"""What a show check found: violations, measured extremes, and the report that holds them."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

from skyquill.show.separation import Separation

#: Units of each check's values.
UNITS = {
    "separation": "m",
    "speed_xy": "m/s",
    "speed_up": "m/s",
    "speed_down": "m/s",
    "acceleration": "m/s^2",
    "max_altitude": "m",
    "min_altitude": "m",
    "geofence": "m",
    "geofence_ceiling": "m",
}


@dataclass(frozen=True)
class Violation:
    """One limit broken by one drone (or a pair, for the separation).

    Attributes
    ----------
    check
        Which limit (a key of :data:`UNITS`).
    drones
        The drone's name, or the two names of a pair.
    first_time_s
        The first time it is broken, s on the show clock.
    worst
        The worst value found (for ``geofence``: the signed distance to the
        fence, negative outside), in the check's unit.
    limit
        The limit, same unit.
    margin
        How far within the limit the worst value is: negative here.
    """

    check: str
    drones: tuple[str, ...]
    first_time_s: float
    worst: float
    limit: float
    margin: float


@dataclass(frozen=True)
class Measured:
    """The worst value of one check over the whole show.

    Attributes
    ----------
    check
        Which quantity (a key of :data:`UNITS`).
    value
        Its worst value (largest, or smallest for a lower limit).
    limit
        The limit it was checked against, or ``None``.
    drone
        Where it was found, and when (s on the show clock).
    """

    check: str
    value: float
    limit: float | None
    drone: str
    time_s: float


@dataclass(frozen=True)
class ShowReport:
    """The result of ``skyquill check``.

    Attributes
    ----------
    drones
        The drones' names, in order.
    duration_s
        Length of the show, s.
    separation
        The guaranteed closest approach (drone indices refer to ``drones``).
    violations
        Every limit broken, separation first, then by time.
    measured
        The worst value of every per-drone check.
    """

    drones: tuple[str, ...]
    duration_s: float
    separation: Separation
    violations: tuple[Violation, ...]
    measured: tuple[Measured, ...]

    @property
    def passed(self) -> bool:
        """Whether the show keeps every limit."""
        return not self.violations

    def as_dict(self) -> dict[str, Any]:
        """A JSON-ready summary (``inf``/``nan`` as ``None``)."""
        sep = self.separation
        pair = sep.attained_drones
        summary: dict[str, Any] = _finite(
            {
                "passed": self.passed,
                "drones": list(self.drones),
                "duration_s": self.duration_s,
                "separation": {
                    "minimum_m": sep.minimum_m,
                    "guaranteed_lower_bound_m": sep.lower_bound_m,
                    "attained_m": sep.attained_m,
                    "attained_drones": [self.drones[i] for i in pair] if pair[0] >= 0 else [],
                    "attained_time_s": sep.attained_time_s,
                    "pairs": sep.pairs,
                    "pairs_examined": sep.pairs_examined,
                    "intervals_bounded": sep.intervals,
                    "passed": sep.passed,
                },
                "violations": [asdict(v) | {"unit": UNITS[v.check]} for v in self.violations],
                "measured": [asdict(m) | {"unit": UNITS[m.check]} for m in self.measured],
            }
        )
        return summary


def _finite(value: Any) -> Any:
    """``value`` with non-finite floats replaced by ``None`` (strict JSON) and tuples as lists."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    return value
