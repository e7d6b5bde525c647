"""Optimal time segmentation (paper 000 §5.4, eqs. 55-56) with an analytic gradient.

The data points ``d_i`` are reached at times ``t_i``; the segment durations
``T_i = t_{i+1} - t_i`` (``N - 1`` of them, ``t_0 = 0``) are the variables and

    min_T  F(T) = f(T) + rho * sum(T)   s.t.  T_i > 0                      (55)

where ``f(T)`` is the optimal cost of the smoothing problem built for those
times by the caller's ``make_problem(times)`` (minimum jerk + deviation, with
limits: paper 000 eqs. 44, 53-54). ``F`` is minimised by gradient descent with
a backtracking (Armijo) line search (first trial step by Barzilai-Borwein),
in two modes:

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

Analytic gradient (envelope theorem)
-------------------------------------
At the optimum ``C*`` with multipliers ``Lambda`` (equalities, one column
per axis) and ``mu >= 0`` (active inequalities), ``df/dtheta`` is the
partial derivative in ``theta`` of the Lagrangian
``J(C) + <Lambda, E C - e> + mu' (G x - h)`` at ``(C*, Lambda, mu)``
(``x = vec C``, rows in the engine's form). The times enter only
through ``alpha = L / D`` with ``D = t_{N-1}`` and through ``s_i = alpha t_i``:

* smoothness ``sum_n sigma_n alpha^(2n-1) C' V_n C``:
  ``dJ/dalpha = sum_n (2n - 1) E_n / alpha``;
* point deviation ``w sum_i ||B(s_i) C - d_i||^2``:
  ``dJ/ds_i = 2 w r_i . B'(s_i) C`` (``r_i`` the residual, ``B'`` the
  ``s``-derivative row; ``alpha B'(s_i) C`` is the velocity), entering
  ``dt_i`` with factor ``alpha`` and ``dalpha`` with factor ``t_i``;
* interpolated points (rows ``B(s_i) C = d_i``): the same with ``Lambda_i``
  in place of ``2 w r_i``;
* boundary rows, written in ``s`` by the engine (``Gamma_n C = v / alpha^n``):
  ``d/dalpha = n v alpha^(-n-1)`` -- zero for rest-to-rest conditions;
* derivative limits ``alpha^n (Hull (x) A) x <= b``: ``d/dalpha =
  (n / alpha) (G x)_r`` on each active row;
* line, plane and corridor windows map to whole knot spans: piecewise
  constant in ``alpha``, derivative zero (almost everywhere).

Then ``df/dt_{N-1} += (df/dalpha) (-alpha / D)`` and ``df/dT_i =
sum_{j > i} df/dt_j`` (a reversed cumulative sum). One solve gives the whole
gradient where the paper's finite differences need one solve per segment.

Multipliers. The engine returns no duals (its QP adapters drop them), so they
are recovered from the primal solution. On the closed-form route the primal
is exact and ``Lambda`` solves ``E' Lambda = -grad J(C*)`` by least squares.
On the QP route the inequality rows whose slack is within the solve's
tightening margin (``FitResult.margin``) plus 1e-7 relative form the active
set; the backend's point is then *polished*: the equality-constrained QP with
those rows held at their (tightened) bounds is solved exactly by one KKT
solve, because an interior-point solution is optimal only to the solver's
tolerance (stationarity residuals of 2e-4 relative, and an active row left
4e-5 inside its bound, were seen with PIQP at tolerance 1e-10), and the
gradient is first-order in that error where the cost is second-order. Rows
the polished point violates are added and rows with ``mu < 0`` dropped until
both hold (one pass in the usual case), then ``(Lambda, mu)`` solve the
stationarity condition ``E' Lambda + G_A' mu = -grad J`` by least squares.
This is exact when the active set is identified and its rows are
independent (LICQ); the residual is reported
(:attr:`TimeGradient.stationarity_residual`), and the gradient is the exact
derivative of :attr:`TimeGradient.polished_cost`. For the default
rest-to-rest point fit without limits no multiplier is needed at all, and the
gradient costs a few sparse products.

Contract on ``make_problem(times)``: ``duration == times[-1]`` (times start
at 0), ``n_ctrl`` the same for every call (so that ``f`` is smooth in ``T``),
and the times enter only through point-deviation / interpolation terms whose
``times`` equal the argument (other time-tagged terms are taken as fixed in
seconds) and through ``alpha``. Smoothness weights, point weights, boundary
values and limits must not depend on the times.
"""

from __future__ import annotations

import logging
import math
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray
from scipy.sparse.csgraph import structural_rank

from skyquill.errors import InfeasibleError, InputError
from skyquill.limits import DerivativeLimit
from skyquill.optimize.assemble import Assembled, _params, assemble, problem_cost
from skyquill.optimize.problem import (
    Boundary,
    PointDeviation,
    SmoothingProblem,
)
from skyquill.optimize.solve import FitResult, solve
from skyquill.solvers import DEFAULT_BACKEND
from skyquill.spline import HullKind
from skyquill.validation import FloatArray, as_array, as_float, as_int, strictly_increasing

log = logging.getLogger(__name__)

Mode = Literal["fixed", "free"]
Status = Literal["converged", "max_iter", "stalled"]
ProblemFactory = Callable[[FloatArray], SmoothingProblem]

_ARMIJO = 1e-4
_MAX_BACKTRACKS = 40
_ACTIVE_RTOL = 1e-7
_DENSE_LSTSQ = 4_000_000
_ACTIVE_SET_ITERATIONS = 30
_DENSE_KKT = 600


# --------------------------------------------------------------------- results
@dataclass(frozen=True)
class TimeGradient:
    """The smoothing cost and its gradient with respect to the point times.

    Attributes
    ----------
    cost
        ``f``: the engine's optimal cost (``FitResult.cost``), no time price.
    grad_times
        ``df/dt_j``, shape (N,), cost per second; entry 0 belongs to
        ``t_0 = 0``, which is not a variable.
    grad_segments
        ``df/dT_i``, shape (N - 1,).
    result
        The solve at these times.
    n_active
        Number of inequality rows treated as active.
    stationarity_residual
        Relative residual of the multiplier fit ``||E'Lambda + G_A'mu +
        grad J||`` against ``||2 G x||`` (0 when no multiplier was needed).
    polished_cost
        Cost at the polished control points (QP route: the exact minimiser on
        the identified active set, module docstring), of which the gradient is
        the exact derivative; equal to ``cost`` on the closed-form route. The
        QP backends' ``cost`` can lie above it by ~1e-8 relative.
    """

    cost: float
    grad_times: FloatArray
    grad_segments: FloatArray
    result: FitResult
    n_active: int
    stationarity_residual: float
    polished_cost: float


@dataclass(frozen=True)
class ResegmentResult:
    """Outcome of :func:`resegment`.

    Attributes
    ----------
    times
        Optimised point times, shape (N,), s, ``times[0] = 0``.
    result
        The engine's solve at ``times``.
    mode
        ``"fixed"`` or ``"free"``.
    time_penalty
        ``rho`` of the objective ``f + rho * total_time`` (cost per second).
    history
        Objective ``f + rho * total_time`` at every accepted iterate, the
        initial one first; non-increasing. Shape (iterations + 1,).
    total_time_history
        Total time at every accepted iterate, s.
    iterations
        Accepted descent steps.
    status
        ``"converged"`` (scaled gradient below ``tol`` or relative decrease
        below ``ftol``), ``"max_iter"``, or ``"stalled"`` (the line search
        found no decrease: the objective is flat to the solver's accuracy).
    gradient_norm
        2-norm of the (projected, in fixed mode) gradient in ``T`` at the end.
    n_solves
        Engine solves, line search included.
    elapsed_s
        Wall time of the whole run.
    gradient_time_s
        Wall time spent in the analytic gradients (solves excluded).
    initial_times
        The starting times (shifted to start at 0), shape (N,).
    """

    times: FloatArray
    result: FitResult
    mode: Mode
    time_penalty: float
    history: FloatArray
    total_time_history: FloatArray
    iterations: int
    status: Status
    gradient_norm: float
    n_solves: int
    elapsed_s: float
    gradient_time_s: float
    initial_times: FloatArray

    @property
    def cost(self) -> float:
        """Final smoothing cost ``f`` (without the time price)."""
        return self.result.cost

    @property
    def total_time(self) -> float:
        """Final total time, s."""
        return float(self.times[-1])


# ------------------------------------------------------------------- factories
def point_fit_factory(
    points: FloatArray,
    n_ctrl: int,
    *,
    degree: int = 5,
    weight: float = 1e4,
    rest_orders: int = 3,
    limits: Sequence[DerivativeLimit] = (),
    hull: HullKind = "bspline",
) -> ProblemFactory:
    """The paper's problem for given times: jerk cost, point deviation, rest boundary.

    Parameters
    ----------
    points
        Shape (N, d), m.
    n_ctrl
        Control points, fixed for every ``times`` (paper 000: ``M + 6``).
    degree
        Spline degree (3 in paper 000).
    weight
        Point-deviation weight against the jerk cost (paper 000's ``1 / w_g``).
    rest_orders
        Position and derivatives ``1 .. rest_orders - 1`` fixed at both ends
        (zero derivatives: at rest).
    limits
        Derivative limits (the QP of paper 000 §5.3).
    hull
        Hull kind for the limits.

    Returns
    -------
    Callable
        ``make_problem(times) -> SmoothingProblem`` with ``duration = times[-1]``.
    """
    pts = as_array("points", points, ndim=2)
    boundary = Boundary.rest(pts[0], pts[-1], rest_orders)
    lims = tuple(limits)

    def make_problem(times: FloatArray) -> SmoothingProblem:
        return SmoothingProblem(
            dim=pts.shape[1],
            degree=degree,
            n_ctrl=n_ctrl,
            duration=float(times[-1]),
            smoothness={3: 1.0},
            deviations=(PointDeviation(times, pts, weight),),
            boundary=boundary,
            limits=lims,
            hull=hull,
        )

    return make_problem


# -------------------------------------------------------------------- gradient
def _times_from_segments(T: FloatArray) -> FloatArray:
    return np.concatenate([[0.0], np.cumsum(T)])


def _zero_based(name: str, times: FloatArray) -> FloatArray:
    """Validated strictly increasing times (N >= 2) with ``times[0] == 0``."""
    t = as_array(name, times, ndim=1)
    if t.size < 2:
        raise InputError(f"{name}: got {t.size} time(s), expected at least 2")
    strictly_increasing(name, t)
    if t[0] != 0.0:
        raise InputError(f"{name}: got {name}[0] = {t[0]:g}, expected 0 (the first point's time)")
    return t


def _check_problem(problem: SmoothingProblem, t: FloatArray, n_ctrl: int | None) -> None:
    if not isinstance(problem, SmoothingProblem):
        raise InputError(
            f"make_problem: returned {type(problem).__name__}, expected a SmoothingProblem"
        )
    if abs(problem.duration - t[-1]) > 1e-12 * t[-1]:
        raise InputError(
            f"make_problem: got duration {problem.duration:.17g} s for times ending at "
            f"{t[-1]:.17g} s, expected duration == times[-1]"
        )
    if n_ctrl is not None and problem.n_ctrl != n_ctrl:
        raise InputError(
            f"make_problem: got n_ctrl = {problem.n_ctrl}, expected the same n_ctrl = {n_ctrl} "
            "for every call (f is only smooth in the times at a fixed knot count)"
        )


def _positions(term_times: FloatArray, t: FloatArray) -> NDArray[np.intp] | None:
    """Indices of ``term_times`` in ``t`` when every one is one of the moving times, else None.

    A term may use a subset of the times (a writing mission weights stroke
    samples, corners and transits differently); its points move with theirs.
    """
    tol = 1e-12 * max(1.0, float(t[-1]))
    idx = np.clip(np.searchsorted(t, term_times - tol), 0, t.size - 1)
    if term_times.size and bool(np.all(np.abs(t[idx] - term_times) <= tol)):
        return idx
    return None


def time_gradient(
    times: FloatArray,
    make_problem: ProblemFactory,
    solver: str = DEFAULT_BACKEND,
    result: FitResult | None = None,
) -> TimeGradient:
    """Optimal cost ``f`` at ``times`` and its analytic gradient (module docstring).

    Parameters
    ----------
    times
        Point times, shape (N,), s, ``times[0] = 0``, strictly increasing.
    make_problem
        ``times -> SmoothingProblem`` under the module's contract.
    solver
        QP backend for problems with inequalities.
    result
        A solve of ``make_problem(times)`` to reuse (skips the solve).

    Returns
    -------
    TimeGradient
    """
    t = _zero_based("times", times)
    if result is None:
        problem = make_problem(t)
        _check_problem(problem, t, None)
        result = solve(problem, solver)
    grad_t, n_active, residual, C = _lagrangian_gradient(result.problem, result, t)
    grad_T = np.cumsum(grad_t[::-1])[::-1][1:].copy()
    polished = result.cost
    if C is not result.trajectory.control_points:
        polished = problem_cost(result.problem, C)["total"]
    return TimeGradient(result.cost, grad_t, grad_T, result, n_active, residual, polished)


@dataclass(frozen=True)
class _Multipliers:
    """Multipliers recovered from the primal solution (module docstring)."""

    C: FloatArray  # (M, d) polished control points
    lam: FloatArray  # (m, d): equality rows of _equality_rows, one column per axis
    mu: FloatArray  # (a,) >= 0
    active: NDArray[np.intp]  # (a,) rows of G_ineq
    order: FloatArray  # (a,) derivative order of each active row (0: corridor)
    Gx: FloatArray  # (a,) G_ineq[active] @ x
    residual: float


def _lagrangian_gradient(
    problem: SmoothingProblem, result: FitResult, t: FloatArray
) -> tuple[FloatArray, int, float, FloatArray]:
    """``df/dt`` (N,) by the envelope theorem; the active count, fit residual, control points."""
    basis, alpha = problem.basis, problem.alpha
    C = result.trajectory.control_points
    grad_t = np.zeros(t.size)
    g_alpha = 0.0

    def at_times(term_times: FloatArray, g_s: FloatArray) -> None:
        # g_s = dL/ds_i for the points at term_times; s_i = alpha * t_i.
        nonlocal g_alpha
        g_alpha += float(term_times @ g_s)
        idx = _positions(term_times, t)
        if idx is not None:
            np.add.at(grad_t, idx, alpha * g_s)

    moving_boundary = any(
        bc.order > 0 and any(v is not None and bool(np.any(v)) for v in (bc.start, bc.end))
        for bc in problem.boundary
    )
    n_active, residual = 0, 0.0
    if moving_boundary or problem.interpolation or result.method == "qp":
        mult = _multipliers(problem, C, result.margin)
        C = mult.C
        n_active, residual = mult.active.size, mult.residual
        i = 0  # rows of _equality_rows: boundary first, then interpolated points
        for bc in problem.boundary:
            for value in (bc.start, bc.end):
                if value is not None:
                    # Row Gamma_n C - value / alpha^n: d/dalpha = n value alpha^(-n-1).
                    g_alpha += bc.order * alpha ** (-bc.order - 1) * float(mult.lam[i] @ value)
                    i += 1
        for interp in problem.interpolation:
            s = _params(problem, interp.times)
            v = basis.design_matrix(s, 1) @ C
            at_times(interp.times, np.sum(mult.lam[i : i + s.size] * v, axis=1))
            i += s.size
        # Limit rows alpha^n (Hull (x) A) x - b: d/dalpha = (n / alpha) (G x).
        g_alpha += float(np.sum(mult.mu * mult.order * mult.Gx)) / alpha

    for order, sigma in problem.smoothness.items():
        if sigma:
            D = basis.derivative_map(order) @ C
            energy = float(np.sum(D * (basis.reduced_gram(order) @ D)))
            g_alpha += (2 * order - 1) * sigma * alpha ** (2 * order - 2) * energy
    for term in problem.deviations:
        if isinstance(term, PointDeviation) and term.weight:
            s = _params(problem, term.times)
            r = basis.design_matrix(s) @ C - term.points
            v = basis.design_matrix(s, 1) @ C
            at_times(term.times, 2.0 * term.weight * np.sum(r * v, axis=1))
    grad_t[-1] += g_alpha * (-alpha / problem.duration)
    return grad_t, n_active, residual, C


def _equality_rows(problem: SmoothingProblem) -> sp.csr_array:
    """Every equality row (boundary, then each interpolated point), per axis, (m, M).

    Unlike the engine, rows duplicated by the boundary are kept: the least-squares
    multiplier fit splits their weight, and their time derivative is zero.
    """
    basis = problem.basis
    rows: list[sp.csr_array] = []
    for bc in problem.boundary:
        start_row, end_row = basis.end_rows(bc.order)
        for row, value in ((start_row, bc.start), (end_row, bc.end)):
            if value is not None:
                rows.append(sp.csr_array(row[None, :]))
    for interp in problem.interpolation:
        rows.append(basis.design_matrix(_params(problem, interp.times)))
    if not rows:
        return sp.csr_array((0, problem.n_ctrl))
    return sp.csr_array(sp.vstack(rows))


def _least_squares(K: sp.csc_array, b: FloatArray) -> FloatArray:
    """Minimum-norm least-squares solution of ``K y = b`` on unit-norm columns.

    The columns mix O(1) equality rows with ``alpha^n`` limit rows. Dense
    SVD (``gelsd``, rank-revealing) up to ``_DENSE_LSTSQ`` entries, else LSMR.
    """
    if K.shape[1] == 0:
        return np.zeros(0)
    col = np.sqrt(np.asarray((K.multiply(K)).sum(axis=0)).ravel())
    col[col == 0.0] = 1.0
    Ks = sp.csc_array(K @ sp.diags_array(1.0 / col))
    if K.shape[0] * K.shape[1] <= _DENSE_LSTSQ:
        y = scipy.linalg.lstsq(Ks.toarray(), b, lapack_driver="gelsd", check_finite=False)[0]
    else:
        y = spla.lsmr(Ks, b, atol=1e-15, btol=1e-15, maxiter=20 * K.shape[1])[0]
    out: FloatArray = np.asarray(y, dtype=float) / col
    return out


def _multipliers(problem: SmoothingProblem, C: FloatArray, margin: float) -> _Multipliers:
    """Multipliers (and polished control points) from the primal solution.

    1. Active set: inequality rows whose relative slack is within the solve's
       tightening ``margin`` plus ``_ACTIVE_RTOL``.
    2. Polish (QP route only): an interior-point solution is optimal only to
       the solver's tolerance (stationarity residuals of 2e-4 relative and
       active rows left 4e-5 inside their bound were seen), and the gradient
       is first-order in that error while the cost is second-order. So the
       equality-constrained QP with the active rows held at their tightened
       bounds is solved exactly (one sparse KKT solve).
    3. ``E' Lambda + G_A' mu = -grad J(C)`` by least squares.
    4. Rows the polished point violates are added, rows with ``mu < 0``
       dropped, and 2-3 repeated (a primal-dual active-set iteration started
       from the solver's active set; one pass in the usual case). If it does
       not settle, or the polished point strays from the solver's, the
       solver's point is used with the last active set.
    """
    asm = assemble(problem)
    d = C.shape[1]
    H, f = sp.csr_array(asm.hessian()), asm.linear()  # J = x'Hx + f'x + const
    E = sp.csr_array(sp.kron(_equality_rows(problem), sp.eye_array(d), format="csr"))
    G = asm.G_ineq
    orders = np.zeros(G.shape[0])
    for fam, lim in zip(asm.families, problem.limits, strict=False):  # limits come first
        orders[fam.rows] = lim.order
    scale = np.maximum(np.abs(asm.h_ineq), 1e-3)
    tightened = asm.h_ineq - margin * scale
    x0 = C.ravel()
    active = np.flatnonzero((asm.h_ineq - G @ x0) / scale <= margin + _ACTIVE_RTOL)
    m = E.shape[0]
    polish = _Polisher(asm, H, f, tightened) if G.shape[0] else None
    x: FloatArray | None = x0
    for _ in range(_ACTIVE_SET_ITERATIONS):
        x = polish(active) if polish is not None else x0
        if x is None:
            break
        violated = np.setdiff1d(np.flatnonzero((G @ x - tightened) / scale > 1e-12), active)
        if violated.size:
            active = np.union1d(active, violated)
            continue
        y = _least_squares(_stationarity_matrix(E, G, active), -(2.0 * (H @ x) + f))
        negative = y[m:] < -1e-9 * max(float(np.abs(y[m:]).max(initial=0.0)), 1e-300)
        if not np.any(negative):
            break
        active = active[~negative]
    else:
        x = None
    if x is None or float(np.linalg.norm(x - x0)) > 1e-3 * max(1.0, float(np.linalg.norm(x0))):
        log.debug("polish failed or strayed; using the solver's point")
        x = x0
    K = _stationarity_matrix(E, G, active)
    quad = 2.0 * (H @ x)
    y = _least_squares(K, -(quad + f))
    # grad J ~ 0 in the interior: measure the fit against its two parts.
    size = max(float(np.linalg.norm(quad)), float(np.linalg.norm(f)), 1e-300)
    residual = float(np.linalg.norm(K @ y + quad + f)) / size
    return _Multipliers(
        x.reshape(C.shape),
        y[:m].reshape(-1, d),
        np.maximum(y[m:], 0.0),
        active,
        orders[active],
        (G @ x)[active],
        residual,
    )


def _stationarity_matrix(
    E: sp.csr_array, G: sp.csr_array, active: NDArray[np.intp]
) -> sp.csc_array:
    """``[E', G_A']``, shape (Md, m + a)."""
    return sp.csc_array(sp.hstack([E.T, G[active.tolist(), :].T], format="csc"))


class _Polisher:
    """Minimiser with the equalities and given rows of ``G x <= h`` held at ``tightened``.

    Rows are scaled to unit norm and the cost by ``asm.cost_scale`` (as the
    closed form does); one LU of the KKT matrix (dense below
    ``_DENSE_KKT`` unknowns, where LAPACK beats building SuperLU's structures).
    """

    def __init__(
        self, asm: Assembled, H: sp.csr_array, f: FloatArray, tightened: FloatArray
    ) -> None:
        d = asm.F.shape[1]
        self.n = f.size
        self.H2 = sp.csr_array(2.0 * asm.cost_scale * H)
        self.q = -asm.cost_scale * f
        self.A_eq = sp.csr_array(sp.kron(asm.E, sp.eye_array(d), format="csr"))
        self.b_eq = asm.e.ravel()
        self.G = asm.G_ineq
        self.tightened = tightened

    def __call__(self, active: NDArray[np.intp]) -> FloatArray | None:
        """Polished ``x`` (n,), or ``None`` if the KKT matrix is singular (no LICQ)."""
        A = sp.csr_array(sp.vstack([self.A_eq, self.G[active.tolist(), :]], format="csr"))
        if A.shape[0] > self.n:
            return None  # more active rows than variables: LICQ fails for certain
        b = np.concatenate([self.b_eq, self.tightened[active]])
        norms = np.sqrt(np.asarray(A.multiply(A).sum(axis=1)).ravel())
        norms[norms == 0.0] = 1.0
        A = sp.csr_array(sp.diags_array(1.0 / norms) @ A)
        rhs = np.concatenate([self.q, b / norms])
        size = self.n + A.shape[0]
        try:
            if size <= _DENSE_KKT:
                K = np.zeros((size, size))
                K[: self.n, : self.n] = self.H2.toarray()
                K[self.n :, : self.n] = A.toarray()
                K[: self.n, self.n :] = K[self.n :, : self.n].T
                with warnings.catch_warnings():
                    warnings.simplefilter("error", scipy.linalg.LinAlgWarning)
                    sol = scipy.linalg.solve(K, rhs, check_finite=False, assume_a="sym")
            else:
                K_sp = sp.block_array([[self.H2, A.T], [A, None]], format="csc")
                # SuperLU (scipy 1.17) segfaults on some structurally singular
                # KKT matrices instead of raising (seen with a 0.01 m/s^3 jerk
                # limit: rank 6660 of 6704); a maximum matching finds them first.
                if structural_rank(K_sp) < size:
                    return None
                sol = spla.splu(K_sp).solve(rhs)
        except (RuntimeError, np.linalg.LinAlgError, scipy.linalg.LinAlgWarning):
            return None
        x = np.asarray(sol, dtype=float)[: self.n]
        return x if bool(np.all(np.isfinite(x))) else None


# ------------------------------------------------------------ finite differences
def finite_difference_gradient(
    times: FloatArray,
    make_problem: ProblemFactory,
    *,
    step: float = 1e-6,
    scheme: Literal["forward", "central"] = "central",
    mode: Mode = "free",
    solver: str = DEFAULT_BACKEND,
    polished: bool = False,
) -> FloatArray:
    """``df/dT`` by finite differences: paper 000 eq. (56), one solve per segment.

    Parameters
    ----------
    times
        Point times, shape (N,), s, starting at 0.
    make_problem
        ``times -> SmoothingProblem``.
    step
        Perturbation relative to the mean segment duration (the paper's ``h``
        is ~1e-6 absolute).
    scheme
        ``"forward"`` (the paper's, N solves) or ``"central"`` (2 (N - 1) solves).
    mode
        ``"free"``: perturb ``e_i``; ``"fixed"``: perturb the paper's
        ``g_i`` (1 at ``i``, ``-1/(N - 2)`` elsewhere), which returns
        ``(N-1)/(N-2)`` times the projected gradient.
    solver
        QP backend.
    polished
        Difference :attr:`TimeGradient.polished_cost` instead of the engine's
        cost (QP route: removes the backend's ~1e-8 relative suboptimality,
        which step ``h`` would amplify to ~1e-8 / h in the quotient).

    Returns
    -------
    numpy.ndarray, shape (N - 1,)
        Directional derivatives of ``f`` (no time price).
    """
    t = _zero_based("times", times)
    T = np.diff(t)
    n = T.size
    h = step * float(T.mean())

    def f(T_new: FloatArray) -> float:
        tt = _times_from_segments(T_new)
        if polished:
            return time_gradient(tt, make_problem, solver).polished_cost
        return solve(make_problem(tt), solver).cost

    base = f(T) if scheme == "forward" else 0.0
    out = np.empty(n)
    for i in range(n):
        if mode == "fixed":
            if n < 2:
                return np.zeros(n)
            g = np.full(n, -1.0 / (n - 1))
            g[i] = 1.0
        else:
            g = np.zeros(n)
            g[i] = 1.0
        if scheme == "forward":
            out[i] = (f(T + h * g) - base) / h
        else:
            out[i] = (f(T + h * g) - f(T - h * g)) / (2.0 * h)
    return out


# ---------------------------------------------------------------------- descent
@dataclass
class _Search:
    """Mutable state of one :func:`resegment` run: solve counts and timings."""

    make_problem: ProblemFactory
    mode: Mode
    rho: float
    solver: str
    total: float
    n_ctrl: int
    n_solves: int = 0
    grad_time: float = 0.0

    def evaluate(self, T: FloatArray) -> tuple[FloatArray, FitResult] | None:
        """Times and solve for segments ``T``; ``None`` if infeasible."""
        tt = _times_from_segments(T)
        if self.mode == "fixed":
            tt[-1] = self.total  # exact; the cumulative sum is off by a few ulp
        problem = self.make_problem(tt)
        _check_problem(problem, tt, self.n_ctrl)
        self.n_solves += 1
        try:
            return tt, solve(problem, self.solver)
        except InfeasibleError:
            return None

    def objective(self, t: FloatArray, res: FitResult) -> float:
        """``f + rho * total_time``."""
        return res.cost + self.rho * float(t[-1])

    def gradient(self, t: FloatArray, res: FitResult) -> FloatArray:
        """Gradient of the objective in ``T``, projected on ``sum(dT) = 0`` in fixed mode."""
        tic = time.perf_counter()
        g = time_gradient(t, self.make_problem, self.solver, res).grad_segments + self.rho
        self.grad_time += time.perf_counter() - tic
        return g - g.mean() if self.mode == "fixed" else g

    def line_search(
        self, T: FloatArray, F: float, g: FloatArray, trial: float
    ) -> tuple[FloatArray, FloatArray, FitResult, float, float] | None:
        """Backtracking (Armijo) along ``-g`` from the step ``trial`` (0: a first guess).

        No segment may shrink by more than half in one step, which keeps
        ``T > 0``. Infeasible trial points are rejected like costlier ones.
        Returns ``(T, t, result, F, step)`` or ``None`` when no decrease is found.
        """
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
            if out is not None:
                F_new = self.objective(*out)
                if F_new <= F + _ARMIJO * trial * slope:
                    return T_new, out[0], out[1], F_new, trial
            trial *= 0.5
        return None


def _initial_times(times: FloatArray, n: int) -> FloatArray:
    """Validated times (n,), shifted to start at 0."""
    t = as_array("times", times, shape=(n,))
    return _zero_based("times", t - t[0])


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
    step_rule: Literal["bb", "double"] = "bb",
    solver: str = DEFAULT_BACKEND,
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
        ``times -> SmoothingProblem`` (module docstring: ``duration ==
        times[-1]``, fixed ``n_ctrl``).
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
    solver
        QP backend for problems with inequalities.

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
    if step_rule not in ("bb", "double"):
        raise InputError(f"step_rule: got {step_rule!r}, expected 'bb' or 'double'")
    rho = as_float("time_penalty", time_penalty, nonneg=True)
    as_int("max_iter", max_iter, low=0)
    as_float("tol", tol, nonneg=True)
    as_float("ftol", ftol, nonneg=True)
    if make_problem is None:
        make_problem = point_fit_factory(pts, pts.shape[0] + 5)
    first = make_problem(t)
    _check_problem(first, t, None)
    search = _Search(make_problem, mode, rho, solver, float(t[-1]), first.n_ctrl, n_solves=1)
    res = solve(first, solver)
    T = np.diff(t)
    F = search.objective(t, res)
    g = search.gradient(t, res)
    history, durations = [F], [float(t[-1])]
    status: Status = "max_iter"
    trial = 0.0
    while True:
        if float(np.max(np.abs(T * g), initial=0.0)) <= tol * abs(F):
            status = "converged"
            break
        if len(history) > max_iter:
            break
        found = search.line_search(T, F, g, trial)
        if found is None:
            status = "stalled"
            break
        T_old, g_old = T, g
        T, t, res, F_new, step = found
        decrease, F = F - F_new, F_new
        history.append(F)
        durations.append(float(t[-1]))
        g = search.gradient(t, res)
        trial = 2.0 * step
        if step_rule == "bb":
            s_k, y_k = T - T_old, g - g_old
            curvature = float(s_k @ y_k)
            if curvature > 0.0:
                trial = float(s_k @ s_k) / curvature
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


__all__ = [
    "ProblemFactory",
    "ResegmentResult",
    "TimeGradient",
    "finite_difference_gradient",
    "point_fit_factory",
    "resegment",
    "time_gradient",
]
