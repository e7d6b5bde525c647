"""Vehicle derivative limits, per axis and axis-coupled.

A limit bounds the ``order``-th time derivative of the trajectory (1 = speed,
2 = acceleration, 3 = jerk, ...; for a chain of ``q`` integrators the input is
derivative ``q``, paper 003 §3.8). Each limit is a convex polytope
``{v : A v <= b}`` in derivative space; through the convex-hull property the
trajectory planner imposes it on hull points, so it holds on the whole
trajectory, not only on samples (paper 003 eq. 39).

Three shapes:

* :class:`BoxLimit` -- an axis-aligned, possibly asymmetric box.
* :class:`NormLimit` -- the Euclidean norm over all axes, ``||d^n p/dt^n|| <= r``
  (``vmax`` is the *speed*, docs/architecture.md, "The meaning of each limit"). The ball is
  convex, so holding it on every hull point holds it on the whole curve. With
  ``sides=None`` the engine imposes it exactly, as a second-order cone per
  hull point; with ``sides=m`` through an inscribed polytope (see
  :meth:`NormLimit.halfspaces`).
* :class:`CylinderLimit` -- horizontal norm ``sqrt(x'^2 + y'^2) <= r`` and
  separate vertical bounds (paper 003 eq. 55). It is enforced through a
  regular ``m``-gon prism *inscribed* in the cylinder, so meeting the polytope
  implies meeting the cylinder. (The paper's text says "hexagonal" while its
  Fig. 4 shows an octagon; ``sides`` is a parameter, default 8.)

:class:`VehicleLimits` is the one value the entry points build: the three
norms and optional per-axis boxes, turned into limits by
:meth:`VehicleLimits.derivative_limits`.

Units are SI: m/s, m/s^2, m/s^3, ...
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np
import scipy.spatial

from skyquill.errors import InputError
from skyquill.validation import FloatArray, as_array, as_float, as_int

ORDER_NAMES = {1: "speed", 2: "acceleration", 3: "jerk", 4: "snap"}


def order_name(order: int) -> str:
    """Human name of a derivative order (``3 -> "jerk"``)."""
    return ORDER_NAMES.get(order, f"derivative {order}")


def _relative(excess: float, bound: float) -> float:
    """Excess relative to the bound's magnitude (absolute when the bound is 0)."""
    return max(0.0, excess) / abs(bound) if bound != 0.0 else max(0.0, excess)


@dataclass(frozen=True)
class BoxLimit:
    """Per-axis bounds ``lower <= d^n p / dt^n <= upper`` on derivative ``order``.

    Parameters
    ----------
    order
        Derivative order ``n >= 1``.
    lower, upper
        Bounds per axis, shape (d,), SI units; ``lower < upper``.
    """

    order: int
    lower: FloatArray
    upper: FloatArray

    def __post_init__(self) -> None:
        as_int("order", self.order, low=1, high=7)
        upper = as_array(f"{order_name(self.order)} upper", self.upper, ndim=1)
        lower = as_array(f"{order_name(self.order)} lower", self.lower, shape=(upper.size,))
        if np.any(lower >= upper):
            i = int(np.argmax(lower >= upper))
            raise InputError(
                f"{order_name(self.order)} limit: got lower[{i}] = {lower[i]:g} >= "
                f"upper[{i}] = {upper[i]:g}, expected lower < upper"
            )
        object.__setattr__(self, "lower", lower)
        object.__setattr__(self, "upper", upper)

    @classmethod
    def symmetric(cls, order: int, bound: float, dim: int) -> BoxLimit:
        """``|d^n p_i / dt^n| <= bound`` on every one of ``dim`` axes."""
        b = as_float(f"{order_name(order)} limit", bound, positive=True)
        return cls(order, np.full(dim, -b), np.full(dim, b))

    @property
    def dim(self) -> int:
        """Number of axes."""
        return int(self.upper.size)

    @property
    def label(self) -> str:
        """Short name for reports."""
        return f"{order_name(self.order)} box"

    def halfspaces(self) -> tuple[FloatArray, FloatArray]:
        """``(A, b)`` with the box ``= {v : A v <= b}``; shapes (2d, d) and (2d,)."""
        eye = np.eye(self.dim)
        return np.vstack([eye, -eye]), np.concatenate([self.upper, -self.lower])

    def relative_excess(self, values: FloatArray) -> tuple[float, float]:
        """Largest per-axis magnitude and the largest relative excess of ``values`` (N, d)."""
        if values.shape[0] == 0:
            return 0.0, 0.0
        by_axis = np.ascontiguousarray(values.T)  # 30x faster reductions than axis=0 on (N, 3)
        high, low = by_axis.max(axis=1), by_axis.min(axis=1)
        rel = max(
            max(
                _relative(float(high[i] - self.upper[i]), self.upper[i]),
                _relative(float(self.lower[i] - low[i]), self.lower[i]),
            )
            for i in range(self.dim)
        )
        return float(max(np.abs(high).max(), np.abs(low).max())), rel


@dataclass(frozen=True)
class CylinderLimit:
    """Horizontal norm ``<= radius`` and vertical bounds on derivative ``order``.

    Parameters
    ----------
    order
        Derivative order ``n >= 1``.
    radius
        Bound on ``sqrt(x^(n)^2 + y^(n)^2)``, > 0.
    z_lower, z_upper
        Bounds on the vertical component (3-D only; ``None`` in 2-D).
    sides
        Number of sides ``m >= 3`` of the inscribed prism used as the
        constraint.
    """

    order: int
    radius: float
    z_lower: float | None = None
    z_upper: float | None = None
    sides: int = 8
    dim: int = field(init=False)

    def __post_init__(self) -> None:
        as_int("order", self.order, low=1, high=7)
        as_float(f"{order_name(self.order)} radius", self.radius, positive=True)
        as_int("sides", self.sides, low=3, high=1024)
        if (self.z_lower is None) != (self.z_upper is None):
            raise InputError(
                f"{order_name(self.order)} vertical bounds: got z_lower={self.z_lower!r}, "
                f"z_upper={self.z_upper!r}, expected both or neither"
            )
        if self.z_lower is not None and self.z_upper is not None:
            lo = as_float("z_lower", self.z_lower)
            hi = as_float("z_upper", self.z_upper)
            if lo >= hi:
                raise InputError(
                    f"{order_name(self.order)} vertical bounds: got z_lower={lo:g} >= "
                    f"z_upper={hi:g}, expected z_lower < z_upper"
                )
        object.__setattr__(self, "dim", 2 if self.z_lower is None else 3)

    @property
    def label(self) -> str:
        """Short name for reports."""
        return f"{order_name(self.order)} cylinder ({self.sides}-gon)"

    def halfspaces(self) -> tuple[FloatArray, FloatArray]:
        """``(A, b)`` of the inscribed prism; shapes (m [+2], d) and (m [+2],).

        Edge ``j`` of a regular m-gon with vertices on the circle at angles
        ``2 pi j / m`` has outward normal at angle ``(2j + 1) pi / m`` and
        distance ``r cos(pi / m)`` from the centre.
        """
        angles = (2 * np.arange(self.sides) + 1) * np.pi / self.sides
        A = np.zeros((self.sides, self.dim))
        A[:, 0], A[:, 1] = np.cos(angles), np.sin(angles)
        b = np.full(self.sides, self.radius * np.cos(np.pi / self.sides))
        if self.dim == 3:
            assert self.z_lower is not None and self.z_upper is not None
            A = np.vstack([A, [[0, 0, 1.0], [0, 0, -1.0]]])
            b = np.concatenate([b, [self.z_upper, -self.z_lower]])
        return A, b

    def relative_excess(self, values: FloatArray) -> tuple[float, float]:
        """Largest horizontal norm and largest relative excess over the *cylinder*."""
        by_axis = np.ascontiguousarray(values.T)  # contiguous rows: fast reductions
        norm = float(np.sqrt((by_axis[0] ** 2 + by_axis[1] ** 2).max(initial=0.0)))
        rel = _relative(norm - self.radius, self.radius)
        if self.dim == 3 and by_axis.shape[1]:
            assert self.z_lower is not None and self.z_upper is not None
            rel = max(
                rel,
                _relative(float(by_axis[2].max()) - self.z_upper, self.z_upper),
                _relative(self.z_lower - float(by_axis[2].min()), self.z_lower),
            )
        return norm, rel


@lru_cache(maxsize=32)
def _unit_polytope(sides: int, dim: int) -> tuple[FloatArray, FloatArray]:
    """``(A, b)`` of a polytope inscribed in the unit ball of ``R^dim``, unit normals.

    1-D: the interval itself. 2-D: the regular ``sides``-gon with vertices at
    angles ``2 pi j / m`` (the horizontal polygon of :class:`CylinderLimit`).
    3-D: the "globe" -- the convex hull of points on the unit sphere at
    longitudes ``2 pi j / m`` and latitudes spaced by the same angle (rings
    at ``k * 2 pi / m`` below +-90 deg, plus both poles). Every vertex lies on
    the sphere, so the polytope is inside the ball. Its equator is the 2-D
    ``m``-gon (level flight loses what the paper's prism loses) and it has no
    preferred direction, unlike an ``m``-gon prism inscribed in the sphere,
    which must trade horizontal against vertical reach (at best
    ``sqrt(2/3) r`` horizontally and ``r / sqrt(3)`` vertically). Facets
    come from Qhull; the triangles of one planar quadrilateral give the same
    row, kept once.
    """
    if dim == 1:
        return np.array([[1.0], [-1.0]]), np.ones(2)
    angles = 2 * np.pi * np.arange(sides) / sides
    if dim == 2:
        points = np.column_stack([np.cos(angles), np.sin(angles)])
    else:
        n_half = max(1, -(-sides // 4))  # rings per hemisphere, equator included
        lat = (np.pi / 2) * np.arange(-(n_half - 1), n_half) / n_half
        lon_g, lat_g = np.meshgrid(angles, lat)
        ring = np.column_stack(
            [
                (np.cos(lat_g) * np.cos(lon_g)).ravel(),
                (np.cos(lat_g) * np.sin(lon_g)).ravel(),
                np.sin(lat_g).ravel(),
            ]
        )
        points = np.vstack([ring, [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]])
    eq = scipy.spatial.ConvexHull(points).equations  # n.x + offset <= 0 inside
    rows = np.unique(np.round(eq, 12), axis=0)
    return rows[:, :dim], -rows[:, dim]


@dataclass(frozen=True)
class NormLimit:
    """Euclidean norm over all axes ``||d^n p / dt^n||_2 <= radius`` on derivative ``order``.

    Parameters
    ----------
    order
        Derivative order ``n >= 1`` (1: the speed).
    radius
        Bound on the norm, > 0, SI units.
    sides
        ``None``: held exactly (a second-order cone on every hull point,
        solved by a conic solver). An integer ``m`` in [3, 1024]: held by a
        polytope inscribed in the ball (:meth:`halfspaces`), solvable by any
        QP backend but smaller than the ball.
    dim
        Number of axes, 1 to 16 (a polytope only for 1 to 3).
    """

    order: int
    radius: float
    sides: int | None = None
    dim: int = 3

    def __post_init__(self) -> None:
        as_int("order", self.order, low=1, high=7)
        r = as_float(f"{order_name(self.order)} norm radius", self.radius, positive=True)
        object.__setattr__(self, "radius", r)
        as_int("dim", self.dim, low=1, high=16)
        if self.sides is not None:
            as_int("sides", self.sides, low=3, high=1024)
            if self.dim > 3:
                raise InputError(
                    f"sides: got {self.sides} for a {self.dim}-axis norm, expected None "
                    "(an exact cone): inscribed polytopes exist for 1 to 3 axes"
                )

    @property
    def is_cone(self) -> bool:
        """Whether the engine imposes the norm exactly as a second-order cone."""
        return self.sides is None

    @property
    def label(self) -> str:
        """Short name for reports, e.g. ``"speed norm (cone)"``."""
        name = order_name(self.order)
        if self.sides is None:
            return f"{name} norm (cone)"
        shape = {1: "interval", 2: f"{self.sides}-gon", 3: f"{self.sides}-gon globe"}
        return f"{name} norm ({shape[self.dim]})"

    @property
    def inscribed_fraction(self) -> float:
        """Radius of the largest ball inside the constraint set, over ``radius`` (1 for a cone)."""
        if self.sides is None:
            return 1.0
        return float(_unit_polytope(self.sides, self.dim)[1].min())

    def halfspaces(self) -> tuple[FloatArray, FloatArray]:
        """``(A, b)`` of the inscribed polytope; shapes (m', d) and (m',).

        Raises
        ------
        InputError
            For a cone (``sides=None``): it has no finite set of half-spaces.
        """
        if self.sides is None:
            raise InputError(
                f"{self.label}: got sides=None (an exact cone), expected an integer "
                "number of sides for a polytope"
            )
        A, b = _unit_polytope(self.sides, self.dim)
        return A.copy(), self.radius * b

    def relative_excess(self, values: FloatArray) -> tuple[float, float]:
        """Largest norm of ``values`` (N, d) and its relative excess over the *ball*."""
        by_axis = np.ascontiguousarray(values.T)  # contiguous rows: fast reductions
        norm = float(np.sqrt((by_axis**2).sum(axis=0).max(initial=0.0)))
        return norm, _relative(norm - self.radius, self.radius)


DerivativeLimit = BoxLimit | CylinderLimit | NormLimit

_VEHICLE_FIELDS: dict[str, tuple[int, str, str]] = {
    "vmax": (1, "m/s", "speed: Euclidean norm of the velocity"),
    "amax": (2, "m/s^2", "Euclidean norm of the acceleration"),
    "jmax": (3, "m/s^3", "Euclidean norm of the jerk"),
    "vmax_axis": (1, "m/s", "per-axis bound |v_i| on every velocity component"),
    "amax_axis": (2, "m/s^2", "per-axis bound |a_i| on every acceleration component"),
    "jmax_axis": (3, "m/s^3", "per-axis bound |j_i| on every jerk component"),
}


#: Largest limit accepted per derivative order, SI: far beyond any multirotor (1000 m/s,
#: ~1000 g, and a jerk to match), so a larger number is a unit mistake; and a bound that
#: large would leave the solvers a badly scaled problem to fail on.
#: Speed, acceleration and jerk beyond any vehicle (m/s, m/s^2, m/s^3): a unit mistake.
LIMIT_CEILINGS = {1: 1e3, 2: 1e4, 3: 1e6}
_CEILINGS = LIMIT_CEILINGS


@dataclass(frozen=True)
class VehicleLimits:
    """The vehicle's limits: built once at the entry, passed down (docs/architecture.md).

    ``None`` leaves a limit out. Every value is in SI units and > 0.

    Attributes
    ----------
    vmax
        Speed, the Euclidean norm of the velocity, m/s.
    amax
        Euclidean norm of the acceleration, m/s^2.
    jmax
        Euclidean norm of the jerk, m/s^3.
    vmax_axis, amax_axis, jmax_axis
        Optional extra per-axis boxes ``|v_i|``, ``|a_i|``, ``|j_i| <= ...``.
    """

    vmax: float | None = None
    amax: float | None = None
    jmax: float | None = None
    vmax_axis: float | None = None
    amax_axis: float | None = None
    jmax_axis: float | None = None

    def __post_init__(self) -> None:
        for name, (order, unit, _) in _VEHICLE_FIELDS.items():
            value = getattr(self, name)
            if value is None:
                continue
            bound = as_float(name, value, positive=True)
            if bound > _CEILINGS[order]:
                raise InputError(
                    f"{name}: got {bound:g} {unit}, expected at most {_CEILINGS[order]:g} {unit} "
                    "(beyond any vehicle: is it in SI units?)"
                )
            object.__setattr__(self, name, bound)

    def norm(self, order: int) -> float | None:
        """The norm bound on derivative ``order`` (1: vmax, 2: amax, 3: jmax; else None)."""
        as_int("order", order, low=1, high=7)
        return {1: self.vmax, 2: self.amax, 3: self.jmax}.get(order)

    def axis(self, order: int) -> float | None:
        """The per-axis bound on derivative ``order`` (``vmax_axis``, ...; else None)."""
        as_int("order", order, low=1, high=7)
        return {1: self.vmax_axis, 2: self.amax_axis, 3: self.jmax_axis}.get(order)

    def derivative_limits(
        self, dim: int, *, sides: int | None = None
    ) -> tuple[DerivativeLimit, ...]:
        """The limits for a ``dim``-axis trajectory, ordered by derivative order.

        Parameters
        ----------
        dim
            Number of axes, 1 to 3.
        sides
            ``None``: norms as exact cones (conic solver); an integer ``m``:
            norms through the inscribed polytope of :class:`NormLimit`.
        """
        as_int("dim", dim, low=1, high=3)
        limits: list[DerivativeLimit] = []
        for order in (1, 2, 3):
            radius, box = self.norm(order), self.axis(order)
            if radius is not None:
                limits.append(NormLimit(order, radius, sides, dim))
            if box is not None:
                limits.append(BoxLimit.symmetric(order, box, dim))
        return tuple(limits)

    def describe(self) -> str:
        """One line for messages: ``"speed 1 m/s, acceleration 2 m/s^2, jerk 10 m/s^3"``."""
        parts = []
        for name, (order, unit, _) in _VEHICLE_FIELDS.items():
            value = getattr(self, name)
            if value is not None:
                kind = order_name(order) + (" per axis" if name.endswith("_axis") else "")
                parts.append(f"{kind} {value:g} {unit}")
        return ", ".join(parts) if parts else "no limits"

    def timing_bounds(self) -> tuple[float, float]:
        """Speed and acceleration a time allocation may plan with, m/s and m/s^2.

        The norms where given, else the per-axis bounds (a move along an axis
        reaches them; a diagonal one could go faster, so this is cautious).

        Raises
        ------
        InputError
            When neither a speed nor an acceleration bound of either kind is set.
        """
        vmax = self.vmax if self.vmax is not None else self.vmax_axis
        amax = self.amax if self.amax is not None else self.amax_axis
        if vmax is None or amax is None:
            raise InputError(
                f"limits: got vmax={self.vmax}, vmax_axis={self.vmax_axis}, amax={self.amax}, "
                f"amax_axis={self.amax_axis}; expected a speed and an acceleration bound to "
                "time the motion"
            )
        return vmax, amax

    def as_dict(self) -> dict[str, object]:
        """``{name: {"value", "unit", "meaning"}}`` for every field (``value`` None if unset)."""
        return {
            name: {"value": getattr(self, name), "unit": unit, "meaning": meaning}
            for name, (_, unit, meaning) in _VEHICLE_FIELDS.items()
        }


def vehicle_limits(
    dim: int,
    vmax: float | None = None,
    amax: float | None = None,
    jmax: float | None = None,
    coupled_sides: int | None = None,
) -> tuple[DerivativeLimit, ...]:
    """Symmetric speed / acceleration / jerk limits, per axis or coupled.

    Parameters
    ----------
    dim
        2 or 3 axes.
    vmax, amax, jmax
        Bounds in m/s, m/s^2, m/s^3; ``None`` leaves that order free.
    coupled_sides
        ``None`` for per-axis boxes; an integer ``m`` for a horizontal
        ``m``-gon inscribed in the circle of that radius (vertical bounds are
        the same number).
    """
    as_int("dim", dim, low=2, high=3)
    limits: list[DerivativeLimit] = []
    for order, bound in ((1, vmax), (2, amax), (3, jmax)):
        if bound is None:
            continue
        b = as_float(f"{order_name(order)} limit", bound, positive=True)
        if coupled_sides is None:
            limits.append(BoxLimit.symmetric(order, b, dim))
        else:
            z: dict[str, Any] = {"z_lower": -b, "z_upper": b} if dim == 3 else {}
            limits.append(CylinderLimit(order, b, sides=coupled_sides, **z))
    return tuple(limits)


def limit_bounds(limits: Sequence[DerivativeLimit]) -> dict[int, float]:
    """The smallest bound on each derivative order's magnitude the limits state, SI units.

    A norm gives its radius, a cylinder the smaller of its radius and vertical bounds, a box
    its smallest bound; orders without a limit are left out. Any motion keeping these in
    every direction keeps the limits (a straight vertical take-off, for one).
    """
    out: dict[int, float] = {}
    for lim in limits:
        if isinstance(lim, NormLimit | CylinderLimit):
            bound = float(lim.radius)
            if isinstance(lim, CylinderLimit) and lim.z_lower is not None:
                assert lim.z_upper is not None
                bound = min(bound, abs(lim.z_lower), abs(lim.z_upper))
        else:
            bound = float(np.minimum(np.abs(lim.lower), np.abs(lim.upper)).min())
        out[lim.order] = min(out.get(lim.order, float("inf")), bound)
    return out


def lifted_limits(limits: Sequence[DerivativeLimit]) -> tuple[DerivativeLimit, ...]:
    """2-axis limits of a plan drawn in the plane, stated for its flight in 3-D.

    A 2-D plan flown at an altitude keeps z still, so a 2-axis norm is the same norm over
    three axes; it is stated so, because the flight's take-off and landing move in z. A
    2-axis box gets the smaller of its x and y bounds on z; a cylinder without vertical
    bounds gets its radius. 3-axis limits are kept.
    """
    out: list[DerivativeLimit] = []
    for lim in limits:
        if isinstance(lim, NormLimit) and lim.dim == 2:
            out.append(NormLimit(lim.order, lim.radius, lim.sides, 3))
        elif isinstance(lim, BoxLimit) and lim.dim == 2:
            low = float(np.max(lim.lower))
            high = float(np.min(lim.upper))
            out.append(BoxLimit(lim.order, np.append(lim.lower, low), np.append(lim.upper, high)))
        elif isinstance(lim, CylinderLimit) and lim.z_lower is None:
            out.append(CylinderLimit(lim.order, lim.radius, -lim.radius, lim.radius, lim.sides))
        else:
            out.append(lim)
    return tuple(out)
