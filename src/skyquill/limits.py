"""Vehicle derivative limits, per axis and axis-coupled.

A limit bounds the ``order``-th time derivative of the trajectory (1 = speed,
2 = acceleration, 3 = jerk, ...; for a chain of ``q`` integrators the input is
derivative ``q``, paper 003 §3.8). Each limit is a convex polytope
``{v : A v <= b}`` in derivative space; through the convex-hull property the
trajectory planner imposes it on hull points, so it holds on the whole
trajectory, not only on samples (paper 003 eq. 39).

Two shapes:

* :class:`BoxLimit` -- an axis-aligned, possibly asymmetric box.
* :class:`CylinderLimit` -- horizontal norm ``sqrt(x'^2 + y'^2) <= r`` and
  separate vertical bounds (paper 003 eq. 55). It is enforced through a
  regular ``m``-gon prism *inscribed* in the cylinder, so meeting the polytope
  implies meeting the cylinder. (The paper's text says "hexagonal" while its
  Fig. 4 shows an octagon; ``sides`` is a parameter, default 8.)

Units are SI: m/s, m/s^2, m/s^3, ...
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

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


DerivativeLimit = BoxLimit | CylinderLimit


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
