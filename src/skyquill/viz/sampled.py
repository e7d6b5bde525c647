"""What ``fit``'s, ``fly``'s, ``write``'s and ``cover``'s figures show, sampled into plain arrays.

Sampling a plan (evaluating its trajectories, finding its pen-down stretches) needs
skyquill's core; drawing the samples needs only numpy and matplotlib. Kept apart, the
drawing can run in the picture worker (:mod:`skyquill.viz.worker`), a second process
that imports matplotlib while the command imports skyquill and plans, and that receives
these samples pickled: numpy arrays, numbers and strings, and nothing of the core.

So this module imports numpy only: unpickling its classes in the worker costs nothing.
The sampling functions import what they need of the core when called (in the command's
process, where it is imported already).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from skyquill.validation import FloatArray

if TYPE_CHECKING:
    from shapely.geometry.base import BaseGeometry

    from skyquill.calligraphy.mission import Mission
    from skyquill.coverage.plan import CoveragePlan
    from skyquill.limits import DerivativeLimit
    from skyquill.optimize.fit import PointFit
    from skyquill.sim.result import Flight

#: Samples of ``fit``'s trajectory in its figure.
FIT_SAMPLES = 2000
#: Samples per drone of ``write``'s board view and of its derivative panels.
BOARD_SAMPLES = 4000
CURVE_SAMPLES = 1500
#: Most setpoints ``cover``'s figure draws as dots (a 10 ha field has 370k; the figure
#: cannot show more).
MAX_DOTS = 40_000
#: Gap between two boards of ``write``'s board view, in units of the board's size.
BOARD_GAP = 0.25


@dataclass(frozen=True)
class LimitMark:
    """A limit drawn on a derivative panel: the curve it bounds (if not the components
    themselves) and its levels, dashed."""

    label: str | None
    curve: FloatArray | None  # (N,), against the panel's times
    levels: tuple[float, ...]


@dataclass(frozen=True)
class FitSamples:
    """``fit``'s figure: the input and path from above, the derivatives against time.

    ``points`` (M, 2+) and ``path`` (N, 2+) in m; ``t`` (N,) s; ``derivatives[k]`` (N, D)
    of order ``k + 1``, with ``limits[k]`` drawn over it.
    """

    points: FloatArray
    path: FloatArray
    t: FloatArray
    derivatives: tuple[FloatArray, ...]
    limits: tuple[tuple[LimitMark, ...], ...]
    title: str


@dataclass(frozen=True)
class FlightSamples:
    """``fly``'s figure of one drone: reference and flown positions (N, 3) m at ``t`` (N,) s,
    the ink strokes (K, 3+), the error (N,) m and the numbers of the title."""

    t: FloatArray
    p_ref: FloatArray
    p: FloatArray
    ink: tuple[FloatArray, ...]
    position_error: FloatArray
    rmse_m: float
    max_error_m: float
    saturated: int
    title: str


@dataclass(frozen=True)
class NormPanel:
    """One derivative of every drone against time: ``curves`` each (N, 2) (t s, size),
    ``bounds`` the limits, ``per_axis`` whether the size is the largest component."""

    curves: tuple[FloatArray, ...]
    bounds: tuple[float, ...]
    per_axis: bool


@dataclass(frozen=True)
class WritingSamples:
    """``write``'s figure: every board side by side, the derivatives' sizes against time.

    Board coordinates (u, v) in m, board ``k`` shifted to its cell of a nearly square
    grid: ``inputs`` the input strokes (K, 2), ``pen_down`` each drone's path (N, 2) with
    NaN where the pen is up (the line breaks there), ``pen_up`` the points with the pen
    up (P, 2). ``board_limits`` ((u0, u1), (v0, v1)) the view.
    """

    inputs: tuple[FloatArray, ...]
    pen_down: tuple[FloatArray, ...]
    pen_up: FloatArray
    board_limits: tuple[tuple[float, float], tuple[float, float]]
    board_title: str
    norms: tuple[NormPanel, ...]
    duration_s: float
    title: str


@dataclass(frozen=True)
class Area:
    """A polygon to fill: its outer ring and its holes' rings, each (K, 2), m."""

    exterior: FloatArray
    holes: tuple[FloatArray, ...]


@dataclass(frozen=True)
class CoverageSamples:
    """``cover``'s figure: the field from above, the flight's derivatives against time.

    ``covered`` and ``missed`` the areas to fill, ``boundaries`` the rings of the fields'
    shells and holes (K, 2); ``dots`` (M, 2) setpoints, m, coloured by ``dot_speed`` (M,),
    m/s; ``waypoints`` (W, 2), m. Against ``t`` (N,) s: ``speed`` (N,) m/s and the
    horizontal components' magnitudes ``acceleration`` (N, 2) m/s² and ``jerk`` (N, 2)
    m/s³, with their ``limits`` (speed, acceleration, jerk).
    """

    covered: tuple[Area, ...]
    missed: tuple[Area, ...]
    boundaries: tuple[FloatArray, ...]
    dots: FloatArray
    dot_speed: FloatArray
    waypoints: FloatArray
    t: FloatArray
    speed: FloatArray
    acceleration: FloatArray
    jerk: FloatArray
    limits: tuple[float, float, float]
    title: str


def sample_fit(fit: PointFit, title: str = "") -> FitSamples:
    """``fit``'s trajectory at :data:`FIT_SAMPLES` times, and its limits per derivative."""
    traj = fit.trajectory
    t = np.linspace(0.0, traj.duration, FIT_SAMPLES)
    derivatives = tuple(traj.evaluate(t, order) for order in (1, 2, 3))
    limits = tuple(
        tuple(_limit_mark(lim, values) for lim in fit.limits if lim.order == order)
        for order, values in zip((1, 2, 3), derivatives, strict=True)
    )
    check = fit.verification
    return FitSamples(
        points=fit.points,
        path=traj.evaluate(t),
        t=t,
        derivatives=derivatives,
        limits=limits,
        title=f"{title}  duration {traj.duration:.2f} s, max excess {check.max_excess:.1e}, "
        f"rms deviation {1e3 * fit.rms_deviation_m:.1f} mm",
    )


def _limit_mark(lim: DerivativeLimit, values: FloatArray) -> LimitMark:
    """A box: its widest bounds; a norm: the norm and its radius; else the horizontal norm."""
    from skyquill.limits import BoxLimit, NormLimit  # the core: not imported by the worker

    if isinstance(lim, BoxLimit):
        return LimitMark(None, None, (float(lim.upper.max()), float(lim.lower.min())))
    if isinstance(lim, NormLimit):
        return LimitMark("norm", np.linalg.norm(values, axis=1), (float(lim.radius),))
    horizontal = np.hypot(values[:, 0], values[:, 1])
    return LimitMark("|xy|", horizontal, (float(lim.radius),))


def sample_flight(flight: Flight, title: str = "") -> FlightSamples:
    """The arrays of ``flight`` the figure draws, and its title."""
    saturated = sum(flight.saturations.values())
    return FlightSamples(
        t=flight.t,
        p_ref=flight.p_ref,
        p=flight.p,
        ink=tuple(flight.ink),
        position_error=flight.position_error,
        rmse_m=flight.rmse_m,
        max_error_m=flight.max_error_m,
        saturated=saturated,
        title=f"{title}  {flight.controller} on {flight.sim}: RMSE {1e3 * flight.rmse_m:.2f} mm, "
        f"max {1e3 * flight.max_error_m:.2f} mm, {saturated} saturated step(s)".strip(),
    )


def sample_missions(missions: list[Mission], title: str = "") -> WritingSamples:
    """Every drone's board view and derivative sizes (see :class:`WritingSamples`)."""
    columns = math.ceil(math.sqrt(len(missions)))
    size = max(m.options.size_m for m in missions)
    pitch = size * (1.0 + BOARD_GAP)
    inputs: list[FloatArray] = []
    downs: list[FloatArray] = []
    ups: list[FloatArray] = []
    for k, mission in enumerate(missions):
        shift = pitch * np.array([k % columns, -(k // columns)])
        traj = mission.trajectory
        t = np.linspace(0.0, traj.duration, BOARD_SAMPLES)
        uv = mission.board.to_board(traj.evaluate(t))[:, :2] + shift
        down = mission.pen(t) > 0
        ups.append(uv[~down])
        inputs.extend(mission.board.to_board(s)[:, :2] + shift for s in mission.strokes_world)
        downs.append(np.where(down[:, None], uv, np.nan))  # NaN breaks the line at pen-up
    rows = math.ceil(len(missions) / columns)
    margin = 0.1 * size  # the boards, not the take-off transits
    worst = max(m.deviation.max_m for m in missions)
    duration = max(m.trajectory.duration for m in missions)
    return WritingSamples(
        inputs=tuple(inputs),
        pen_down=tuple(downs),
        pen_up=np.concatenate(ups) if ups else np.empty((0, 2)),
        board_limits=(
            (-margin, (columns - 1) * pitch + size + margin),
            (-(rows - 1) * pitch - margin, size + margin),
        ),
        board_title=f"boards: {duration:.1f} s, deviation {1e3 * worst:.1f} mm",
        norms=tuple(_norm_panel(missions, order) for order in (1, 2, 3)),
        duration_s=duration,
        title=f"{title}  {len(missions)} drone(s), max deviation {1e3 * worst:.2f} mm, max "
        f"excess {max(m.verification.max_excess for m in missions):.1e}",
    )


def _norm_panel(missions: list[Mission], order: int) -> NormPanel:
    """Derivative ``order`` of every drone against time, and its limits.

    Its norm, or its largest component where the limit is per axis (a box).
    """
    from skyquill.limits import BoxLimit  # the core: not imported by the worker

    limits = [lim for lim in missions[0].options.derivative_limits() if lim.order == order]
    per_axis = any(isinstance(lim, BoxLimit) for lim in limits)
    curves = []
    for mission in missions:
        traj = mission.trajectory
        t = np.linspace(0.0, traj.duration, CURVE_SAMPLES)
        values = traj.evaluate(t, order)
        size = np.abs(values).max(axis=1) if per_axis else np.linalg.norm(values, axis=1)
        curves.append(np.column_stack([t, size]))
    bounds = tuple(
        float(lim.upper.max()) if isinstance(lim, BoxLimit) else float(lim.radius) for lim in limits
    )
    return NormPanel(tuple(curves), bounds, per_axis)


def sample_coverage(plan: CoveragePlan) -> CoverageSamples:
    """What ``cover``'s figure of ``plan`` draws (see :class:`CoverageSamples`)."""
    import shapely  # the core: not imported by the worker

    opts = plan.options
    sp = plan.samples()
    swept = plan.sprayed
    speed = np.linalg.norm(sp.v, axis=1)
    every = max(1, speed.size // MAX_DOTS)
    missed = "" if plan.missed is None else f", {plan.missed.area_m2:.3g} m²"
    return CoverageSamples(
        covered=_areas(plan.region.intersection(swept)),
        missed=_areas(plan.region.difference(swept)),
        boundaries=tuple(
            np.asarray(ring.coords)[:, :2] for ring in shapely.get_parts(plan.region.boundary)
        ),
        dots=sp.p[::every, :2],
        dot_speed=speed[::every],
        waypoints=np.asarray(plan.waypoints)[:, :2],
        t=sp.t,
        speed=speed,
        acceleration=np.abs(sp.a[:, :2]),
        jerk=np.abs(sp.j[:, :2]),
        limits=(float(opts.vmax), float(opts.amax), float(opts.jmax)),
        # Two lines: on one, a long flight's numbers ran past the map's left edge.
        title=f"{opts.pattern}: {plan.duration:.1f} s, {plan.path_length:.1f} m\n"
        f"coverage {100 * plan.coverage:.1f} % (red: missed{missed})",
    )


def _areas(shape: BaseGeometry) -> tuple[Area, ...]:
    """The polygons of ``shape`` (a polygon or a collection), as rings to fill."""
    from shapely.geometry import Polygon

    return tuple(
        Area(
            np.asarray(part.exterior.coords)[:, :2],
            tuple(np.asarray(hole.coords)[:, :2] for hole in part.interiors),
        )
        for part in getattr(shape, "geoms", [shape])
        if isinstance(part, Polygon) and not part.is_empty
    )
