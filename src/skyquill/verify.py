"""The dense check every returned trajectory carries (DESIGN.md, "verified").

The trajectory is sampled at >= 20 points per knot span and >= 10,000 points
in all; the largest speed, per-axis acceleration and jerk, the horizontal
norms, and the largest relative excess over each limit asked for are
reported. A limit the method guarantees through the convex hull must show an
excess of 0 (to 1e-9 relative); the check says for each limit whether it was
guaranteed.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any, Protocol

import numpy as np

from skyquill.limits import DerivativeLimit
from skyquill.validation import FloatArray


class Region(Protocol):
    """A convex polytope ``{p : A p <= b}`` to be respected on ``[t_start, t_end]``."""

    @property
    def A(self) -> FloatArray: ...  # noqa: N802 -- the papers' name

    @property
    def b(self) -> FloatArray: ...

    @property
    def t_start(self) -> float: ...

    @property
    def t_end(self) -> float: ...


class DenseTrajectory(Protocol):
    """What the dense check needs of a trajectory."""

    @property
    def duration(self) -> float: ...

    def evaluate(self, t: FloatArray, order: int = 0) -> FloatArray: ...

    def dense_times(self) -> FloatArray: ...

    def dense_derivatives(self, orders: Sequence[int]) -> dict[int, FloatArray]: ...


@dataclass(frozen=True)
class LimitCheck:
    """One limit checked on the dense samples.

    Attributes
    ----------
    label
        e.g. ``"jerk cylinder (8-gon)"``.
    order
        Derivative order.
    max_value
        Largest per-axis magnitude (box), horizontal norm (cylinder) or norm (norm limit).
    relative_excess
        ``max(0, value - bound) / |bound|`` over all samples and axes.
    guaranteed
        True when the planner imposed the limit through the convex hull.
    """

    label: str
    order: int
    max_value: float
    relative_excess: float
    guaranteed: bool


@dataclass(frozen=True)
class Verification:
    """Result of the dense check.

    Attributes
    ----------
    n_samples
        Number of sample times.
    max_speed
        Largest ``|v|``, m/s.
    max_velocity, max_acc, max_jerk
        Largest absolute value per axis, tuples of length d.
    max_horizontal_acc, max_horizontal_jerk
        Largest norm of the first two components.
    checks
        One entry per limit asked for.
    corridor_excess_m
        Largest ``A p - b`` (m for unit normals) over the corridor windows;
        ``<= 0`` means inside.
    max_excess
        Largest relative excess over all limits (0 when every limit holds).
    """

    n_samples: int
    max_speed: float
    max_velocity: tuple[float, ...]
    max_acc: tuple[float, ...]
    max_jerk: tuple[float, ...]
    max_horizontal_acc: float
    max_horizontal_jerk: float
    checks: tuple[LimitCheck, ...]
    corridor_excess_m: float
    max_excess: float

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary."""
        return asdict(self)

    def limits_report(self) -> list[dict[str, Any]]:
        """Per limit: label, largest value, relative excess, guaranteed (for summary.json)."""
        return [
            {
                "label": c.label,
                "max_value": c.max_value,
                "relative_excess": c.relative_excess,
                "guaranteed": c.guaranteed,
            }
            for c in self.checks
        ]


def verify(
    traj: DenseTrajectory,
    limits: Sequence[DerivativeLimit] = (),
    corridors: Sequence[Region] = (),
    guaranteed: bool = True,
) -> Verification:
    """Check ``traj`` densely against ``limits`` and ``corridors``.

    Parameters
    ----------
    traj
        Any trajectory with ``dense_times``.
    limits
        Limits to report on.
    corridors
        Regions with time windows; the largest excursion is reported.
    guaranteed
        Whether the planner imposed these limits through the convex hull.
    """
    t = traj.dense_times()
    orders = sorted({1, 2, 3} | {lim.order for lim in limits} | ({0} if corridors else set()))
    derivs = traj.dense_derivatives(orders)
    checks = []
    for lim in limits:
        value, excess = lim.relative_excess(derivs[lim.order])
        checks.append(LimitCheck(lim.label, lim.order, value, excess, guaranteed))
    corridor_excess = -np.inf
    for region in corridors:
        inside = (t >= region.t_start) & (t <= region.t_end)
        if np.any(inside):
            p = derivs[0][inside]
            corridor_excess = max(corridor_excess, float((p @ region.A.T - region.b).max()))

    # One (d, N) copy per order: reductions along contiguous rows are ~30x
    # faster than along axis 0 of an (N, 3) array.
    by_axis = {n: np.ascontiguousarray(derivs[n].T) for n in (1, 2, 3)}

    def horizontal(x: FloatArray) -> float:
        return float(np.sqrt((x[0] ** 2 + x[1] ** 2).max())) if x.shape[0] >= 2 else 0.0

    peaks = {n: np.abs(x).max(axis=1) for n, x in by_axis.items()}
    return Verification(
        n_samples=int(t.size),
        max_speed=float(np.sqrt((by_axis[1] ** 2).sum(axis=0).max())),
        max_velocity=tuple(float(x) for x in peaks[1]),
        max_acc=tuple(float(x) for x in peaks[2]),
        max_jerk=tuple(float(x) for x in peaks[3]),
        max_horizontal_acc=horizontal(by_axis[2]),
        max_horizontal_jerk=horizontal(by_axis[3]),
        checks=tuple(checks),
        corridor_excess_m=float(corridor_excess) if corridors else 0.0,
        max_excess=max((c.relative_excess for c in checks), default=0.0),
    )
