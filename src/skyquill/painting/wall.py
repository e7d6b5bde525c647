"""Frames and walls of paper 002 (§2.1, §5.1).

Frames (all right-handed, z up, SI units):

* ``R_w`` -- the wall frame. ``x_w`` runs along the wall (to the right as seen by a drone facing
  it), ``y_w`` points *into* the wall, ``z_w`` up. Paint dots are given in ``(x_w, z_w)``; the
  reference (nominal) wall is the plane ``y_w = 0``.
* ``R_rho`` -- the onboard localization frame: origin at the drone before take-off, axes along
  the drone's axes then. The operator places it at ``delta`` (in ``R_w``) with yaw ``gamma``, so
  ``p_w = R(gamma) p_rho + delta`` and ``p_rho = R(gamma)^T (p_w - delta)`` (eq. 1 and 2; the
  cleaned text of eq. 1 and 11 drops the transpose that the typeset eq. 2 shows -- with
  ``p_w = R p_rho + delta`` as in eq. 3 the transpose is needed).
* ``R_b`` -- the body frame; only its yaw ``psi`` (in ``R_rho``) matters in quasi-stationary
  flight. The paint tool points along ``y_b``: ``y_b = R(psi) e_y``.

A wall is a polyline in the horizontal plane, ``y_w = f(x_w)`` (piecewise linear, continuous),
made of segments at angular offsets ``theta_k`` (paper §5, Fig. 13). The segment that contains
``x_w = 0`` passes through the wall origin; the others are attached end to end. A positive
angle turns a segment counter-clockwise seen from above, so on the right of the origin it
recedes from the drone, and on the left it comes closer.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from skyquill.errors import InputError
from skyquill.io.numbers import parse_number
from skyquill.validation import FloatArray, as_array, as_float

#: Largest segment angle accepted, deg: a steeper segment is no longer a wall in front of the
#: drone (``y = f(x)`` would not be a function).
MAX_WALL_ANGLE_DEG = 60.0
#: How far outside its segment a ray's root on that segment's line still counts as a hit,
#: m: round-off at a kink of the wall (see :meth:`Wall.hit`).
KINK_TOLERANCE_M = 1e-9


def rot2(angle: float) -> FloatArray:
    """Rotation of the plane by ``angle`` rad, shape (2, 2)."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def rot_z(angle: float) -> FloatArray:
    """Rotation about z by ``angle`` rad, shape (3, 3)."""
    out = np.eye(3)
    out[:2, :2] = rot2(angle)
    return out


@dataclass(frozen=True)
class Placement:
    """Where the operator put the drone: ``p_w = R(gamma) p_rho + delta``.

    Attributes
    ----------
    delta_w
        Origin of ``R_rho`` in ``R_w``, shape (3,), m. The paper's nominal value is
        ``[0, -d, 0]`` (``d`` in front of the wall).
    gamma_rad
        Yaw of ``R_rho`` relative to ``R_w``, rad.
    """

    delta_w: FloatArray
    gamma_rad: float

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "delta_w", as_array("delta_w", self.delta_w, shape=(3,), max_abs=1e3)
        )
        gamma = as_float("gamma_rad", self.gamma_rad)
        if abs(gamma) >= math.pi / 2:
            raise InputError(
                f"gamma: got {math.degrees(gamma):g} deg, expected |gamma| < 90 deg (the drone "
                "must face the wall)"
            )

    def to_rho(self, p_w: FloatArray) -> FloatArray:
        """``R(gamma)^T (p_w - delta)``; ``p_w`` shape (..., 3), m."""
        return (p_w - self.delta_w) @ rot_z(self.gamma_rad)

    def to_w(self, p_rho: FloatArray) -> FloatArray:
        """``R(gamma) p_rho + delta``; ``p_rho`` shape (..., 3), m."""
        return p_rho @ rot_z(self.gamma_rad).T + self.delta_w

    @property
    def gamma_deg(self) -> float:
        """The yaw offset in degrees."""
        return math.degrees(self.gamma_rad)


@dataclass(frozen=True)
class Wall:
    """A vertical wall made of segments, ``y_w = f(x_w)`` piecewise linear.

    Attributes
    ----------
    angles_rad
        Angle of each segment from ``x_w``, left to right, shape (K,), rad.
    breaks_m
        ``x_w`` of the K - 1 corners, increasing, shape (K - 1,), m.
    x_range_m
        ``(x_min, x_max)`` of the wall's extent along ``x_w``, m.
    height_m
        The wall spans ``0 <= z_w <= height_m``.
    """

    angles_rad: FloatArray
    breaks_m: FloatArray
    x_range_m: tuple[float, float] = (-4.0, 4.0)
    height_m: float = 4.0
    _y_at_breaks: FloatArray = field(init=False, repr=False)
    _anchors: FloatArray = field(init=False, repr=False)
    _normals: FloatArray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        angles = as_array("wall angles", self.angles_rad, ndim=1)
        breaks = as_array("wall breaks", self.breaks_m, ndim=1)
        if angles.size == 0 or breaks.size != angles.size - 1:
            raise InputError(
                f"wall angles: got {angles.size} angle(s) and {breaks.size} corner(s), expected "
                "at least one angle and one corner fewer than angles"
            )
        if np.any(np.abs(angles) > math.radians(MAX_WALL_ANGLE_DEG)):
            raise InputError(
                f"wall angles: got {np.round(np.degrees(angles), 3).tolist()} deg, expected "
                f"each within +-{MAX_WALL_ANGLE_DEG:g} deg"
            )
        if np.any(np.diff(breaks) <= 0):
            raise InputError(f"wall breaks: got {breaks.tolist()}, expected increasing values")
        x0, x1 = (as_float("wall x range", v) for v in self.x_range_m)
        if not x0 < x1:
            raise InputError(f"wall x range: got {self.x_range_m}, expected x_min < x_max")
        as_float("wall height", self.height_m, positive=True)
        object.__setattr__(self, "angles_rad", angles)
        object.__setattr__(self, "breaks_m", breaks)
        object.__setattr__(self, "_y_at_breaks", self._corner_depths())
        lines = [self.line(k) for k in range(self.n_segments)]
        object.__setattr__(self, "_anchors", np.array([a for a, _ in lines]))
        object.__setattr__(self, "_normals", np.array([[-u[1], u[0]] for _, u in lines]))

    @classmethod
    def flat(cls, *, x_range_m: tuple[float, float] = (-4.0, 4.0), height_m: float = 4.0) -> Wall:
        """The plane ``y_w = 0``."""
        return cls(np.zeros(1), np.zeros(0), x_range_m, height_m)

    @classmethod
    def segmented(
        cls,
        angles_deg: Sequence[float],
        span_m: tuple[float, float],
        *,
        x_range_m: tuple[float, float] = (-4.0, 4.0),
        height_m: float = 4.0,
    ) -> Wall:
        """Segments at ``angles_deg`` (left to right) splitting ``span_m`` in equal widths.

        ``span_m`` is usually the drawing's ``x`` extent, so that each segment carries a share of
        the dots as in the paper's Fig. 14.
        """
        angles = as_array("wall angles", list(angles_deg), ndim=1)
        lo, hi = span_m
        if not lo < hi:
            raise InputError(f"wall span: got {span_m}, expected x_min < x_max")
        breaks = lo + (hi - lo) * np.arange(1, angles.size) / angles.size
        return cls(np.radians(angles), breaks, x_range_m, height_m)

    @classmethod
    def cylinder(
        cls,
        radius_m: float,
        *,
        x_range_m: tuple[float, float] = (-4.0, 4.0),
        height_m: float = 4.0,
        step_deg: float = 0.5,
    ) -> Wall:
        """A vertical cylinder touching ``y_w = 0`` at ``x_w = 0``, as a fine polygon.

        ``radius_m > 0`` puts the axis behind the wall (a round tower seen from outside: the
        wall recedes from the drone on both sides); ``radius_m < 0`` in front of it (inside a
        round hall). The polygon is circumscribed: its segments are tangent to the circle at
        every ``step_deg`` of arc, the one holding ``x_w = 0`` along ``x_w`` through the origin,
        so it stays within ``|R| (1 / cos(step / 2) - 1)`` of the circle (0.2 mm for R = 20 m).

        Raises
        ------
        InputError
            A radius so small that the wall over ``x_range_m`` turns by more than
            :data:`MAX_WALL_ANGLE_DEG`.
        """
        r = as_float("cylinder radius", radius_m)
        x0, x1 = (as_float("wall x range", v) for v in x_range_m)
        reach = max(abs(x0), abs(x1))
        step = math.radians(as_float("step_deg", step_deg, positive=True))
        # the outermost tangent point the extent needs, and its angle
        need = math.sin(math.radians(MAX_WALL_ANGLE_DEG)) * abs(r)
        if not math.isfinite(r) or abs(r) <= 0 or reach >= need:
            smallest = reach / math.sin(math.radians(MAX_WALL_ANGLE_DEG))
            raise InputError(
                f"cylinder radius: got {r:g} m, expected |radius| > {smallest:.3g} m so that the "
                f"wall over x from {x0:g} to {x1:g} m turns by less than {MAX_WALL_ANGLE_DEG:g} deg"
            )
        half = math.asin(reach / abs(r))
        m = math.ceil(half / step + 0.5)
        k = np.arange(-m, m + 1)
        angles = (k * step * math.copysign(1.0, r)).astype(np.float64)
        # corner between the tangents at k * step and (k + 1) * step
        mid = (k[:-1] + 0.5) * step
        breaks = abs(r) / math.cos(step / 2) * np.sin(mid)
        first = int(np.searchsorted(breaks, x0, side="right"))  # the segments over the extent
        last = int(np.searchsorted(breaks, x1, side="left"))
        return cls(angles[first : last + 1], breaks[first:last], (x0, x1), height_m)

    @classmethod
    def recess(
        cls,
        x_from_m: float,
        x_to_m: float,
        depth_m: float,
        *,
        side_deg: float = MAX_WALL_ANGLE_DEG,
        x_range_m: tuple[float, float] = (-4.0, 4.0),
        height_m: float = 4.0,
    ) -> Wall:
        """The flat wall ``y_w = 0`` with a recess ``depth_m`` deep from ``x_from_m`` to ``x_to_m``.

        The recess's sides slope at ``side_deg`` (a ``y = f(x)`` wall cannot have sides at 90
        deg; at 60 deg a 10 cm recess has 5.8 cm wide sides). It must not hold ``x_w = 0``: the
        wall frame is the wall in front of the take-off point.
        """
        a, b = as_float("recess from", x_from_m), as_float("recess to", x_to_m)
        depth = as_float("recess depth", depth_m, positive=True)
        side = as_float("recess side angle", side_deg, positive=True)
        if side > MAX_WALL_ANGLE_DEG:
            raise InputError(
                f"recess side angle: got {side:g} deg, expected at most {MAX_WALL_ANGLE_DEG:g} deg"
            )
        run = depth / math.tan(math.radians(side))
        if not b - a > 2 * run:
            raise InputError(
                f"recess: got from {a:g} to {b:g} m, expected a recess wider than its two sides "
                f"({2 * run:.3g} m at {depth:g} m deep and {side:g} deg)"
            )
        if a <= 0.0 <= b:
            raise InputError(
                f"recess: got from {a:g} to {b:g} m, expected it beside x = 0 (the wall frame "
                "is the wall in front of the take-off point)"
            )
        angles = np.radians([0.0, side, 0.0, -side, 0.0])
        return cls(angles, np.array([a, a + run, b - run, b]), x_range_m, height_m)

    @property
    def n_segments(self) -> int:
        """Number of segments K."""
        return int(self.angles_rad.size)

    def _corner_depths(self) -> FloatArray:
        """``y_w`` at each corner, shape (K - 1,), with the segment holding x = 0 through 0."""
        k0 = int(np.searchsorted(self.breaks_m, 0.0, side="right"))
        y = np.zeros(self.breaks_m.size)
        slopes = np.tan(self.angles_rad)
        for k in range(k0, self.breaks_m.size):  # corners right of the origin
            start_x = 0.0 if k == k0 else self.breaks_m[k - 1]
            start_y = 0.0 if k == k0 else y[k - 1]
            y[k] = start_y + slopes[k] * (self.breaks_m[k] - start_x)
        for k in range(k0 - 1, -1, -1):  # corners left of the origin
            end_x = 0.0 if k == k0 - 1 else self.breaks_m[k + 1]
            end_y = 0.0 if k == k0 - 1 else y[k + 1]
            y[k] = end_y - slopes[k + 1] * (end_x - self.breaks_m[k])
        return y

    def segment_of(self, x_w: FloatArray) -> np.ndarray:
        """Index of the segment under each ``x_w`` (shape (N,)), ints in ``[0, K)``."""
        return np.searchsorted(self.breaks_m, np.asarray(x_w, dtype=float), side="right")

    def line(self, k: int) -> tuple[FloatArray, FloatArray]:
        """Segment ``k``'s infinite line: a point on it and its unit direction, both (2,)."""
        if k < self.breaks_m.size:
            anchor = np.array([self.breaks_m[k], self._y_at_breaks[k]])
        elif k > 0:
            anchor = np.array([self.breaks_m[k - 1], self._y_at_breaks[k - 1]])
        else:
            anchor = np.zeros(2)
        a = float(self.angles_rad[k])
        return anchor, np.array([math.cos(a), math.sin(a)])

    def depth(self, x_w: FloatArray) -> FloatArray:
        """``y_w`` of the wall at each ``x_w``, shape (N,), m."""
        x = np.atleast_1d(np.asarray(x_w, dtype=float))
        out = np.empty_like(x)
        for k in range(self.n_segments):
            mask = self.segment_of(x) == k
            anchor, u = self.line(k)
            out[mask] = anchor[1] + (x[mask] - anchor[0]) * u[1] / u[0]
        return out

    def normal(self, x_w: FloatArray) -> FloatArray:
        """Unit normal into the wall at each ``x_w``, shape (N, 2)."""
        a = self.angles_rad[self.segment_of(np.atleast_1d(x_w))]
        return np.column_stack([-np.sin(a), np.cos(a)])

    def hit(self, start: FloatArray, direction: FloatArray) -> float:
        """Distance along the ray ``start + t * direction`` (xy, (2,)) to the wall, m.

        ``direction`` is a unit vector pointing at the wall. ``t`` is negative when ``start``
        is already beyond the wall (the drone would have touched it on its way), and ``inf``
        when the ray is parallel to the wall. With segments within +-60 deg and a direction
        within 90 deg of every normal, ``g(t) = y(t) - f(x(t))`` increases with ``t``, so the
        root is unique: each segment's line is tried and the root inside that segment kept.
        A root within :data:`KINK_TOLERANCE_M` of its segment counts: a ray through a kink
        of the wall finds it on both segments' lines, and round-off can put each of them
        just inside the other segment (a ray from the kink itself found no wall).
        """
        along = self._normals @ direction
        facing = along > 1e-12
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.einsum("kj,kj->k", self._anchors - start, self._normals) / along
        x = np.where(facing, start[0] + t * direction[0], np.nan)
        lower = np.concatenate([[-np.inf], self.breaks_m]) - KINK_TOLERANCE_M
        upper = np.concatenate([self.breaks_m, [np.inf]]) + KINK_TOLERANCE_M
        hits = np.flatnonzero((x >= lower) & (x <= upper))
        return float(t[hits[0]]) if hits.size else math.inf

    def foot(self, p_w: FloatArray) -> FloatArray:
        """Foot of the perpendicular from ``p_w`` (xy, shape (N, 2)) to the wall, shape (N, 2).

        The segment is the one under ``p_w``'s ``x``: this is the "fresco" reference, a dot
        projected normally onto the segment that carries it (paper §5.2, last sentence).
        """
        pts = np.atleast_2d(p_w)
        out = np.empty_like(pts)
        for i, (k, p) in enumerate(zip(self.segment_of(pts[:, 0]), pts, strict=True)):
            anchor, u = self.line(int(k))
            out[i] = anchor + ((p - anchor) @ u) * u
        return out

    def polyline(self) -> FloatArray:
        """The wall seen from above over its x range, shape (K + 1, 2), m (for plots)."""
        x = np.concatenate([[self.x_range_m[0]], self.breaks_m, [self.x_range_m[1]]])
        return np.column_stack([x, self.depth(x)])


def parse_angles(text: str) -> list[float]:
    """``"-10,0,10"`` (or ``"-10|0|10"``) into degrees; InputError naming ``--wall-angles``."""
    parts = [p.strip() for p in text.replace("|", ",").split(",")]
    try:
        values = [parse_number(p) for p in parts]
    except ValueError:
        values = []
    if not values:
        raise InputError(
            f"--wall-angles: got {text!r}, expected comma-separated finite angles in degrees, "
            "e.g. -10,0,10"
        )
    if any(abs(v) > MAX_WALL_ANGLE_DEG for v in values):
        raise InputError(
            f"--wall-angles: got {text!r}, expected each angle within +-{MAX_WALL_ANGLE_DEG:g} deg"
        )
    return values
