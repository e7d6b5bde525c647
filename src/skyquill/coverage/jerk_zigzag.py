"""The zigzag whose turns are time-optimal under the jerk limit (issue 16, part 5).

Paper 001 fixes the path first (a spline through rounded corners) and then
times it with the speed LP: at a U-turn of radius ``r`` the jerk limit holds
the speed to ``(jmax r^2)^(1/3)`` (1.4 m/s for the paper's 2 m swath), so
every turn is a slow crawl around a curve chosen before its timing. Here the
turn is not drawn first: it is the time-optimal motion between two states,
full speed along one lane and full speed back along the next, computed per
axis by Ruckig (Berscheid & Kröger, RSS 2021), and its shape is whatever
that motion sweeps. With the paper's limits the along-lane axis reverses from
+3 to -3 m/s in ``2 sqrt(6 / 3) = 2.83 s`` while the cross axis steps 2 m
rest to rest in ``(32 * 2 / 3)^(1/3) = 2.77 s``: both fit in one turn, which
sweeps a loop ``2.83 m`` deep beyond its entry point.

Construction, for a convex region (other regions are flown piece by piece):

* lanes are chords of the region along the lane direction, at most one
  swath apart, the outer ones ``side_inset`` inside the region;
* each turn is pushed out along its lanes as far as the region shrunk by
  ``edge_gap`` allows (the loop is a fixed shape, so the bound is exact:
  one linear inequality per side of the shrunk convex polygon);
* between turns, Ruckig joins the exit of one turn to the entry of the next
  (straight, at full speed when the lane is long enough); the flight starts
  and ends at rest on the first and last lane.

The speed is a norm while Ruckig bounds each axis, so the turn's entry speed
is lowered until the sampled speed norm of the turn is within the limit
(``vmax``); acceleration and jerk per axis are Ruckig's own bounds (norm
limits are held by the inscribed box, ``limit / sqrt(2)`` per axis). The
planner's dense check then verifies the whole flight against the true limits.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from ruckig import InputParameter, Result, Ruckig, Synchronization, Trajectory
from shapely.geometry import LineString, Polygon

from skyquill.errors import InfeasibleError, SolverError
from skyquill.optimize.legs import LegLimits, leg_pieces
from skyquill.trajectory import PiecewisePolynomial
from skyquill.validation import FloatArray

#: Turn speed search: the fraction of the lane speed is lowered by this factor until
#: the turn's speed norm holds.
TURN_SPEED_STEP = 0.98
#: Time step of the turn's sampling (speed norm and the loop's shape), s.
TURN_SAMPLE_S = 0.005
#: Phases shorter than this are dropped (they only add round-off), s.
MIN_PHASE_S = 1e-9
#: The tuning's grid, in half swaths: the outer lanes' distance from the sides, and the
#: turns' closest approach to the boundary (the paper's square: 97 % in 22.1 s at
#: 1.0 and 0.1, 98.7 % in 26.1 s at 0.9 and 0.15).
SIDE_INSETS = (1.0, 0.95, 0.9, 0.8)
EDGE_GAPS = (0.05, 0.1, 0.2, 0.3, 0.45)
#: Turn entry speeds tried, fractions of vmax: slower turns sweep shallower loops and fit
#: the short lanes of a triangle's apex (none of the full-speed layouts did).
TURN_SPEEDS = (1.0, 0.6, 0.35)
#: Lane spacings tried, in swaths.
SPACINGS = (1.0, 0.9, 0.8)
#: The default shape (no tuning), in half swaths.
DEFAULT_SIDE_INSET = 0.9
DEFAULT_EDGE_GAP = 0.3


@dataclass(frozen=True)
class AxisLimits:
    """Per-axis bounds Ruckig holds and the speed norm the flight must keep.

    Attributes
    ----------
    vmax : float
        Speed norm, m/s.
    amax, jmax : float
        Acceleration (m/s^2) and jerk (m/s^3) bound of each axis.
    """

    vmax: float
    amax: float
    jmax: float

    @classmethod
    def from_limits(cls, vmax: float, amax: float, jmax: float, *, per_axis: bool) -> AxisLimits:
        """Per-axis limits that keep the given ones (norms: the inscribed box)."""
        scale = 1.0 if per_axis else 1.0 / math.sqrt(2.0)
        return cls(vmax, amax * scale, jmax * scale)


@dataclass(frozen=True)
class JerkZigzagShape:
    """The geometry of one plan (lengths in m).

    Attributes
    ----------
    angle : float
        Lane direction, rad from the x axis.
    spacing : float
        Largest distance between neighbouring lanes (the swath or less).
    side_inset : float
        Distance of the first and last lanes from the region's sides.
    edge_gap : float
        Closest approach of a turn's loop, the start and the end to the boundary.
    turn_speed : float
        The highest turn entry speed tried, a fraction of ``vmax`` in (0, 1].
    """

    angle: float
    spacing: float
    side_inset: float
    edge_gap: float
    turn_speed: float = 1.0


@dataclass(frozen=True)
class JerkZigzag:
    """A planned jerk-zigzag.

    Attributes
    ----------
    trajectory : PiecewisePolynomial
        The flight at ``altitude``, 3-D, cubic pieces, rest to rest.
    waypoints : ndarray, shape (K, 2)
        Start, every turn's entry and exit, end (m).
    turn_speed : float
        The lanes' speed at the turns, m/s.
    """

    trajectory: PiecewisePolynomial
    waypoints: FloatArray
    turn_speed: float


def plan_jerk_zigzag(
    region: Polygon, shape: JerkZigzagShape, limits: AxisLimits, altitude: float
) -> JerkZigzag:
    """The jerk-zigzag over the convex ``region`` with ``shape``.

    Raises
    ------
    InfeasibleError
        The region is too narrow for the lanes and turns of ``shape`` (family
        ``"coverage"``).
    SolverError
        Ruckig fails on a segment.
    """
    u = np.array([math.cos(shape.angle), math.sin(shape.angle)])
    lanes = _lanes(region, shape, u)
    if len(lanes) < 2:
        raise InfeasibleError(
            "region: got room for fewer than two lanes, expected a region wider than the swath",
            ("coverage",),
        )
    step = _spacing(lanes, u) * _normal(u)
    speed, loop = _turn(step, u, limits, shape.turn_speed)
    inner = region.buffer(-shape.edge_gap, join_style="mitre")
    if not isinstance(inner, Polygon) or inner.is_empty:
        raise InfeasibleError(
            f"edge_gap: got {shape.edge_gap:g} m, expected a region wider than twice it",
            ("coverage",),
        )
    planes = _half_planes(inner)
    states = _states(lanes, u, step, (speed, loop), planes)
    # Even segments run along a lane (start, between turns, end), odd ones are turns.
    pieces = [
        _turn_pieces(a, b, limits) if k % 2 else _lane_pieces(a, b, limits)
        for k, (a, b) in enumerate(itertools.pairwise(states))
    ]
    trajectory = _joined(pieces, altitude)
    return JerkZigzag(trajectory, np.array([s[0] for s in states]), speed)


def _lanes(region: Polygon, shape: JerkZigzagShape, u: FloatArray) -> list[FloatArray]:
    """Each lane's chord ``[p, q]`` (2, 2) through ``region``, in sweep order (m)."""
    n = np.array([-u[1], u[0]])
    coords = np.asarray(region.exterior.coords, dtype=np.float64)
    across = coords @ n
    lo, hi = float(across.min()) + shape.side_inset, float(across.max()) - shape.side_inset
    if hi <= lo:
        return []
    count = math.ceil((hi - lo) / shape.spacing - 1e-9) + 1
    reach = float(np.ptp(coords @ u)) + 1.0
    centre = coords.mean(axis=0)
    chords = []
    for offset in np.linspace(lo, hi, count):
        base = centre + (offset - centre @ n) * n
        line = LineString([base - reach * u, base + reach * u]).intersection(region)
        if line.is_empty or not isinstance(line, LineString):
            continue
        ends = np.asarray(line.coords, dtype=np.float64)[[0, -1]]
        chords.append(ends if (ends[1] - ends[0]) @ u >= 0.0 else ends[::-1])
    return chords


def _turn(
    step: FloatArray, u: FloatArray, limits: AxisLimits, fraction: float
) -> tuple[float, FloatArray]:
    """The fastest entry speed whose turn keeps the speed norm, and the loop (K, 2).

    The loop is sampled relative to the entry point, for a turn entered
    along ``+u`` (the other end's is its mirror along ``u``).
    """
    speed = fraction * limits.vmax
    while True:
        state_in = (np.zeros(2), speed * u)
        state_out = (step, -speed * u)
        ruckig = _ruckig(state_in, state_out, _box(limits))
        t = np.arange(0.0, ruckig.duration, TURN_SAMPLE_S)
        kinematics = [ruckig.at_time(x) for x in t]
        velocity = np.array([k[1] for k in kinematics])
        if np.linalg.norm(velocity, axis=1).max() <= limits.vmax:
            return speed, np.array([k[0] for k in kinematics])
        speed *= TURN_SPEED_STEP


def _half_planes(polygon: Polygon) -> tuple[FloatArray, FloatArray]:
    """``normals (S, 2)`` and ``offsets (S,)`` with ``polygon = {x: normals x <= offsets}``."""
    ring = np.asarray(polygon.exterior.coords, dtype=np.float64)
    if polygon.exterior.is_ccw is False:
        ring = ring[::-1]
    edges = np.diff(ring, axis=0)
    keep = np.linalg.norm(edges, axis=1) > 0.0
    edges, starts = edges[keep], ring[:-1][keep]
    normals = np.column_stack([edges[:, 1], -edges[:, 0]]) / np.linalg.norm(edges, axis=1)[:, None]
    return normals, np.einsum("ij,ij->i", normals, starts)


def _reach(
    point: FloatArray,
    direction: FloatArray,
    shape: FloatArray,
    planes: tuple[FloatArray, FloatArray],
) -> float:
    """Largest ``s`` with ``point + s direction + shape`` inside the half-planes (m).

    ``shape`` (K, 2) is a set of points relative to ``point`` (a turn's loop,
    or the origin alone for a point at rest).
    """
    normals, offsets = planes
    rate = normals @ direction
    room = offsets - normals @ point - (shape @ normals.T).max(axis=0)
    ahead = rate > 1e-12
    if not np.any(ahead):
        return math.inf
    return float(np.min(room[ahead] / rate[ahead]))


State = tuple[FloatArray, FloatArray]


def _spacing(lanes: list[FloatArray], u: FloatArray) -> float:
    """Distance between neighbouring lanes (equal by construction), m."""
    return float((lanes[1][0] - lanes[0][0]) @ _normal(u))


def _states(
    lanes: list[FloatArray],
    u: FloatArray,
    step: FloatArray,
    turn: tuple[float, FloatArray],
    planes: tuple[FloatArray, FloatArray],
) -> list[State]:
    """Start, every turn's entry and exit, end: ``(position, velocity)`` pairs (m, m/s).

    ``step`` (2,) is from a lane to the next, ``turn`` the entry speed and the loop.
    """
    speed, loop = turn
    origin = np.zeros((1, 2))
    first = lanes[0][0]
    states: list[State] = [(first + _reach(first, -u, origin, planes) * -u, np.zeros(2))]
    for k in range(len(lanes) - 1):
        sign = 1.0 if k % 2 == 0 else -1.0
        lane = lanes[k][0]
        # The loop entered along -u is the mirror of the one entered along +u.
        shape = loop if sign > 0 else -loop + 2.0 * np.outer(loop @ _normal(u), _normal(u))
        entry = lane + _reach(lane, sign * u, shape, planes) * sign * u
        states.append((entry, sign * speed * u))
        states.append((entry + step, -sign * speed * u))
    sign = 1.0 if (len(lanes) - 1) % 2 == 0 else -1.0
    last = states[-1][0]
    states.append((last + _reach(last, sign * u, origin, planes) * sign * u, np.zeros(2)))
    _check_order(states, u)
    return states


def _normal(u: FloatArray) -> FloatArray:
    return np.array([-u[1], u[0]])


def _check_order(states: list[State], u: FloatArray) -> None:
    """Every lane is flown forward: a lane shorter than its two turns cannot be."""
    for a, b in zip(states[::2], states[1::2], strict=True):
        heading = b[1] if np.any(b[1]) else a[1]
        if (b[0] - a[0]) @ heading < -1e-9:
            raise InfeasibleError(
                "region: got a lane shorter than its two turns, expected room to turn at "
                "the lanes' speed",
                ("coverage",),
            )


def _ruckig(
    start: State, end: State, limits: tuple[list[float], list[float], list[float]]
) -> Trajectory:
    """Ruckig's time-optimal motion from ``start`` to ``end`` (any number of axes, arriving
    together), under per-axis ``(velocity, acceleration, jerk)`` bounds."""
    dofs = len(start[0])
    inp = InputParameter(dofs)
    inp.current_position, inp.current_velocity = list(start[0]), list(start[1])
    inp.target_position, inp.target_velocity = list(end[0]), list(end[1])
    inp.current_acceleration = inp.target_acceleration = [0.0] * dofs
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = limits
    inp.synchronization = Synchronization.Time
    out = Trajectory(dofs)
    result = Ruckig(dofs).calculate(inp, out)
    if result != Result.Working:
        raise SolverError(f"Ruckig failed on a coverage turn or lane: {result}")
    return out


def _box(limits: AxisLimits) -> tuple[list[float], list[float], list[float]]:
    return [limits.vmax] * 2, [limits.amax] * 2, [limits.jmax] * 2


def _turn_pieces(start: State, end: State, limits: AxisLimits) -> tuple[FloatArray, FloatArray]:
    """A turn, both axes at once: durations (P,) s and coefficients (P, 4, 2)."""
    return _pieces(_ruckig(start, end, _box(limits)))


def _lane_pieces(start: State, end: State, limits: AxisLimits) -> tuple[FloatArray, FloatArray]:
    """A straight stretch along a lane, one axis along it: the speed is then the norm
    (two axes at their bounds would fly a diagonal lane at sqrt(2) vmax)."""
    offset = end[0] - start[0]
    length = float(np.linalg.norm(offset))
    if length <= 0.0:
        return np.zeros(0), np.zeros((0, 4, 2))
    heading = offset / length
    box = LegLimits(limits.vmax, limits.amax, limits.jmax, per_axis=True)
    return leg_pieces(
        start[0], end[0], box, speeds=(float(start[1] @ heading), float(end[1] @ heading))
    )


def _pieces(motion: Trajectory) -> tuple[FloatArray, FloatArray]:
    """Ruckig's motion as cubic pieces: durations (P,) s and coefficients (P, 4, d).

    Its phases have constant jerk, so each piece is exact: position, velocity
    and acceleration at the piece's start, jerk from the acceleration's change.
    """
    switches = {0.0, motion.duration}
    for profile in motion.profiles[0]:
        switches.update(np.cumsum(profile.t).tolist())
    times = np.array(sorted(t for t in switches if 0.0 <= t <= motion.duration))
    times = times[np.concatenate([[True], np.diff(times) > MIN_PHASE_S])]
    times[-1] = motion.duration
    coeffs = []
    for t0, t1 in itertools.pairwise(times):
        p0, v0, a0 = (np.atleast_1d(np.asarray(x, dtype=np.float64)) for x in motion.at_time(t0))
        a1 = np.atleast_1d(np.asarray(motion.at_time(t1)[2], dtype=np.float64))
        coeffs.append(np.stack([p0, v0, a0 / 2.0, (a1 - a0) / (t1 - t0) / 6.0]))
    return np.diff(times), np.array(coeffs)


def _joined(pieces: list[tuple[FloatArray, FloatArray]], altitude: float) -> PiecewisePolynomial:
    """The segments back to back at ``altitude`` (3-D)."""
    durations = np.concatenate([d for d, _ in pieces])
    planar = np.concatenate([c for _, c in pieces])
    height = np.zeros((planar.shape[0], 4, 1))
    height[:, 0, 0] = altitude
    breaks = np.concatenate([[0.0], np.cumsum(durations)])
    return PiecewisePolynomial(breaks, np.concatenate([planar, height], axis=2))


def lane_angles(region: Polygon) -> list[float]:
    """Lane directions worth trying, rad: the hull's longest side (first), then the axes."""
    hull = np.asarray(region.convex_hull.exterior.coords, dtype=np.float64)
    sides = np.diff(hull, axis=0)
    longest = sides[np.argmax(np.linalg.norm(sides, axis=1))]
    angles = [math.atan2(longest[1], longest[0]) % math.pi, 0.0, 0.5 * math.pi]
    return [a for k, a in enumerate(angles) if all(abs(a - b) > 1e-6 for b in angles[:k])]


def default_shape(region: Polygon, width: float, epsilon: float) -> JerkZigzagShape:
    """The untuned shape: lanes along the hull's longest side, ``epsilon`` swaths apart."""
    half = 0.5 * width
    inset, gap = DEFAULT_SIDE_INSET * half, DEFAULT_EDGE_GAP * half
    return JerkZigzagShape(lane_angles(region)[0], epsilon * width, inset, gap)


def tuning_shapes(region: Polygon, width: float) -> list[JerkZigzagShape]:
    """Every shape of the tuning grid (:data:`SPACINGS`, :data:`SIDE_INSETS`, :data:`EDGE_GAPS`)."""
    half = 0.5 * width
    return [
        JerkZigzagShape(angle, spacing * width, inset * half, gap * half, speed)
        for angle, spacing, inset, gap, speed in itertools.product(
            lane_angles(region), SPACINGS, SIDE_INSETS, EDGE_GAPS, TURN_SPEEDS
        )
    ]


def fastest(
    region: Polygon,
    shapes: list[JerkZigzagShape],
    limits: AxisLimits,
    altitude: float,
    *,
    accept: Callable[[FloatArray], bool],
    step: Callable[[str], None],
) -> tuple[JerkZigzag, FloatArray] | None:
    """The fastest flight of ``shapes`` that stays over ``region`` and that ``accept`` takes.

    Every shape is planned (Ruckig only, milliseconds); the flights are then
    measured from the fastest up until one is accepted, so that the coverage
    (the expensive part) is measured only as often as needed.

    Parameters
    ----------
    accept
        Told the flight's path (M, 2), m, sampled every ~2 cm: whether it covers enough.
    step
        Told each step before it starts (a deadline's check).

    Returns
    -------
    (JerkZigzag, ndarray (M, 2)) or None
        The flight and its path; None when no shape fits or none is accepted.
    """
    flights = []
    for shape in shapes:
        step(f"the jerk-zigzag of lanes at {math.degrees(shape.angle):.0f} deg")
        try:
            flights.append(plan_jerk_zigzag(region, shape, limits, altitude))
        except InfeasibleError:
            continue
    inside = region.buffer(PATH_TOLERANCE * math.sqrt(region.area))
    for flight in sorted(flights, key=lambda f: f.trajectory.duration):
        step("the coverage measure")
        path = sampled_path(flight.trajectory, limits.vmax)
        if inside.contains(LineString(path)) and accept(path):
            return flight, path
    return None


#: A flight counts as over the region within this fraction of its size (round-off).
PATH_TOLERANCE = 1e-9
#: Spacing of the sampled path, m (as the other patterns' dense paths).
PATH_SPACING_M = 0.02


def sampled_path(trajectory: PiecewisePolynomial, vmax: float) -> FloatArray:
    """The flight's horizontal path (M, 2), m, a sample at most :data:`PATH_SPACING_M` apart."""
    count = max(2, math.ceil(trajectory.duration * vmax / PATH_SPACING_M) + 1)
    t = np.linspace(0.0, trajectory.duration, count)
    path: FloatArray = trajectory.evaluate(t)[:, :2]
    return path
