"""The one dense check of every trajectory kind (docs/architecture.md, "verified").

:func:`verify` takes any :class:`~skyquill.trajectory.Trajectory`: the
B-spline a planner holds, or the file a command wrote, read back. The
trajectory is sampled at >= 20 points per span between its breakpoints and
>= 10,000 points in all; the largest speed, per-axis acceleration and jerk, the horizontal
norms, and the largest relative excess over each limit asked for are
reported. A limit the method guarantees through the convex hull must show an
excess of 0 (to 1e-9 relative); the check says for each limit whether it was
guaranteed.
"""

from __future__ import annotations

import pickle
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np

from skyquill.limits import DerivativeLimit
from skyquill.trajectory.base import Trajectory, check_times, derivatives
from skyquill.trajectory.polynomial import PiecewisePolynomial
from skyquill.trajectory.sequence import RestToRestSequence
from skyquill.validation import FloatArray

#: Samples evaluated at once: bounds the check's memory on long trajectories
#: (4 orders x 3 axes x 8 B x this = ~100 MB).
CHUNK = 1_000_000


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


@runtime_checkable
class FastDense(Protocol):
    """A trajectory with its own faster dense sampler (the B-spline's sparse design matrices)."""

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

    def excess(self, order: int) -> float:
        """Largest relative excess over the limits on derivative ``order`` (0 if none)."""
        return max((c.relative_excess for c in self.checks if c.order == order), default=0.0)

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
    traj: Trajectory,
    limits: Sequence[DerivativeLimit] = (),
    corridors: Sequence[Region] = (),
    guaranteed: bool = True,
) -> Verification:
    """Check ``traj`` densely against ``limits`` and ``corridors``.

    A :class:`~skyquill.trajectory.RestToRestSequence` without corridors is checked piece
    by piece, and a trajectory checked before against the same limits is not checked
    again (:func:`_memo`): a coverage mission's check costs its transits, where it
    sampled every piece again (1.2 s of the 10 ha field's 6.6 s, after its pieces were
    checked in parallel).

    Parameters
    ----------
    traj
        Any trajectory kind.
    limits
        Limits to report on.
    corridors
        Regions with time windows; the largest excursion is reported.
    guaranteed
        Whether the planner imposed these limits through the convex hull (an
        approximate planner, such as the coverage speed LP, passes False).
    """
    if corridors:  # their windows are on this trajectory's clock: sampled as a whole
        return _checked(traj, limits, corridors, guaranteed)
    if isinstance(traj, RestToRestSequence):
        # At rest where its pieces meet, each piece's check covers its side of every join:
        # the pieces' checks are the sequence's (each as dense or denser), and a piece
        # checked before (a coverage piece in the worker that planned it) is not again.
        return _merged([verify(p, limits, guaranteed=guaranteed) for p in traj.pieces])
    memo = _memo(traj)
    key = pickle.dumps((tuple(limits), guaranteed))
    if memo is not None and key in memo:
        return memo[key]
    check = _checked(traj, limits, (), guaranteed)
    if memo is not None:
        memo[key] = check
    return check


def _memo(traj: Trajectory) -> dict[bytes, Verification] | None:
    """The checks of ``traj`` made so far, by limits (None: it keeps no attributes).

    Kept in the trajectory's own attributes (as :func:`functools.cached_property` keeps
    its values), so a trajectory checked in a worker process comes back with its check.
    The trajectory kinds are frozen: what was checked is what is held.
    """
    attributes = getattr(traj, "__dict__", None)
    if attributes is None:
        return None
    memo: dict[bytes, Verification] = attributes.setdefault(_MEMO, {})
    return memo


#: The attribute :func:`_memo` keeps the checks in.
_MEMO = "_verified"


def _merged(parts: Sequence[Verification]) -> Verification:
    """The check of trajectories flown one after another, from each one's (the limits the
    same): the largest of every peak and excess, and the samples of all."""
    checks = tuple(
        LimitCheck(
            first.label,
            first.order,
            max(p.checks[i].max_value for p in parts),
            max(p.checks[i].relative_excess for p in parts),
            first.guaranteed,
        )
        for i, first in enumerate(parts[0].checks)
    )

    def per_axis(name: str) -> tuple[float, ...]:
        return tuple(float(x) for x in np.max([getattr(p, name) for p in parts], axis=0))

    return Verification(
        n_samples=sum(p.n_samples for p in parts),
        max_speed=max(p.max_speed for p in parts),
        max_velocity=per_axis("max_velocity"),
        max_acc=per_axis("max_acc"),
        max_jerk=per_axis("max_jerk"),
        max_horizontal_acc=max(p.max_horizontal_acc for p in parts),
        max_horizontal_jerk=max(p.max_horizontal_jerk for p in parts),
        checks=checks,
        corridor_excess_m=0.0,
        max_excess=max((c.relative_excess for c in checks), default=0.0),
    )


def _checked(
    traj: Trajectory,
    limits: Sequence[DerivativeLimit],
    corridors: Sequence[Region],
    guaranteed: bool,
) -> Verification:
    """:func:`verify`'s dense sampling of ``traj``."""
    orders = sorted({1, 2, 3} | {lim.order for lim in limits} | ({0} if corridors else set()))
    peaks = _Peaks(limits, corridors, traj.dim)
    if isinstance(traj, FastDense):
        t = traj.dense_times()
        peaks.add(t, traj.dense_derivatives(orders))
    else:
        t = check_times(traj)
        flat = _constant_per_piece(traj, orders)
        per_piece = {} if not flat else derivatives(traj, traj.breakpoints[:-1], flat)
        sampled = [n for n in orders if n not in flat]
        for start in range(0, t.size, CHUNK):
            chunk = t[start : start + CHUNK]
            # (a linear interpolation has no order left to sample: no pieces looked up)
            values = derivatives(traj, chunk, sampled) if sampled else {}
            peaks.add(chunk, values | per_piece)
    return peaks.result(int(t.size), guaranteed)


def _constant_per_piece(traj: Trajectory, orders: Sequence[int]) -> list[int]:
    """The ``orders`` (>= 1) whose dense samples take one value per piece of ``traj``.

    A piecewise polynomial's derivatives of its degree and above are constant on each
    piece, and every piece holds dense samples (:func:`dense_times`: >= 20 per span; the
    last sample, at the end, lies in the last piece): their values are exactly the values
    at the pieces' starts, so every maximum over them is the same, bit for bit, at one
    evaluation per piece instead of 20 or more (all of a linear interpolation's, such as a
    Skybrush CSV read back; a cubic's jerk). Position (order 0) stays sampled: the corridors
    are checked at the times of its samples.
    """
    if not isinstance(traj, PiecewisePolynomial):
        return []
    return [n for n in orders if n >= max(1, traj.degree)]


class _Peaks:
    """Running maxima over chunks of dense samples."""

    def __init__(self, limits: Sequence[DerivativeLimit], corridors: Sequence[Region], dim: int):
        self.limits, self.corridors = tuple(limits), tuple(corridors)
        self.limit_values = [0.0] * len(self.limits)
        self.limit_excess = [0.0] * len(self.limits)
        self.speed = 0.0
        self.axis = {n: np.zeros(dim) for n in (1, 2, 3)}
        self.horizontal = {2: 0.0, 3: 0.0}
        self.corridor = -np.inf

    def add(self, t: FloatArray, derivs: dict[int, FloatArray]) -> None:
        for i, lim in enumerate(self.limits):
            value, excess = lim.relative_excess(derivs[lim.order])
            self.limit_values[i] = max(self.limit_values[i], value)
            self.limit_excess[i] = max(self.limit_excess[i], excess)
        for region in self.corridors:
            inside = (t >= region.t_start) & (t <= region.t_end)
            if np.any(inside):
                excursion = float((derivs[0][inside] @ region.A.T - region.b).max())
                self.corridor = max(self.corridor, excursion)
        # One (d, N) copy per order: reductions along contiguous rows are ~30x
        # faster than along axis 0 of an (N, 3) array.
        by_axis = {n: np.ascontiguousarray(derivs[n].T) for n in (1, 2, 3)}
        self.speed = max(self.speed, float(np.sqrt((by_axis[1] ** 2).sum(axis=0).max())))
        for n, x in by_axis.items():
            self.axis[n] = np.maximum(self.axis[n], np.abs(x).max(axis=1))
            if n in self.horizontal and x.shape[0] >= 2:
                peak = float(np.sqrt((x[0] ** 2 + x[1] ** 2).max()))
                self.horizontal[n] = max(self.horizontal[n], peak)

    def result(self, n_samples: int, guaranteed: bool) -> Verification:
        checks = tuple(
            LimitCheck(lim.label, lim.order, value, excess, guaranteed)
            for lim, value, excess in zip(
                self.limits, self.limit_values, self.limit_excess, strict=True
            )
        )
        return Verification(
            n_samples=n_samples,
            max_speed=self.speed,
            max_velocity=tuple(float(x) for x in self.axis[1]),
            max_acc=tuple(float(x) for x in self.axis[2]),
            max_jerk=tuple(float(x) for x in self.axis[3]),
            max_horizontal_acc=self.horizontal[2],
            max_horizontal_jerk=self.horizontal[3],
            checks=checks,
            corridor_excess_m=float(self.corridor) if self.corridors else 0.0,
            max_excess=max((c.relative_excess for c in checks), default=0.0),
        )
