"""Fit a path into a vehicle's upload budget (``--target``): one upload, or several.

A Crazyflie holds 31 polynomial pieces per upload (:mod:`skyquill.targets`),
and the next upload can only be written while it hovers. A path whose fit in
one upload (the target's pieces spread over the whole flight) misses the
fidelity tolerance is cut into consecutive chunks of its points, each fitted
on its own from rest to rest in at most one upload's pieces, with a hover of
:attr:`~skyquill.targets.UploadTarget.hover_s` between them: a
:class:`~skyquill.trajectory.RestToRestSequence` that :func:`plan_uploads`
cuts back into exactly those uploads.

Chunks are bisected where they miss the tolerance (only there: a path with
one dense knot of detail gets its uploads where the detail is), at the
slowest point of the chunk's middle third -- a corner the allocation slows
in anyway, so the added rest costs little time. ``fit`` and ``cover`` share
this; the fit of one chunk is the caller's (:class:`ChunkFitter`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from skyquill.errors import InfeasibleError
from skyquill.limits import DerivativeLimit
from skyquill.optimize.solve import FitResult
from skyquill.targets import Strategy, Upload, UploadTarget, hover, plan_uploads, uploads_summary
from skyquill.trajectory import RestToRestSequence, SplineTrajectory, Trajectory
from skyquill.validation import FloatArray
from skyquill.verify import Verification, verify

#: Most uploads one plan may be cut into. Each costs a hover and a radio
#: upload (about a second each on a Crazyflie), and the bisection at most two
#: fits per upload; 50 uploads of 31 pieces is already 20 times the
#: Crazyflie's memory, a mission better split by the user.
MAX_UPLOADS = 50
#: The split point of a chunk is looked for between these fractions of its arc length
#: (the middle third: both halves keep a fair share of the path).
SPLIT_WINDOW = (1.0 / 3.0, 2.0 / 3.0)


@dataclass(frozen=True)
class ChunkFit:
    """The fit of one chunk of points from rest to rest, in one upload.

    Attributes
    ----------
    result
        The engine's result; its trajectory has at most the target's pieces.
    times
        The chunk's points' times on its own clock, shape (n,), s, from 0.
    max_deviation_m
        Largest ``||p(t_i) - points_i||`` over the chunk, m.
    time_scale
        Stretch applied to the chunk's allocated timing (1 if none).
    accel_fraction
        Fraction of ``amax`` the chunk's time allocation used.
    """

    result: FitResult
    times: FloatArray
    max_deviation_m: float
    time_scale: float = 1.0
    accel_fraction: float | None = None


#: Fits ``points`` (n, d), m, from rest to rest in one upload (times allocated by the caller).
ChunkFitter = Callable[[FloatArray], ChunkFit]


@dataclass(frozen=True)
class BudgetPlan:
    """A fit cut into a target's uploads.

    Attributes
    ----------
    target
        The vehicle the plan is made for.
    strategy
        ``"one-upload"`` (one spline over the whole flight) or ``"split"``
        (chunks flown rest to rest, hovering between them).
    trajectory
        The plan: a :class:`~skyquill.trajectory.SplineTrajectory` of at most
        the target's pieces, or a :class:`~skyquill.trajectory.RestToRestSequence`
        of such splines and hovers.
    chunks
        Each motion chunk's fit, in flight order.
    bounds
        Index of the first point of each chunk and the last point, shape
        (len(chunks) + 1,); chunk ``k`` holds points ``bounds[k]..bounds[k+1]``
        (neighbours share their joining point).
    times
        Every point's time on the plan's clock, shape (N,), s (a joining point:
        its arrival).
    uploads
        :func:`~skyquill.targets.plan_uploads` of ``trajectory``.
    verification
        The dense check of ``trajectory`` against the fit's limits.
    """

    target: UploadTarget
    strategy: Strategy
    trajectory: Trajectory
    chunks: tuple[ChunkFit, ...]
    bounds: tuple[int, ...]
    times: FloatArray
    uploads: tuple[Upload, ...]
    verification: Verification

    def summary(self) -> dict[str, Any]:
        """The ``"target"`` section of a ``summary.json`` (SI units)."""
        return uploads_summary(self.target, self.strategy, self.uploads)


def one_upload(
    chunk: ChunkFit, target: UploadTarget, limits: tuple[DerivativeLimit, ...]
) -> BudgetPlan:
    """The plan of a fit made in one upload (``chunk`` holds every point)."""
    return _plan(target, "one-upload", (chunk,), (0, chunk.times.size - 1), limits)


def split_into_uploads(
    points: FloatArray,
    fit_chunk: ChunkFitter,
    tolerance_m: float,
    target: UploadTarget,
    limits: tuple[DerivativeLimit, ...],
    *,
    max_uploads: int | None = None,
) -> BudgetPlan:
    """Cut ``points`` (N, d), m, into chunks each fitted within ``tolerance_m`` in one upload.

    A chunk that misses the tolerance is bisected (see the module's
    docstring); a chunk of two points is a straight rest-to-rest move, exact.

    ``max_uploads``: the ceiling (``None``: :data:`MAX_UPLOADS`).

    Raises
    ------
    InfeasibleError
        More than ``max_uploads`` chunks would be needed; the message says how
        much of the path fits in that many.
    """
    ceiling = MAX_UPLOADS if max_uploads is None else max_uploads
    arc = _arc_length(points)
    done: dict[int, tuple[int, ChunkFit]] = {}  # first point -> (last point, fit)
    pending = [(0, points.shape[0] - 1)]
    while pending:
        first, last = pending.pop()
        chunk = fit_chunk(points[first : last + 1])
        if chunk.max_deviation_m <= tolerance_m or last - first < 2:
            done[first] = (last, chunk)
        else:
            middle = _split_point(arc[first : last + 1] - arc[first], chunk.times) + first
            pending += [(middle, last), (first, middle)]
        if len(done) + len(pending) > ceiling:
            raise _too_many_uploads(arc, done, tolerance_m, ceiling, target)
    firsts = sorted(done)
    bounds = (*firsts, points.shape[0] - 1)
    chunks = tuple(done[f][1] for f in firsts)
    strategy: Strategy = "split" if len(chunks) > 1 else "one-upload"
    return _plan(target, strategy, chunks, bounds, limits)


def lifted(traj: Trajectory, z: float) -> Trajectory:
    """A 2-D plan of splines (one, or a rest-to-rest sequence of them) at height ``z``, m."""
    if isinstance(traj, SplineTrajectory):
        return traj.in_3d(z)
    if isinstance(traj, RestToRestSequence):
        return RestToRestSequence(tuple(lifted(p, z) for p in traj.pieces))
    raise TypeError(f"traj: got {type(traj).__name__}, expected splines")  # pragma: no cover


def _plan(
    target: UploadTarget,
    strategy: Strategy,
    chunks: tuple[ChunkFit, ...],
    bounds: tuple[int, ...],
    limits: tuple[DerivativeLimit, ...],
) -> BudgetPlan:
    parts: list[Trajectory] = []
    times: list[FloatArray] = []
    clock = 0.0
    for k, chunk in enumerate(chunks):
        spline = chunk.result.trajectory
        if k > 0:
            # The vehicle holds the joining point while the next upload is written.
            parts.append(hover(spline.evaluate(np.zeros(1))[0], target.hover_s))
            clock += target.hover_s
        parts.append(spline)
        times.append(clock + (chunk.times if k == 0 else chunk.times[1:]))
        clock += spline.duration
    trajectory = parts[0] if len(parts) == 1 else RestToRestSequence(tuple(parts))
    # The one cut into uploads (refuses a part beyond the budget: a bug here, not the user's).
    uploads = plan_uploads(trajectory, target)
    return BudgetPlan(
        target,
        strategy,
        trajectory,
        chunks,
        bounds,
        np.concatenate(times),
        uploads,
        verify(trajectory, limits, guaranteed=True),
    )


def _arc_length(points: FloatArray) -> FloatArray:
    steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
    return np.concatenate([[0.0], np.cumsum(steps)])


def _split_point(arc: FloatArray, times: FloatArray) -> int:
    """Index (into the chunk) of its slowest interior point in the middle third of its length."""
    lo, hi = (arc[-1] * f for f in SPLIT_WINDOW)
    inner = np.arange(1, arc.size - 1)
    window = inner[(arc[inner] >= lo) & (arc[inner] <= hi)]
    if window.size == 0:  # a few far-apart points: the one nearest the middle
        return int(inner[np.argmin(np.abs(arc[inner] - 0.5 * arc[-1]))])
    # Speed at a point: the arc length over the time between its neighbours.
    dt = np.maximum(times[window + 1] - times[window - 1], 1e-12)
    speed = (arc[window + 1] - arc[window - 1]) / dt
    return int(window[np.argmin(speed)])


def _too_many_uploads(
    arc: FloatArray,
    done: dict[int, tuple[int, ChunkFit]],
    tolerance_m: float,
    max_uploads: int,
    target: UploadTarget,
) -> InfeasibleError:
    fitted = sum(arc[last] - arc[first] for first, (last, _) in done.items())
    fits = (
        f"the uploads fitted so far hold {fitted / len(done):.3g} m each, so about "
        f"{fitted / len(done) * max_uploads:.3g} m of path would fit"
        if done
        else f"no part of it fitted in one upload yet, so less than {arc[-1] / 2:.3g} m would"
    )
    return InfeasibleError(
        f"target: the {arc[-1]:.4g} m path needs more than {max_uploads} uploads of "
        f"{target.max_pieces} pieces within {tolerance_m * 1e3:.4g} mm, expected at most "
        f"{max_uploads}; {fits} (a shorter path, a larger tolerance, or several missions)",
        ("target",),
    )
