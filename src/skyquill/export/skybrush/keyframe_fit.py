"""A C2 cubic spline on given segments, as close to the plan as its limits allow (a QP).

Where the plan is not one cubic per segment, the keyframes are the cubic Bézier segments
``Q`` that minimise the squared distance from the plan (sampled :data:`SAMPLES` times per
segment, weighted by the segment's length: the integral of the squared error), subject to

* C2 joins (velocity and acceleration continuous; the point is shared),
* the plan's position, velocity and acceleration at both ends of the region (where it
  meets exact pieces or the plan's own start and end),
* the plan's limits on every segment's Bézier hull: velocity ``3 dQ / h``, acceleration
  ``6 d^2Q / h^2``, jerk ``6 d^3Q / h^3`` (``d`` the forward difference); the curve lies in
  the convex hull of its derivative's Bézier points, so each limit holds on the whole
  segment (norms as second-order cones, boxes and vertical bounds as half-spaces).

The limits may be shrunk by a ``margin`` (a refit asks for one). The QP is first solved
without the limits (equalities alone: one sparse KKT solve); when that already meets them it
is the answer, else Clarabel solves the conic program. Long regions are cut into windows of
at most :data:`WINDOW_SEGMENTS` segments at the plan's own states (it is C2 there).
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from skyquill.errors import InfeasibleError, SolverError
from skyquill.export.base import ALLOWED_EXCESS
from skyquill.limits import BoxLimit, CylinderLimit, DerivativeLimit, NormLimit
from skyquill.solvers import QuadraticProgram, SecondOrderCones, solve_qp
from skyquill.trajectory import Trajectory
from skyquill.validation import FloatArray

#: Points per segment at which the distance from the plan is measured.
SAMPLES = 8
#: Most segments solved in one program.
WINDOW_SEGMENTS = 300
#: Relative slack with which the unconstrained solution counts as meeting a limit.
INSIDE_TOLERANCE = 1e-9
#: Share of each limit the fit may exceed on its hull, per order: a quarter of what the
#: delivery allows (:data:`~skyquill.export.base.ALLOWED_EXCESS`), the rest left to the grid's
#: rounding. Without it a plan on its jerk limit everywhere (a time-optimal move, whose jerk
#: switches between its bounds) leaves no room to make up a switch that falls inside a
#: segment, and the fit either leaves the plan by centimetres or is infeasible.
FIT_SLACK = {order: 0.25 * excess for order, excess in ALLOWED_EXCESS.items()}
#: Forward-difference stencils of a cubic's hull points per derivative order, and the factor
#: (times ``1 / h^order``) that makes them the derivative's Bézier points.
HULL = {
    1: (((-1, 1, 0, 0), (0, -1, 1, 0), (0, 0, -1, 1)), 3.0),
    2: (((1, -2, 1, 0), (0, 1, -2, 1)), 6.0),
    3: (((-1, 3, -3, 1),), 6.0),
}


def fit_region(
    traj: Trajectory,
    times_ms: FloatArray,
    limits: Sequence[DerivativeLimit],
    margin: float = 0.0,
) -> FloatArray:
    """Bézier points of the C2 cubic segments ``times_ms`` (ms) nearest ``traj`` in its limits.

    Parameters
    ----------
    traj
        The plan (z-up world frame, m, s); held at its end past its duration.
    times_ms
        Segment boundaries, shape (S + 1,), ms, S >= 4 per window.
    limits
        The plan's limits (speed, acceleration, jerk; 2- or 3-axis).
    margin
        Relative shrink of every limit, in [0, 1).

    Returns
    -------
    numpy.ndarray, shape (S, 4, 3)
        Each segment's Bézier points, m; a segment's last point is the next one's first.

    Raises
    ------
    InfeasibleError
        When no C2 cubic on these segments meets the limits and the plan's end states.
    """
    times = np.asarray(times_ms, dtype=float)
    n = times.size - 1
    windows = max(1, -(-n // WINDOW_SEGMENTS))
    cuts = np.round(np.linspace(0, n, windows + 1)).astype(int)
    parts = [
        _fit_window(traj, times[a : b + 1] / 1000.0, limits, margin)
        for a, b in itertools.pairwise(cuts)
    ]
    return np.concatenate(parts)


def _state(traj: Trajectory, t: float) -> list[FloatArray]:
    """Position, velocity and acceleration of ``traj`` at ``t`` (held past its end)."""
    if t >= traj.duration:
        end = traj.evaluate(np.array([traj.duration]))[0]
        return [end, *(traj.evaluate(np.array([traj.duration]), k)[0] for k in (1, 2))]
    return [traj.evaluate(np.array([t]), k)[0] for k in range(3)]


def _fit_window(
    traj: Trajectory, times_s: FloatArray, limits: Sequence[DerivativeLimit], margin: float
) -> FloatArray:
    """One window: a QP over the ``3 S + 1`` Bézier points per axis."""
    h = np.diff(times_s)
    s_count = h.size
    n_pts = 3 * s_count + 1
    cost, rhs = _deviation(traj, times_s)
    eq, b_eq = _equalities(h, _state(traj, times_s[0]), _state(traj, times_s[-1]))
    P = sp.csc_array(sp.kron(sp.eye_array(3), cost.T @ cost))
    q = -np.concatenate([cost.T @ rhs[:, ax] for ax in range(3)])
    A_eq = sp.csc_array(sp.kron(sp.eye_array(3), eq))
    b = np.concatenate([b_eq[:, ax] for ax in range(3)])
    x = _equality_solution(P, q, A_eq, b)
    if x is not None and _inside(x.reshape(3, n_pts).T, h, limits, margin):
        return _segments(x.reshape(3, n_pts).T)
    G, g, cones = _limit_constraints(h, n_pts, limits, margin)
    qp = QuadraticProgram(P, q, A_eq, b, G, g, cones)
    sol = solve_qp(qp, "clarabel", tol=1e-9)
    if sol.status == "infeasible":
        raise InfeasibleError(
            f"keyframes: no C2 cubic on {s_count} segments from {times_s[0]:.3f} s to "
            f"{times_s[-1]:.3f} s keeps the plan's limits (margin {margin:g}); expected a "
            "plan inside its limits",
            ("limits",),
        )
    if sol.status != "optimal" or sol.x is None:
        raise SolverError(
            f"keyframes: the fit from {times_s[0]:.3f} s to {times_s[-1]:.3f} s failed "
            f"({sol.message}); expected Clarabel to solve it"
        )
    return _segments(sol.x.reshape(3, n_pts).T)


def _segments(points: FloatArray) -> FloatArray:
    """The points (3 S + 1, 3) as segments (S, 4, 3) sharing their ends."""
    s_count = (points.shape[0] - 1) // 3
    idx = 3 * np.arange(s_count)[:, None] + np.arange(4)[None, :]
    return np.asarray(points[idx])


def _bernstein(u: FloatArray) -> FloatArray:
    return np.stack([(1 - u) ** 3, 3 * u * (1 - u) ** 2, 3 * u**2 * (1 - u), u**3], axis=1)


def _deviation(traj: Trajectory, times_s: FloatArray) -> tuple[sp.csr_array, FloatArray]:
    """Rows ``W B`` (samples x points) and the weighted plan ``W p`` (samples, 3)."""
    h = np.diff(times_s)
    u = (np.arange(SAMPLES) + 0.5) / SAMPLES
    basis = _bernstein(u)  # (SAMPLES, 4)
    weight = np.sqrt(h / SAMPLES)  # the integral of the squared distance
    seg = np.repeat(np.arange(h.size), SAMPLES)
    rows = np.repeat(np.arange(seg.size), 4)
    cols = (3 * seg[:, None] + np.arange(4)[None, :]).ravel()
    vals = (np.tile(basis, (h.size, 1)) * weight[seg][:, None]).ravel()
    matrix = sp.csr_array((vals, (rows, cols)), shape=(seg.size, 3 * h.size + 1))
    t = (times_s[:-1, None] + u[None, :] * h[:, None]).ravel()
    plan = traj.evaluate(np.minimum(t, traj.duration))
    return matrix, plan * weight[seg][:, None]


def _equalities(
    h: FloatArray, start: list[FloatArray], end: list[FloatArray]
) -> tuple[sp.csr_array, FloatArray]:
    """C1 and C2 at every join, position, velocity, acceleration at both ends (per axis)."""
    n_pts = 3 * h.size + 1
    rows: list[dict[int, float]] = []
    rhs: list[FloatArray] = []
    zero = np.zeros(3)
    for k in range(1, h.size):
        m, ha, hb = 3 * k, h[k - 1], h[k]
        rows.append({m: 1 / ha + 1 / hb, m - 1: -1 / ha, m + 1: -1 / hb})
        rows.append(
            {m - 2: 1 / ha**2, m - 1: -2 / ha**2, m: 1 / ha**2 - 1 / hb**2, m + 1: 2 / hb**2}
            | {m + 2: -1 / hb**2}
        )
        rhs.extend([zero, zero])
    h0, hl, last = h[0], h[-1], n_pts - 1
    rows.extend(
        [
            {0: 1.0},
            {0: -3 / h0, 1: 3 / h0},
            {0: 6 / h0**2, 1: -12 / h0**2, 2: 6 / h0**2},
            {last: 1.0},
            {last - 1: -3 / hl, last: 3 / hl},
            {last - 2: 6 / hl**2, last - 1: -12 / hl**2, last: 6 / hl**2},
        ]
    )
    rhs.extend([*start, *end])
    r = [i for i, row in enumerate(rows) for _ in row]
    c = [col for row in rows for col in row]
    v = [val for row in rows for val in row.values()]
    return sp.csr_array((v, (r, c)), shape=(len(rows), n_pts)), np.array(rhs)


def _equality_solution(
    P: sp.csc_array, q: FloatArray, A: sp.csc_array, b: FloatArray
) -> FloatArray | None:
    """The minimiser subject to the equalities alone (one sparse KKT solve), or None."""
    zero = sp.csc_array((A.shape[0], A.shape[0]))
    kkt = sp.csc_array(sp.vstack([sp.hstack([P, A.T]), sp.hstack([A, zero])]))
    try:
        with np.errstate(all="ignore"):
            x = spla.spsolve(kkt, np.concatenate([-q, b]))
    except RuntimeError:  # pragma: no cover - a singular KKT: the QP decides
        return None
    x = np.asarray(x)[: q.size]
    return x if np.all(np.isfinite(x)) else None


def hull_points(points: FloatArray, h: FloatArray) -> dict[int, FloatArray]:
    """Per order, the derivative's Bézier points of cubic segments, SI units.

    ``points`` (..., 4, 3) Bézier points (m) of segments of ``h`` (...,) s; returns
    ``{1: (..., 3, 3), 2: (..., 2, 3), 3: (..., 1, 3)}``.
    """
    hh = np.asarray(h, dtype=float)[..., None, None]
    return {
        1: 3.0 * np.diff(points, axis=-2) / hh,
        2: 6.0 * np.diff(points, 2, axis=-2) / hh**2,
        3: 6.0 * np.diff(points, 3, axis=-2) / hh**3,
    }


def hull_excess(limits: Sequence[DerivativeLimit], hull: dict[int, FloatArray]) -> FloatArray:
    """Per segment (leading axes of ``hull``), the largest relative excess of each order.

    Returns an array of shape (..., 4): column ``n`` the excess of order ``n`` (column 0 is
    unused), ``<= 0`` where every limit of that order holds on the hull.
    """
    shape = next(iter(hull.values())).shape[:-2]
    out = np.full((*shape, 4), -np.inf)
    for lim in limits:
        if lim.order not in hull:
            continue
        x = hull[lim.order]
        if isinstance(lim, NormLimit):
            e = np.linalg.norm(x[..., : lim.dim], axis=-1).max(axis=-1) / lim.radius - 1.0
        elif isinstance(lim, CylinderLimit):
            e = np.linalg.norm(x[..., :2], axis=-1).max(axis=-1) / lim.radius - 1.0
            if lim.z_lower is not None and lim.z_upper is not None:
                up = (x[..., 2].max(axis=-1) - lim.z_upper) / abs(lim.z_upper)
                down = (lim.z_lower - x[..., 2].min(axis=-1)) / abs(lim.z_lower)
                e = np.maximum(e, np.maximum(up, down))
        elif isinstance(lim, BoxLimit):
            d = lim.dim
            up = ((x[..., :d] - lim.upper) / np.abs(lim.upper)).max(axis=(-1, -2))
            down = ((lim.lower - x[..., :d]) / np.abs(lim.lower)).max(axis=(-1, -2))
            e = np.maximum(up, down)
        else:  # pragma: no cover - the three limit kinds
            continue
        out[..., lim.order] = np.maximum(out[..., lim.order], e)
    return out


def _inside(
    points: FloatArray, h: FloatArray, limits: Sequence[DerivativeLimit], margin: float
) -> bool:
    excess = hull_excess(limits, hull_points(_segments(points), h))[..., 1:]
    room = np.array([_room(order, margin) for order in (1, 2, 3)])
    return bool(np.all((1.0 + excess) <= room * (1.0 + INSIDE_TOLERANCE)))


def _room(order: int, margin: float) -> float:
    """The share of a limit of ``order`` the fit may use: the slack less the margin."""
    return (1.0 + FIT_SLACK.get(order, 0.0)) * (1.0 - margin)


def _limit_constraints(
    h: FloatArray, n_pts: int, limits: Sequence[DerivativeLimit], margin: float
) -> tuple[sp.csc_array, FloatArray, SecondOrderCones | None]:
    """Half-spaces and second-order cones that hold every limit on every segment's hull.

    Each hull point is written as a difference of Bézier points (``d^n Q``), its bound
    scaled by ``h^n / factor``: the same constraint, better conditioned.
    """
    lin_rows: list[sp.csr_array] = []
    lin_rhs: list[FloatArray] = []
    cone_blocks: list[sp.csr_array] = []
    cone_rhs: list[FloatArray] = []
    dims: list[int] = []
    for lim in limits:
        if lim.order not in HULL:
            continue
        stencils, factor = HULL[lim.order]
        shrink = _room(lim.order, margin)
        diff, scale = _difference_rows(h, stencils, n_pts, lim.order, factor)
        if isinstance(lim, NormLimit | CylinderLimit):
            axes = lim.dim if isinstance(lim, NormLimit) else 2
            cone_blocks.append(_cone_rows(diff, axes, n_pts))
            head = np.zeros((diff.shape[0], axes + 1))
            head[:, 0] = lim.radius * shrink * scale
            cone_rhs.append(head.ravel())
            dims.extend([axes + 1] * diff.shape[0])
        if isinstance(lim, CylinderLimit) and lim.z_upper is not None:
            assert lim.z_lower is not None
            bounds = [(2, lim.z_upper, 1.0), (2, -lim.z_lower, -1.0)]
        elif isinstance(lim, BoxLimit):
            bounds = [(ax, float(lim.upper[ax]), 1.0) for ax in range(lim.dim)]
            bounds += [(ax, -float(lim.lower[ax]), -1.0) for ax in range(lim.dim)]
        else:
            bounds = []
        for ax, bound, sign in bounds:
            block = sp.hstack(
                [diff * sign if a == ax else sp.csr_array((diff.shape[0], n_pts)) for a in range(3)]
            )
            lin_rows.append(sp.csr_array(block))
            lin_rhs.append(bound * shrink * scale)
    G = sp.csc_array(sp.vstack(lin_rows)) if lin_rows else sp.csc_array((0, 3 * n_pts))
    g = np.concatenate(lin_rhs) if lin_rhs else np.zeros(0)
    cones = None
    if cone_blocks:
        cones = SecondOrderCones(
            sp.csc_array(sp.vstack(cone_blocks)), np.concatenate(cone_rhs), tuple(dims)
        )
    return G, g, cones


def _difference_rows(
    h: FloatArray, stencils: tuple[tuple[int, ...], ...], n_pts: int, order: int, factor: float
) -> tuple[sp.csr_array, FloatArray]:
    """Rows ``d^n Q`` of every hull point (per axis) and each one's ``h^n / factor``."""
    per_seg = len(stencils)
    count = h.size * per_seg
    seg = np.repeat(np.arange(h.size), per_seg)
    stencil = np.tile(np.array(stencils, dtype=float), (h.size, 1))  # (count, 4)
    rows = np.repeat(np.arange(count), 4)
    cols = (3 * seg[:, None] + np.arange(4)[None, :]).ravel()
    matrix = sp.csr_array((stencil.ravel(), (rows, cols)), shape=(count, n_pts))
    matrix.eliminate_zeros()
    return matrix, h[seg] ** order / factor


def _cone_rows(diff: sp.csr_array, axes: int, n_pts: int) -> sp.csr_array:
    """Clarabel's ``b - A x`` rows for ``||d^n Q_xyz|| <= bound``: per point (bound, -dQ)."""
    count = diff.shape[0]
    coo = diff.tocoo()
    rows, cols, vals = [], [], []
    for ax in range(axes):
        rows.append(coo.row * (axes + 1) + 1 + ax)
        cols.append(coo.col + ax * n_pts)
        vals.append(-coo.data)
    return sp.csr_array(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
        shape=(count * (axes + 1), 3 * n_pts),
    )
