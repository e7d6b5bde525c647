"""Planning a writing route: solve, measure how faithfully it writes, stretch, re-segment.

:func:`plan_at` solves the route's smoothing problem
(:mod:`skyquill.calligraphy.problem`) at one timing and measures how
faithfully the plan writes; fitting the swung tip, the solve is polished
against the swing's second-order part. The time allocation
(:mod:`skyquill.calligraphy.allocation`) calls it for each timing it tries.
:func:`resegmented` then moves time between the samples (paper 000 §5.4) with
the total kept, if that keeps the plan faithful.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.fidelity import (
    Contact,
    Deviation,
    measure_deviation,
    planned_ink,
    swung_tip_of,
)
from skyquill.calligraphy.options import WritingOptions
from skyquill.calligraphy.problem import route_problem
from skyquill.calligraphy.route import RouteSamples
from skyquill.calligraphy.timing import writing_span
from skyquill.errors import InfeasibleError
from skyquill.optimize import SmoothingProblem, resegment, solve
from skyquill.optimize.solve import FitResult
from skyquill.trajectory import Trajectory
from skyquill.validation import FloatArray

#: One DEBUG record per solve of a route (a progress display listens: the studio).
logger = logging.getLogger(__name__)

#: Plans whose first-order tip is beyond this many tolerances are not polished.
POLISH_WITHIN = 1.2
#: Solves after the first that take the swung tip's second-order part off the
#: targets (``follow="tip"``): the part is ~1e-4 m horizontally and the tip's
#: rise (<= L amax^2 / 2 g^2) vertically, and each pass shrinks what is left by
#: about that ratio again, so two leave well under 0.1 mm.
TIP_POLISH_PASSES = 2
#: Samples per stroke of the deviation that decides whether to polish (against
#: :data:`POLISH_WITHIN` tolerances): a gate, not the plan's fidelity (that is
#: measured on the ink, :func:`fidelity`), so a quarter of the usual 400.
GATE_SAMPLES = 100
#: The re-segmentation ends at a step that lowers the jerk cost by less than this
#: fraction. Measured on 职 from a home: three steps take it from 250.7 to 213.4,
#: then the home leg's speed limit holds every step to ~1e-6 s and five more
#: steps (20 solves) gain 0.15 % together; 永, 中 and 绪 still gain 0.3-4 % a step.
RESEGMENT_FTOL = 1e-3


@dataclass(frozen=True)
class RoutePlan:
    """One spline along a route and how well it writes.

    Attributes
    ----------
    fit
        The engine's result.
    windows
        Pen-down ``(t_start, t_end)`` per stroke, s.
    deviation, contact
        Fidelity (:func:`fidelity`); ``contact`` is ``None`` unless the swung
        tip is fitted.
    scale
        Stretch of the initial timing.
    times
        Sample times, (N,), s.
    targets
        What the samples were fitted to, (N, 3), m: the route itself, or with
        the swung tip fitted, the route pressed into the board and polished
        against the swing's second-order part.
    """

    fit: FitResult
    windows: tuple[tuple[float, float], ...]
    deviation: Deviation
    scale: float
    times: FloatArray
    targets: FloatArray
    contact: Contact | None

    def faithful(self, opts: WritingOptions) -> bool:
        """Whether the pen-down path is within ``opts.tolerance`` (and the contact holds)."""
        held = self.contact is None or self.contact.holds
        return self.deviation.max_m <= opts.tolerance and held


def fidelity_error(plan: RoutePlan, opts: WritingOptions) -> InfeasibleError:
    """The error for a plan that stays unfaithful (beyond the tolerance, or out of contact)."""
    what = "the swung brush tip" if plan.contact is not None else "the pen-down path"
    if plan.deviation.max_m > opts.tolerance or plan.contact is None:
        problem = (
            f"{what} stays {1e3 * plan.deviation.max_m:.3g} mm from the input, expected "
            f"within the tolerance of {1e3 * opts.tolerance:.3g} mm (1 % of the size "
            "unless tolerance_m is given)"
        )
    else:
        c = plan.contact
        problem = (
            f"{what} leaves {c.ink_strokes} ink strokes for {c.strokes} strokes, pressed up "
            f"to {1e3 * c.max_depth_m:.3g} mm, expected one ink stroke per stroke within the "
            f"brush's travel of {1e3 * c.travel_m:.3g} mm"
        )
    return InfeasibleError(
        f"strokes: {problem}, after {opts.max_stretches} stretches ({plan.scale:.3g}x slower) "
        f"within {opts.limits.describe()}; a larger size, a lower speed limit (the route is "
        "timed by it) or best_effort",
        ("fidelity",),
    )


def resegmented(
    samples: RouteSamples, plan: RoutePlan, board: Board, opts: WritingOptions
) -> RoutePlan:
    """``plan`` after time re-segmentation (paper 000 §5.4), if that keeps it faithful.

    The targets stay those of ``plan`` (the polish's corrections are of second
    order in the swing and move little with the times); fidelity and contact
    are measured again, and ``plan`` is kept if the result is less faithful.
    """
    n_ctrl = plan.fit.trajectory.control_points.shape[0]
    gain = opts.tip_gain(board)

    def make(ts: FloatArray) -> SmoothingProblem:
        return route_problem(samples, plan.targets, ts, opts, gain=gain, n_ctrl=n_ctrl, board=board)

    penalty = 0.0
    if opts.resegment == "free":
        # Uniform scaling by k multiplies the jerk energy by k^-5: this rho
        # makes the current total time stationary, so the descent trades time
        # between segments and moves the total only where that pays.
        penalty = 5.0 * plan.fit.cost_terms["smoothness"] / float(plan.times[-1])
    logger.debug("re-segmenting the times (up to %d steps)", opts.resegment_iterations)
    try:
        result = resegment(
            samples.points,
            plan.times,
            make,
            mode="free" if opts.resegment == "free" else "fixed",
            time_penalty=penalty,
            max_iter=opts.resegment_iterations,
            initial_result=plan.fit,  # the plan just made at these times: not solved again
            workspace=samples.workspace,
            interior=True,  # each conic solve costs 10-50 closed forms
            ftol=RESEGMENT_FTOL,
            frozen=_legs_frozen(samples),
            step_rule="lbfgs",  # further down step for step than Barzilai-Borwein
        )
    except InfeasibleError:
        return plan
    new = _measured(
        samples, result.result, result.times, plan.targets, board=board, opts=opts, scale=plan.scale
    )
    if not new.faithful(opts) and plan.faithful(opts):
        return plan  # never trade fidelity for smoothness
    if new.deviation.max_m > max(opts.tolerance, plan.deviation.max_m):
        return plan
    return new


def _legs_frozen(samples: RouteSamples) -> NDArray[np.bool_]:
    """The route's segments on the legs from and to home (N - 1,): their timing stays."""
    first, last = writing_span(samples.roles, samples.legs)
    frozen = np.zeros(samples.points.shape[0] - 1, dtype=bool)
    frozen[:first] = frozen[last:] = True
    if samples.lead_in is not None:  # a continuing flight's braking keeps its timing
        frozen[: samples.lead_in.size - 1] = True
    return frozen


def plan_at(
    samples: RouteSamples, times: FloatArray, board: Board, opts: WritingOptions, scale: float
) -> RoutePlan:
    """Solve at ``times``; with the swung tip fitted, polish the targets against the swing."""
    gain = opts.tip_gain(board)
    if gain is None:
        problem = route_problem(samples, samples.points, times, opts, board=board)
        fit = solve(problem, workspace=samples.workspace)
        return _measured(samples, fit, times, samples.points, board=board, opts=opts, scale=scale)
    pressed = samples.points - _press(samples, board, opts)
    targets = pressed
    problem = route_problem(samples, targets, times, opts, gain=gain)
    fit = solve(problem, workspace=samples.workspace)
    windows = pen_windows(samples.roles, times, len(samples.strokes_world))
    first = measure_deviation(
        fit.trajectory,
        windows,
        samples.strokes_world,
        opts.brush.length_m,
        GATE_SAMPLES,
        plane=board,
    )
    # The polish moves the tip by the model's second-order part (~0.1 mm in the
    # plane): a plan this far off is stretched without it.
    if first.max_m <= POLISH_WITHIN * opts.tolerance:
        # Each pass takes what the first-order model misses (measured on the
        # last fit) off the pressed targets.
        n_ctrl = fit.trajectory.control_points.shape[0]
        for _ in range(TIP_POLISH_PASSES):
            targets = pressed - _model_error(fit.trajectory, times, gain, opts.brush.length_m)
            problem = route_problem(samples, targets, times, opts, gain=gain, n_ctrl=n_ctrl)
            fit = solve(problem, workspace=samples.workspace)
    return _measured(samples, fit, times, targets, board=board, opts=opts, scale=scale)


def _press(samples: RouteSamples, board: Board, opts: WritingOptions) -> FloatArray:
    """How far each target goes into the board (N, 3): the pressing depth on stroke samples."""
    depth = np.where(samples.roles >= 0, opts.brush.press_depth_m, 0.0)
    return np.asarray(depth[:, None] * board.normal)


def _model_error(traj: Trajectory, t: FloatArray, gain: FloatArray, length: float) -> FloatArray:
    """The swung tip minus its first-order model ``P + c a`` at times ``t`` (N, 3), m."""
    position, acceleration = traj.evaluate(t), traj.evaluate(t, 2)
    model = position + gain * acceleration
    return np.asarray(swung_tip_of(position, acceleration, length) - model)


def _measured(
    samples: RouteSamples,
    fit: FitResult,
    times: FloatArray,
    targets: FloatArray,
    *,
    board: Board,
    opts: WritingOptions,
    scale: float,
) -> RoutePlan:
    windows = pen_windows(samples.roles, times, len(samples.strokes_world))
    deviation, contact = fidelity(fit.trajectory, windows, samples.strokes_world, board, opts)
    return RoutePlan(fit, windows, deviation, scale, times, targets, contact)


def fidelity(
    traj: Trajectory,
    windows: tuple[tuple[float, float], ...],
    strokes_world: tuple[FloatArray, ...],
    board: Board,
    opts: WritingOptions,
) -> tuple[Deviation, Contact | None]:
    """How well ``traj`` (the untilted tip) writes the strokes.

    With the swung tip fitted (``opts.follows_tip``): the ink the plan leaves
    (:func:`planned_ink`) against the strokes, in the board's plane, and its
    :class:`Contact`. Otherwise the planned tip's 3-D distance over the pen
    windows, and no contact.
    """
    if not opts.follows_tip(board):
        return measure_deviation(traj, windows, strokes_world), None
    return planned_ink(traj, windows, strokes_world, board, brush=opts.brush, size_m=opts.size_m)


def pen_windows(roles: FloatArray, times: FloatArray, n: int) -> tuple[tuple[float, float], ...]:
    """``(t_start, t_end)`` of each of the ``n`` strokes: its first and last sample's time, s."""
    windows = []
    for i in range(n):
        where = np.flatnonzero(roles == i)
        windows.append((float(times[where[0]]), float(times[where[-1]])))
    return tuple(windows)
