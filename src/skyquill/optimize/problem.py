"""The smoothing-spline problem of paper 003 §3, as validated data.

A :class:`SmoothingProblem` says what is wanted of a clamped uniform B-spline
trajectory: how smooth (cost on derivatives), what nominal plan to stay close
to (points, lines, planes on time windows), what to hit exactly (points,
boundary conditions) and what never to leave (derivative limits, safe
corridors). :func:`skyquill.optimize.solve` turns it into a trajectory.

Every term validates itself at construction; :class:`SmoothingProblem`
checks that dimensions agree and that every time lies within the duration.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import scipy.optimize

from skyquill.errors import InputError
from skyquill.limits import BoxLimit, CylinderLimit, DerivativeLimit, NormLimit
from skyquill.spline import ClampedUniformBasis, HullKind, basis_for
from skyquill.validation import FloatArray, as_array, as_float, as_int, strictly_increasing


def _points_at_times(name: str, times: object, points: object) -> tuple[FloatArray, FloatArray]:
    t = as_array(f"{name}.times", times, ndim=1)
    p = as_array(f"{name}.points", points, ndim=2)
    if p.shape[0] != t.size:
        raise InputError(f"{name}.points: got {p.shape[0]} rows, expected one per time ({t.size})")
    if t.size == 0:
        raise InputError(f"{name}.times: got an empty array, expected at least one time")
    return t, p


def _window(name: str, t_start: float, t_end: float) -> None:
    lo = as_float(f"{name}.t_start", t_start)
    hi = as_float(f"{name}.t_end", t_end)
    if hi <= lo:
        raise InputError(f"{name} window: got [{lo:g}, {hi:g}] s, expected t_start < t_end")


@dataclass(frozen=True)
class PointDeviation:
    """Penalise ``weight * sum_i ||p(t_i) + c * a(t_i) - points_i||^2`` (paper 003 eq. 11-12).

    ``a`` is the acceleration and ``c = accel_gain`` a gain per axis (s^2),
    zero by default: then this is paper 003's point deviation. A non-zero gain
    puts the deviation on a point the acceleration moves linearly: the tip of
    a brush hanging ``L`` below a quadrotor swings by ``-(L / g) a_xy`` as it
    tilts (to first order), so ``c = (-L/g, -L/g, 0)`` fits the tip, not the
    vehicle (:mod:`skyquill.calligraphy.mission`).

    Parameters
    ----------
    times
        Shape (N,), s.
    points
        Shape (N, d), m.
    weight
        ``omega >= 0``.
    accel_gain
        Shape (d,), s^2, or ``None`` for zero.
    """

    times: FloatArray
    points: FloatArray
    weight: float = 1.0
    accel_gain: FloatArray | None = None

    def __post_init__(self) -> None:
        t, p = _points_at_times("points", self.times, self.points)
        as_float("points.weight", self.weight, nonneg=True)
        object.__setattr__(self, "times", t)
        object.__setattr__(self, "points", p)
        if self.accel_gain is not None:
            gain = as_array("points.accel_gain", self.accel_gain, shape=(p.shape[1],))
            object.__setattr__(self, "accel_gain", None if not np.any(gain) else gain)

    @classmethod
    def of_checked(
        cls,
        times: FloatArray,
        points: FloatArray,
        weight: float,
        accel_gain: FloatArray | None = None,
    ) -> PointDeviation:
        """The term of arrays the caller has already validated, without checking them again.

        For a planner that builds many problems from selections of the same
        checked arrays (a writing route's re-segmentation builds one per descent
        step, five terms each): ``times`` (N,) and ``points`` (N, d) finite
        float64, ``weight >= 0``, ``accel_gain`` (d,) finite or ``None``. A selection
        of a checked array is as finite as the array; converting and scanning it
        again per term was ~0.1 ms each. Empty ``times`` are still refused (the
        one property a selection can lose).
        """
        if times.size == 0 or points.shape != (times.size, points.shape[-1]):
            raise InputError(
                f"points: got times of shape {times.shape} and points of shape "
                f"{points.shape}, expected N >= 1 times and one point per time"
            )
        term = object.__new__(cls)
        object.__setattr__(term, "times", times)
        object.__setattr__(term, "points", points)
        object.__setattr__(term, "weight", weight)
        gain = None if accel_gain is None or not np.any(accel_gain) else accel_gain
        object.__setattr__(term, "accel_gain", gain)
        return term

    @cached_property
    def _groups(self) -> tuple[tuple[FloatArray, float], ...]:
        d = self.points.shape[1]
        gain = np.zeros(d) if self.accel_gain is None else self.accel_gain
        return tuple((np.asarray(gain == g, dtype=float), float(g)) for g in np.unique(gain))

    def axis_groups(self) -> list[tuple[FloatArray, float]]:
        """The axes that share a gain: ``[(mask (d,), gain), ...]``, one group if all do."""
        return list(self._groups)  # assembly, cost and gradient ask for it on every solve


@dataclass(frozen=True)
class Interpolation:
    """Pass exactly through ``points`` at ``times`` (paper 003 eq. 13)."""

    times: FloatArray
    points: FloatArray

    def __post_init__(self) -> None:
        t, p = _points_at_times("interpolation", self.times, self.points)
        strictly_increasing("interpolation.times", t)
        object.__setattr__(self, "times", t)
        object.__setattr__(self, "points", p)


@dataclass(frozen=True)
class LineDeviation:
    """Penalise the distance to the line through ``a`` and ``b`` on ``[t_start, t_end)``.

    Paper 003 eqs. (14)-(25): the squared distances of the control points
    active on the window are penalised; by eq. (22) the curve is never
    farther from the line than the farthest of them.
    """

    a: FloatArray
    b: FloatArray
    t_start: float
    t_end: float
    weight: float = 1.0

    def __post_init__(self) -> None:
        a = as_array("line.a", self.a, ndim=1)
        b = as_array("line.b", self.b, shape=(a.size,))
        if np.linalg.norm(b - a) <= 1e-12 * max(1.0, float(np.linalg.norm(a))):
            raise InputError(f"line: got a == b == {a.tolist()}, expected two distinct points")
        _window("line", self.t_start, self.t_end)
        as_float("line.weight", self.weight, nonneg=True)
        object.__setattr__(self, "a", a)
        object.__setattr__(self, "b", b)

    def quadratic(self) -> tuple[FloatArray, FloatArray]:
        """``(Q, w)`` with squared distance ``(p - w)' Q (p - w)``.

        Paper 003 eq. (15) is garbled in print (its ``R`` mixes a scalar and a
        vector); this is the correct form: ``Q = I - u u' / u'u``, ``u = a - b``.
        """
        u = self.a - self.b
        return np.eye(u.size) - np.outer(u, u) / (u @ u), self.b


@dataclass(frozen=True)
class PlaneDeviation:
    """Penalise the distance to a plane (normal, anchor) on ``[t_start, t_end)``.

    Paper 003 eqs. (23)-(24), (27): ``Q = zeta zeta' / zeta'zeta``.
    """

    normal: FloatArray
    anchor: FloatArray
    t_start: float
    t_end: float
    weight: float = 1.0

    def __post_init__(self) -> None:
        n = as_array("plane.normal", self.normal, ndim=1)
        g = as_array("plane.anchor", self.anchor, shape=(n.size,))
        if np.linalg.norm(n) == 0.0:
            raise InputError("plane.normal: got the zero vector, expected a non-zero normal")
        _window("plane", self.t_start, self.t_end)
        as_float("plane.weight", self.weight, nonneg=True)
        object.__setattr__(self, "normal", n)
        object.__setattr__(self, "anchor", g)

    def quadratic(self) -> tuple[FloatArray, FloatArray]:
        """``(Q, w)`` with squared distance ``(p - w)' Q (p - w)``."""
        return np.outer(self.normal, self.normal) / (self.normal @ self.normal), self.anchor


Deviation = PointDeviation | LineDeviation | PlaneDeviation


@dataclass(frozen=True)
class Boundary:
    """Fix derivative ``order`` at the start and/or end (paper 003 eqs. 40-42).

    Parameters
    ----------
    order
        0 = position, 1 = velocity, ...; below the degree.
    start, end
        Shape (d,) in SI units, or ``None`` for free.
    """

    order: int
    start: FloatArray | None = None
    end: FloatArray | None = None

    def __post_init__(self) -> None:
        as_int("boundary.order", self.order, low=0, high=6)
        if self.start is None and self.end is None:
            raise InputError("boundary: got start=None and end=None, expected at least one")
        for side in ("start", "end"):
            value = getattr(self, side)
            if value is not None:
                object.__setattr__(self, side, as_array(f"boundary.{side}", value, ndim=1))

    @classmethod
    def rest(cls, start: FloatArray, end: FloatArray, orders: int) -> tuple[Boundary, ...]:
        """Position at both ends and derivatives ``1..orders-1`` zero: rest to rest."""
        s = as_array("start", start, ndim=1)
        e = as_array("end", end, shape=(s.size,))
        as_int("orders", orders, low=1, high=7)  # fix: garbage gave TypeError from range()
        zero = np.zeros(s.size)
        return (cls(0, s, e), *(cls(n, zero, zero) for n in range(1, orders)))


@dataclass(frozen=True)
class Corridor:
    """Stay in ``{p : A p <= b}`` on ``[t_start, t_end)`` (paper 003 eqs. 28-32).

    Parameters
    ----------
    A
        Shape (m, d).
    b
        Shape (m,).
    """

    A: FloatArray
    b: FloatArray
    t_start: float
    t_end: float

    def __post_init__(self) -> None:
        A = as_array("corridor.A", self.A, ndim=2)
        b = as_array("corridor.b", self.b, shape=(A.shape[0],))
        if A.shape[0] == 0:
            raise InputError("corridor.A: got no half-spaces, expected at least one row")
        if A.shape[1] == 0:  # fix: linprog raised ValueError on zero columns
            raise InputError(f"corridor.A: got shape {A.shape}, expected at least one column")
        _window("corridor", self.t_start, self.t_end)
        object.__setattr__(self, "A", A)
        object.__setattr__(self, "b", b)
        if not self.is_nonempty():
            raise InputError(
                f"corridor: got half-spaces with an empty intersection on "
                f"[{self.t_start:g}, {self.t_end:g}] s, expected a non-empty polytope"
            )

    def is_nonempty(self) -> bool:
        """Whether some point satisfies ``A p <= b`` (an LP through HiGHS)."""
        res = scipy.optimize.linprog(
            np.zeros(self.A.shape[1]),
            A_ub=self.A,
            b_ub=self.b,
            bounds=[(None, None)] * self.A.shape[1],
            method="highs",
        )
        return bool(res.status == 0)


@dataclass(frozen=True)
class SmoothingProblem:
    """Everything the engine needs to produce one trajectory.

    Parameters
    ----------
    dim
        Number of axes ``d`` (1 to 3 for vehicles; any for chains of integrators).
    degree
        Spline degree ``k``, 1 to 7.
    n_ctrl
        Number of control points ``M >= k + 1``.
    duration
        Seconds.
    smoothness
        ``{n: sigma_n}``: cost ``sum_n sigma_n ∫ ||d^n p / dt^n||^2 dt`` (eq. 8);
        default jerk (paper 000).
    deviations, interpolation, boundary, limits, corridors
        The terms above.
    hull
        ``"bspline"`` (papers' hull, eq. 39) or ``"bezier"`` (per-span
        Bézier points, tighter) for limits and corridors.
    """

    dim: int
    degree: int
    n_ctrl: int
    duration: float
    smoothness: Mapping[int, float] = field(default_factory=lambda: {3: 1.0})
    deviations: tuple[Deviation, ...] = ()
    interpolation: tuple[Interpolation, ...] = ()
    boundary: tuple[Boundary, ...] = ()
    limits: tuple[DerivativeLimit, ...] = ()
    corridors: tuple[Corridor, ...] = ()
    hull: HullKind = "bspline"

    def __post_init__(self) -> None:
        as_int("dim", self.dim, low=1, high=16)
        ClampedUniformBasis(self.degree, self.n_ctrl)
        as_float("duration", self.duration, positive=True)
        # Checked by type first: a non-str hull (an array has no truth value),
        # a non-mapping smoothness or a stray object among the terms would
        # otherwise escape as AttributeError / TypeError instead of InputError.
        if not isinstance(self.hull, str) or self.hull not in ("bspline", "bezier"):
            raise InputError(f"hull: got {self.hull!r}, expected 'bspline' or 'bezier'")
        if not isinstance(self.smoothness, Mapping):
            raise InputError(
                f"smoothness: got {type(self.smoothness).__name__}, expected a mapping "
                "{order: weight}"
            )
        self._check_terms("deviations", (PointDeviation, LineDeviation, PlaneDeviation))
        self._check_terms("interpolation", (Interpolation,))
        self._check_terms("boundary", (Boundary,))
        self._check_terms("limits", (BoxLimit, CylinderLimit, NormLimit))
        self._check_terms("corridors", (Corridor,))
        for order, sigma in self.smoothness.items():
            as_int("smoothness order", order, low=1, high=self.degree)
            as_float(f"smoothness[{order}]", sigma, nonneg=True)
        for lim in self.limits:
            self._check_order("limit", lim.order, self.degree)
            self._check_dim(f"{lim.label}", lim.dim)
        for bc in self.boundary:
            self._check_order("boundary", bc.order, self.degree - 1)
            for value in (bc.start, bc.end):
                if value is not None:
                    self._check_dim(f"boundary (order {bc.order})", value.size)
        for term in (*self.deviations, *self.interpolation, *self.corridors):
            self._check_term(term)

    def _check_terms(self, name: str, kinds: tuple[type, ...]) -> None:
        terms = getattr(self, name)
        if not isinstance(terms, tuple | list):
            raise InputError(
                f"{name}: got {type(terms).__name__}, expected a tuple of "
                f"{' / '.join(k.__name__ for k in kinds)}"
            )
        for i, term in enumerate(terms):
            if not isinstance(term, kinds):
                raise InputError(
                    f"{name}[{i}]: got {type(term).__name__}, expected "
                    f"{' / '.join(k.__name__ for k in kinds)}"
                )
        object.__setattr__(self, name, tuple(terms))

    def _check_order(self, what: str, order: int, highest: int) -> None:
        if order > highest:
            raise InputError(
                f"{what} order: got {order}, expected at most {highest} for degree {self.degree}"
            )

    def _check_dim(self, what: str, size: int) -> None:
        if size != self.dim:
            raise InputError(f"{what}: got {size} axes, expected dim = {self.dim}")

    def _check_times(self, what: str, lo: float, hi: float) -> None:
        tol = 1e-9 * self.duration
        if lo < -tol or hi > self.duration + tol:
            raise InputError(
                f"{what}: got times in [{lo:g}, {hi:g}] s, expected within the duration "
                f"[0, {self.duration:g}] s"
            )

    def _check_term(self, term: Deviation | Interpolation | Corridor) -> None:
        name = type(term).__name__
        if isinstance(term, PointDeviation | Interpolation):
            self._check_dim(f"{name}.points", term.points.shape[1])
            self._check_times(f"{name}.times", float(term.times.min()), float(term.times.max()))
        else:
            size = (
                term.A.shape[1]
                if isinstance(term, Corridor)
                else (term.a.size if isinstance(term, LineDeviation) else term.normal.size)
            )
            self._check_dim(name, size)
            self._check_times(f"{name} window", term.t_start, term.t_end)

    @property
    def basis(self) -> ClampedUniformBasis:
        """The spline basis (shared cache)."""
        return basis_for(self.degree, self.n_ctrl)

    @property
    def alpha(self) -> float:
        """Spans per second (paper 003 eq. 5)."""
        return (self.n_ctrl - self.degree) / self.duration

    @property
    def has_cones(self) -> bool:
        """Whether a limit is an exact norm (a conic program, solved by Clarabel)."""
        return any(isinstance(lim, NormLimit) and lim.is_cone for lim in self.limits)

    @property
    def has_inequalities(self) -> bool:
        """Whether a QP (rather than the closed form) is needed."""
        return bool(self.limits or self.corridors)
