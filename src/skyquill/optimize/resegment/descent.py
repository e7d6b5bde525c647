"""Re-segmentation by gradient descent (paper 000 §5.4, eqs. 55-56).

The data points ``d_i`` are reached at times ``t_i``; the segment durations
``T_i = t_{i+1} - t_i`` (``N - 1`` of them, ``t_0 = 0``) are the variables and

    min_T  F(T) = f(T) + rho * sum(T)   s.t.  T_i > 0                      (55)

where ``f(T)`` is the optimal cost of the smoothing problem built for those
times by the caller's ``make_problem(times)`` (:mod:`.problems`). ``F`` is
minimised by gradient descent (gradient: :mod:`.gradient`) with a
backtracking (Armijo) line search (first trial step by Barzilai-Borwein), in
two modes:

* ``"fixed"``: the total time ``D = sum(T)`` is kept. The paper perturbs
  along ``g_i`` with "1 at ``i`` and ``-1/N - 2`` elsewhere"; that is a
  typesetting slip for ``-1/(N - 2)``: with ``N - 1`` segment variables the
  other ``N - 2`` entries then sum to ``-1`` and ``sum(g_i) = 0``. The
  directional derivatives along these ``g_i`` are
  ``grad.g_i = (N-1)/(N-2) * (P grad)_i`` with the orthogonal projection
  ``P = I - 1 1' / (N - 1)`` onto ``{sum(dT) = 0}``: the paper's vector is
  the projected gradient up to a positive factor, which the line search
  absorbs. Here ``P grad`` is used, and the total time is re-imposed exactly
  after every step (``T <- T * D / sum(T)``).
* ``"free"``: the total time moves too, and a price on it is required. For a
  time-scaled path ``p(t) = q(t / D)`` with ``n_ctrl`` fixed, the parameters
  ``s_i = alpha t_i = L t_i / D`` do not change, so the deviation term is
  scale-invariant while ``∫ ||p^(n)||^2 dt = D^-(2n-1) ∫ ||q^(n)||^2 du``
  (``D^-5`` for jerk). Hence ``f(kappa T) <= kappa^-5 E_jerk + E_dev`` falls
  for ever as ``kappa`` grows, and without a price descent drifts to
  ever longer times. With ``rho * D`` (``rho`` = ``time_penalty``, cost per
  second) the scaling direction has the finite optimum
  ``rho D = sum_n (2n - 1) E_n`` (envelope theorem, no limit active),
  i.e. ``kappa^6 = 5 E_jerk / (rho D)`` for jerk alone. A linear price is
  chosen over e.g. ``rho D^2`` because ``rho`` then reads as "cost units one
  second is worth", and the stationarity condition above stays one line.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import InfeasibleError, InputError
from skyquill.optimize.resegment.gradient import time_gradient
from skyquill.optimize.resegment.problems import (
    ProblemFactory,
    check_initial,
    check_problem,
    point_fit_factory,
    times_from_segments,
    zero_based,
)
from skyquill.optimize.resegment.results import Mode, ResegmentResult, Status
from skyquill.optimize.solve import FitResult, solve, solve_inside
from skyquill.optimize.workspace import Workspace
from skyquill.solvers import DEFAULT_BACKEND
from skyquill.validation import FloatArray, as_array, as_float, as_int

_ARMIJO = 1e-4
_MAX_BACKTRACKS = 40
#: Step and gradient-change pairs the ``"lbfgs"`` rule keeps.
LBFGS_MEMORY = 6


@dataclass
class _Search:
    """Mutable state of one :func:`resegment` run: solve counts and timings."""

    make_problem: ProblemFactory
    mode: Mode
    rho: float
    solver: str
    total: float
    n_ctrl: int
    interior: bool = False
    n_solves: int = 0
    #: Trial points of the last line search rejected as infeasible (or, ``interior``,
    #: where a limit would bind).
    rejected: int = 0
    #: Segments whose durations stay as given (``None``: all move).
    frozen: NDArray[np.bool_] | None = None
    grad_time: float = 0.0
    #: Every solve of the run shares it: the problems differ only in the times.
    workspace: Workspace = field(default_factory=Workspace)

    def evaluate(self, T: FloatArray) -> tuple[FloatArray, FitResult] | None:
        """Times and solve for segments ``T``; ``None`` if infeasible."""
        tt = times_from_segments(T)
        if self.mode == "fixed":
            tt[-1] = self.total  # exact; the cumulative sum is off by a few ulp
        problem = self.make_problem(tt)
        check_problem(problem, tt, self.n_ctrl)
        self.n_solves += 1
        if self.interior:  # a point where a limit would bind is rejected unsolved
            inside = solve_inside(problem, self.workspace)
            return None if inside is None else (tt, inside)
        try:
            return tt, solve(problem, self.solver, workspace=self.workspace)
        except InfeasibleError:
            return None

    def objective(self, t: FloatArray, res: FitResult) -> float:
        """``f + rho * total_time``."""
        return res.cost + self.rho * float(t[-1])

    def gradient(self, t: FloatArray, res: FitResult) -> FloatArray:
        """Gradient of the objective in ``T``, projected on ``sum(dT) = 0`` in fixed mode."""
        tic = time.perf_counter()
        g = time_gradient(
            t, self.make_problem, self.solver, res, workspace=self.workspace
        ).grad_segments
        self.grad_time += time.perf_counter() - tic
        return self.project(g + self.rho)

    def project(self, v: FloatArray) -> FloatArray:
        """``v`` with the frozen segments' entries 0 and, in fixed mode, the free ones
        summing to 0 (the subspace the descent moves in)."""
        if self.frozen is not None:
            v = np.where(self.frozen, 0.0, v)
            if self.mode == "fixed" and not self.frozen.all():
                free = ~self.frozen
                v[free] -= v[free].mean()
            return v
        return v - v.mean() if self.mode == "fixed" else v

    def line_search(
        self,
        T: FloatArray,
        F: float,
        g: FloatArray,
        trial: float,
        direction: FloatArray | None = None,
    ) -> tuple[FloatArray, FloatArray, FitResult, float, float] | None:
        """Backtracking (Armijo) along ``direction`` (default ``-g``) from the step ``trial``
        (0: a first guess).

        No segment may shrink by more than half in one step, which keeps
        ``T > 0``. Infeasible trial points are rejected like costlier ones
        (and counted in :attr:`rejected`, which the next first trial heeds).
        Returns ``(T, t, result, F, step)`` or ``None`` when no decrease is found.
        """
        self.rejected = 0
        if direction is None:
            direction = -g
        shrinking = direction < 0
        cap = math.inf
        if shrinking.any():
            cap = 0.5 * float(np.min(T[shrinking] / -direction[shrinking]))
        if not trial > 0.0:
            trial = 0.1 * float(T.mean()) / float(np.abs(direction).max())
        trial = min(cap, trial)
        slope = float(g @ direction)
        for _ in range(_MAX_BACKTRACKS):
            T_new = T + trial * direction
            if self.mode == "fixed":
                T_new = T_new * (self.total / T_new.sum())
            out = self.evaluate(T_new)
            self.rejected += out is None
            if out is not None:
                F_new = self.objective(*out)
                if F_new <= F + _ARMIJO * trial * slope:
                    return T_new, out[0], out[1], F_new, trial
            trial *= 0.5
        return None


@dataclass
class _Steps:
    """The direction and first trial step of each line search (``step_rule``)."""

    rule: str
    #: The next line search's first trial step (0: :meth:`_Search.line_search` guesses).
    trial: float = 0.0
    #: ``"lbfgs"``: the last steps ``s`` and gradient changes ``y`` with ``s'y > 0``.
    pairs: list[tuple[FloatArray, FloatArray]] = field(default_factory=list)

    def direction(self, search: _Search, g: FloatArray) -> FloatArray | None:
        """The search direction at gradient ``g`` (``None``: along ``-g``)."""
        if self.rule != "lbfgs" or not self.pairs:
            return None
        direction = search.project(-_two_loop(g, self.pairs))
        if not float(g @ direction) < 0.0:  # not a descent direction: the gradient's,
            self.pairs, self.trial = [], 0.0  # from a fresh first guess (another scale)
            return None
        self.trial = 1.0  # the quasi-Newton step
        return direction

    def update(self, s_k: FloatArray, y_k: FloatArray, step: float, rejected: int) -> None:
        """After a step ``s_k`` (the line search's ``step`` along its direction) that
        changed the gradient by ``y_k``, with ``rejected`` trial points on the way."""
        self.trial = 2.0 * step
        curvature = float(s_k @ y_k)
        if self.rule == "lbfgs":
            if curvature > 1e-12 * float(np.linalg.norm(s_k) * np.linalg.norm(y_k)):
                self.pairs = [*self.pairs, (s_k, y_k)][-LBFGS_MEMORY:]
        elif self.rule == "bb":
            if curvature > 0.0:
                self.trial = float(s_k @ s_k) / curvature
            if rejected:
                # Where the feasible (or limit-free) region, not the curvature, held
                # the step, Barzilai-Borwein overshoots it again: 5-11 rejected solves
                # per step on a writing route (职). Twice the step that was taken.
                self.trial = min(self.trial, 2.0 * step)


def _start(search: _Search, t: FloatArray, initial: FitResult | None) -> tuple[_Search, FitResult]:
    """``search`` with its control-point count, and the solve at the initial times ``t``.

    The caller's solve ``initial`` is taken when given (its problem checked
    against ``t``); else ``make_problem(t)`` is solved.
    """
    if initial is not None:
        check_initial(initial.problem, t)
        search.n_ctrl = initial.problem.n_ctrl
        return search, initial
    first = search.make_problem(t)
    check_problem(first, t, None)
    search.n_ctrl, search.n_solves = first.n_ctrl, 1
    return search, solve(first, search.solver, workspace=search.workspace)


def _frozen(frozen: NDArray[np.bool_] | None, n: int) -> NDArray[np.bool_] | None:
    """The validated mask of segments that keep their durations (``None``: none, or all)."""
    if frozen is None:
        return None
    mask = np.asarray(frozen, dtype=bool)
    if mask.shape != (n,):
        raise InputError(
            f"frozen: got shape {mask.shape}, expected ({n},): one flag per segment "
            "between consecutive points"
        )
    return mask if mask.any() else None


def _initial_times(times: FloatArray, n: int) -> FloatArray:
    """Validated times (n,), shifted to start at 0."""
    t = as_array("times", times, shape=(n,))
    return zero_based("times", t - t[0])


def resegment(
    points: FloatArray,
    times: FloatArray,
    make_problem: ProblemFactory | None = None,
    *,
    mode: Mode = "fixed",
    time_penalty: float = 0.0,
    max_iter: int = 100,
    tol: float = 1e-6,
    ftol: float = 1e-10,
    step_rule: Literal["bb", "double", "lbfgs"] = "bb",
    solver: str = DEFAULT_BACKEND,
    initial_result: FitResult | None = None,
    workspace: Workspace | None = None,
    interior: bool = False,
    frozen: NDArray[np.bool_] | None = None,
    final_gradient: bool = True,
) -> ResegmentResult:
    """Re-segment the point times by gradient descent (paper 000 §5.4).

    Parameters
    ----------
    points
        Shape (N, d), m; only their count is used when ``make_problem`` is
        given, else :func:`point_fit_factory` builds the problem from them
        (degree 5, ``N + 5`` control points, weight 1e4, rest to rest).
    times
        Initial times, shape (N,), s, strictly increasing (shifted to start
        at 0).
    make_problem
        ``times -> SmoothingProblem`` (contract in :mod:`.problems`:
        ``duration == times[-1]``, fixed ``n_ctrl``).
    mode
        ``"fixed"``: keep the total time; ``"free"``: let it move, priced by
        ``time_penalty``.
    time_penalty
        ``rho >= 0`` in ``f + rho * total_time`` (cost per second). In free
        mode with ``rho = 0`` the cost falls for ever as time grows (module
        docstring) and the run ends at ``max_iter``.
    max_iter
        Largest number of accepted descent steps.
    tol
        Converged when ``max_i |T_i (P grad F)_i| <= tol * |F|``: no relative
        change of one segment can change the objective by more than ``tol``
        relative, to first order.
    ftol
        Also converged when one step lowers ``F`` by less than ``ftol * |F|``.
    step_rule
        First trial step of each line search: ``"bb"`` (Barzilai-Borwein,
        ``s's / s'y`` from the last step ``s`` and gradient change ``y``; twice
        the last step when ``s'y <= 0``) or ``"double"`` (twice the last
        accepted step). Either way the direction is the (projected) negative
        gradient and Armijo backtracking makes every accepted step decrease
        ``F``; Barzilai-Borwein only picks a better-scaled first trial
        (2-4x fewer iterations on the spiral, ``bench/resegment.py``).
        ``"lbfgs"``: the direction itself is the limited-memory BFGS one
        (:data:`LBFGS_MEMORY` pairs, Nocedal & Wright Alg. 7.4) projected onto
        the moving subspace, first trial the full quasi-Newton step; the
        gradient's where no pair with ``s'y > 0`` is kept yet or the direction
        does not descend. Step for step it goes further down than ``"bb"``
        (a writing route's eight steps: ~3 % lower cost, fewer rejected trials).
    solver
        QP backend for problems with inequalities.
    initial_result
        The caller's solve of ``make_problem(times)``, if it has one: used
        as the first iterate instead of solving the same problem again. Its
        problem must be made for ``times`` (checked: duration, control points,
        point-deviation times).
    workspace
        Shared by every solve and gradient of the run
        (:class:`~skyquill.optimize.workspace.Workspace`); a fresh one if
        ``None``. A caller that solved the first problem with a workspace
        passes it on, so that the run starts from its assembly and PIQP setup.
    interior
        Stay where no limit binds: when nothing binds at the initial times,
        a trial whose optimum would touch a limit, a corridor or a cone is
        rejected like an infeasible one (the step shrinks) without its conic
        solve (:func:`~skyquill.optimize.solve.solve_inside`), so every solve
        of the run is the closed form. The descent may stop earlier than it
        would across the limits; a writing plan re-segmented from the home
        (its long legs at the speed limit) spent 80 % of its time there.
    frozen
        Segments (N - 1,) whose durations stay as given: the descent moves time
        among the others only (in fixed mode their total is kept). A writing
        plan freezes its legs from and to home, timed near the speed limit:
        steps that shortened them were rejected at the limit, two in five.
    final_gradient
        ``False``: a run that ends on ``max_iter`` or on the ``ftol`` test does not
        compute the gradient at its last point, which nothing but the report
        uses (one gradient of the six to eight a writing plan's run computes):
        ``gradient_norm`` is then ``nan``, and a run that reaches ``max_iter``
        reports ``"max_iter"`` without the ``tol`` test at its last point. The
        times and the solve returned are the same either way.

    Returns
    -------
    ResegmentResult

    Raises
    ------
    InputError
        Bad arguments, or ``make_problem`` breaks its contract.
    InfeasibleError
        The problem at the initial times is infeasible (infeasible trial steps
        during the search are only rejected).
    """
    start = time.perf_counter()
    pts = as_array("points", points, ndim=2)
    t0 = t = _initial_times(times, pts.shape[0])
    if mode not in ("fixed", "free"):
        raise InputError(f"mode: got {mode!r}, expected 'fixed' or 'free'")
    if step_rule not in ("bb", "double", "lbfgs"):
        raise InputError(f"step_rule: got {step_rule!r}, expected 'bb', 'double' or 'lbfgs'")
    rho = as_float("time_penalty", time_penalty, nonneg=True)
    as_int("max_iter", max_iter, low=0)
    as_float("tol", tol, nonneg=True)
    as_float("ftol", ftol, nonneg=True)
    if make_problem is None:
        make_problem = point_fit_factory(pts, pts.shape[0] + 5)
    search, res = _start(
        _Search(
            make_problem,
            mode,
            rho,
            solver,
            float(t[-1]),
            0,
            workspace=workspace if workspace is not None else Workspace(),
        ),
        t,
        initial_result,
    )
    search.interior = interior and res.method == "closed_form"
    search.frozen = _frozen(frozen, pts.shape[0] - 1)
    T = np.diff(t)
    F = search.objective(t, res)
    g = search.gradient(t, res)
    history, durations = [F], [float(t[-1])]
    status: Status = "max_iter"
    steps = _Steps(step_rule)
    while True:
        if float(np.max(np.abs(T * g), initial=0.0)) <= tol * abs(F):
            status = "converged"
            break
        if len(history) > max_iter:
            break
        direction = steps.direction(search, g)
        found = search.line_search(T, F, g, steps.trial, direction)
        if found is None:
            status = "stalled"
            break
        T_old, g_old = T, g
        T, t, res, F_new, step = found
        decrease, F = F - F_new, F_new
        history.append(F)
        durations.append(float(t[-1]))
        last = decrease <= ftol * abs(F) or len(history) > max_iter
        if last and not final_gradient:  # the gradient here would only be reported
            g = np.full_like(g, np.nan)
            status = "converged" if decrease <= ftol * abs(F) else "max_iter"
            break
        g = search.gradient(t, res)
        steps.update(T - T_old, g - g_old, step, search.rejected)
        if decrease <= ftol * abs(F):
            status = "converged"
            break
    return ResegmentResult(
        times=t,
        result=res,
        mode=mode,
        time_penalty=rho,
        history=np.array(history),
        total_time_history=np.array(durations),
        iterations=len(history) - 1,
        status=status,
        gradient_norm=float(np.linalg.norm(g)),
        n_solves=search.n_solves,
        elapsed_s=time.perf_counter() - start,
        gradient_time_s=search.grad_time,
        initial_times=t0,
    )


def _two_loop(g: FloatArray, pairs: list[tuple[FloatArray, FloatArray]]) -> FloatArray:
    """The L-BFGS inverse-Hessian estimate times ``g`` (Nocedal & Wright, Algorithm 7.4),
    from the step and gradient-change ``pairs`` (oldest first, each with ``s'y > 0``),
    the initial matrix ``s'y / y'y`` of the newest pair."""
    q = g.copy()
    alphas = []
    for s_k, y_k in reversed(pairs):
        a = float(s_k @ q) / float(s_k @ y_k)
        alphas.append(a)
        q -= a * y_k
    s_n, y_n = pairs[-1]
    r = q * (float(s_n @ y_n) / float(y_n @ y_n))
    for (s_k, y_k), a in zip(pairs, reversed(alphas), strict=True):
        b = float(y_k @ r) / float(s_k @ y_k)
        r += (a - b) * s_k
    return r
