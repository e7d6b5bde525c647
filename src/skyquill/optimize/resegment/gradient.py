"""The gradient of the optimal smoothing cost in the point times (envelope theorem).

At the optimum ``C*`` with multipliers ``Lambda`` (equalities, one column
per axis) and ``mu >= 0`` (inequalities), ``df/dtheta`` is the partial
derivative in ``theta`` of the Lagrangian
``J(C) + <Lambda, E C - e> + mu' (G x - h)`` at ``(C*, Lambda, mu)``
(``x = vec C``, rows in the engine's form). The times enter only through
``alpha = L / D`` with ``D = t_{N-1}`` and through ``s_i = alpha t_i``:

* smoothness ``sum_n sigma_n alpha^(2n-1) C' V_n C``:
  ``dJ/dalpha = sum_n (2n - 1) E_n / alpha``;
* point deviation ``w sum_i ||B(s_i) C - d_i||^2``:
  ``dJ/ds_i = 2 w r_i . B'(s_i) C`` (``r_i`` the residual, ``B'`` the
  ``s``-derivative row; ``alpha B'(s_i) C`` is the velocity), entering
  ``dt_i`` with factor ``alpha`` and ``dalpha`` with factor ``t_i``;
* interpolated points (rows ``B(s_i) C = d_i``): the same with ``Lambda_i``
  in place of ``2 w r_i``; a point the engine dropped because the boundary
  already fixes it (at ``s = 0`` or ``L``) has no row and stays at its ``s``;
* boundary rows, written in ``s`` by the engine (``Gamma_n C = v / alpha^n``):
  ``d/dalpha = n v alpha^(-n-1)`` -- zero for rest-to-rest conditions;
* derivative limits ``alpha^n (Hull (x) A) x <= b``: ``d/dalpha =
  (n / alpha) (G x)_r`` on each active row;
* exact norm limits, Clarabel's cones ``b_c - A_c x in SOC(d + 1)`` with
  ``A_c x = (0, v_p)``, ``v_p = alpha^n (Hull (x) I_d) x`` and ``b_c`` (the
  radius) fixed: the same, ``d/dalpha = (n / alpha) z_c' (A_c x)``, which is
  ``(n / alpha) z_0 r_p`` on an active cone;
* line, plane and corridor windows map to whole knot spans: piecewise
  constant in ``alpha``, derivative zero (almost everywhere).

Then ``df/dt_{N-1} += (df/dalpha) (-alpha / D)`` and ``df/dT_i =
sum_{j > i} df/dt_j`` (a reversed cumulative sum). One solve gives the whole
gradient where the paper's finite differences need one solve per segment.

The multipliers are the solve's own duals (:mod:`.multipliers`). For the
default rest-to-rest point fit without limits no multiplier is needed at all,
and the gradient costs a few sparse products.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from skyquill.optimize.assemble import AssemblyCache, _params, curves_at
from skyquill.optimize.problem import PointDeviation, SmoothingProblem
from skyquill.optimize.resegment.multipliers import Multipliers, multipliers
from skyquill.optimize.resegment.problems import ProblemFactory, check_problem, zero_based
from skyquill.optimize.resegment.results import TimeGradient
from skyquill.optimize.solve import FitResult, solve
from skyquill.optimize.workspace import Workspace
from skyquill.solvers import DEFAULT_BACKEND
from skyquill.validation import FloatArray

#: Rows whose multiplier exceeds this fraction of the largest count as active.
_ACTIVE_DUAL_RTOL = 1e-6


def time_gradient(
    times: FloatArray,
    make_problem: ProblemFactory,
    solver: str = DEFAULT_BACKEND,
    result: FitResult | None = None,
    *,
    workspace: Workspace | None = None,
) -> TimeGradient:
    """Optimal cost ``f`` at ``times`` and its analytic gradient (module docstring).

    Parameters
    ----------
    times
        Point times, shape (N,), s, ``times[0] = 0``, strictly increasing.
    make_problem
        ``times -> SmoothingProblem`` under the contract of :mod:`.problems`.
    solver
        QP backend for problems with inequalities.
    result
        A solve of ``make_problem(times)`` to reuse (skips the solve).
    workspace
        Shared with the solves of a sequence (:mod:`skyquill.optimize.workspace`):
        the solve (when ``result`` is None) and the multipliers re-use its
        assembly blocks and PIQP setup.

    Returns
    -------
    TimeGradient
    """
    t = zero_based("times", times)
    if result is None:
        problem = make_problem(t)
        check_problem(problem, t, None)
        result = solve(problem, solver, workspace=workspace)
    mult = multipliers(result, workspace) if _needs_multipliers(result) else None
    cache = workspace.assembly if workspace is not None else None
    grad_t = _lagrangian_gradient(result.problem, result.trajectory.control_points, mult, t, cache)
    grad_T = np.cumsum(grad_t[::-1])[::-1][1:].copy()
    if mult is None:
        return TimeGradient(result.cost, grad_t, grad_T, result, 0, 0.0, result.cost)
    n_active = _n_active(mult.mu)
    # Cone blocks (z_0, z_1..z_d): z_0 >= ||z_1..z_d||, positive when the cone is active.
    n_cones = _n_active(mult.cone_z[:: result.problem.dim + 1])
    return TimeGradient(
        result.cost, grad_t, grad_T, result, n_active, mult.residual, mult.cost, n_cones
    )


def _n_active(duals: FloatArray) -> int:
    """Number of multipliers above ``_ACTIVE_DUAL_RTOL`` of the largest."""
    return int(np.count_nonzero(duals > _ACTIVE_DUAL_RTOL * duals.max(initial=0.0)))


def _needs_multipliers(result: FitResult) -> bool:
    """Whether any row with a multiplier moves with the times."""
    problem = result.problem
    moving_boundary = any(
        bc.order > 0 and any(v is not None and bool(np.any(v)) for v in (bc.start, bc.end))
        for bc in problem.boundary
    )
    return moving_boundary or bool(problem.interpolation) or result.method == "qp"


def _positions(term_times: FloatArray, t: FloatArray) -> NDArray[np.intp] | None:
    """Indices of ``term_times`` in ``t`` when every one is one of the moving times, else None.

    A term may use a subset of the times (a writing mission weights stroke
    samples, corners and transits differently); its points move with theirs.
    """
    tol = 1e-12 * max(1.0, float(t[-1]))
    # searchsorted's indices are >= 0: only the top needs the bound (np.clip costs ~4x more).
    idx = np.minimum(np.searchsorted(t, term_times - tol), t.size - 1)
    if term_times.size and bool(np.all(np.abs(t[idx] - term_times) <= tol)):
        return idx
    return None


def _lagrangian_gradient(
    problem: SmoothingProblem,
    C: FloatArray,
    mult: Multipliers | None,
    t: FloatArray,
    cache: AssemblyCache | None = None,
) -> FloatArray:
    """``df/dt`` (N,) by the envelope theorem (module docstring); ``cache``: design matrices."""
    basis, alpha = problem.basis, problem.alpha
    if mult is not None:
        C = mult.C
    grad_t = np.zeros(t.size)
    g_alpha = 0.0

    def at_times(term_times: FloatArray, g_s: FloatArray) -> None:
        # g_s = dL/ds_i for the points at term_times; s_i = alpha * t_i.
        nonlocal g_alpha
        g_alpha += float(term_times @ g_s)
        idx = _positions(term_times, t)
        if idx is None:
            return
        if idx.size < 2 or bool(np.all(idx[1:] > idx[:-1])):
            grad_t[idx] += alpha * g_s  # increasing, so distinct: the same sums as np.add.at
        else:
            np.add.at(grad_t, idx, alpha * g_s)

    if mult is not None:
        # Not "g_alpha += ...": at_times adds to g_alpha during the call.
        boundary = _equality_terms(problem, C, mult.lam, at_times)
        g_alpha += boundary
        # Limit rows alpha^n (Hull (x) A) x - b: d/dalpha = (n / alpha) (G x).
        g_alpha += float(np.sum(mult.mu * mult.order * mult.Gx)) / alpha
        # Cone rows (0, alpha^n (Hull (x) I_d) x): the same, with the cone duals.
        g_alpha += float(np.sum(mult.cone_z * mult.cone_order * mult.cone_values)) / alpha
    for order, sigma in problem.smoothness.items():
        if sigma:
            D = basis.derivative_map(order) @ C
            energy = float(np.sum(D * (basis.reduced_gram(order) @ D)))
            g_alpha += (2 * order - 1) * sigma * alpha ** (2 * order - 2) * energy
    for term in problem.deviations:
        if isinstance(term, PointDeviation) and term.weight:
            # Two steps, not "g_alpha += ...": at_times adds to g_alpha during the call.
            explicit = _point_terms(problem, term, C, at_times, cache)
            g_alpha += explicit
    grad_t[-1] += g_alpha * (-alpha / problem.duration)
    return grad_t


def _point_terms(
    problem: SmoothingProblem,
    term: PointDeviation,
    C: FloatArray,
    at_times: Callable[[FloatArray, FloatArray], None],
    cache: AssemblyCache | None,
) -> float:
    """A point deviation's ``dJ/ds_i`` (through ``at_times``) and its own ``d/dalpha``.

    The residual ``r_i = B(s_i) C + c alpha^2 B_2(s_i) C - d_i`` (``B_n`` the
    ``n``-th ``s``-derivative rows) moves with ``s_i`` as
    ``B_1(s_i) C + c alpha^2 B_3(s_i) C`` and, with a gain ``c``, with
    ``alpha`` itself as ``2 c alpha B_2(s_i) C``.
    """
    alpha = problem.alpha
    if term.accel_gain is None:
        position, v = curves_at(problem, term.times, C, 2, cache)
        r = position - term.points
        g_alpha = 0.0
    else:
        gain = term.accel_gain
        position, v, acc_s, jerk_s = curves_at(problem, term.times, C, 4, cache)
        r = position + alpha**2 * gain * acc_s - term.points
        v = v + alpha**2 * gain * jerk_s
        g_alpha = 2.0 * term.weight * float(np.sum(r * (2.0 * alpha * gain * acc_s)))
    at_times(term.times, 2.0 * term.weight * np.sum(r * v, axis=1))
    return g_alpha


def _equality_terms(
    problem: SmoothingProblem,
    C: FloatArray,
    lam: FloatArray,
    at_times: Callable[[FloatArray, FloatArray], None],
) -> float:
    """``d/dalpha`` of the boundary rows; interpolated points go through ``at_times``.

    ``lam`` follows the engine's rows (:func:`skyquill.optimize.assemble.assemble`):
    each boundary value, start before end, then each interpolation term's
    points except those at an end whose position the boundary already fixes.
    """
    alpha = problem.alpha
    g_alpha = 0.0
    fixed_ends: list[float] = []
    i = 0
    for bc in problem.boundary:
        for value, s_end in ((bc.start, 0.0), (bc.end, float(problem.basis.n_spans))):
            if value is not None:
                # Row Gamma_n C - value / alpha^n: d/dalpha = n value alpha^(-n-1).
                g_alpha += bc.order * alpha ** (-bc.order - 1) * float(lam[i] @ value)
                i += 1
                if bc.order == 0:
                    fixed_ends.append(s_end)
    for interp in problem.interpolation:
        s = _params(problem, interp.times)
        kept = ~np.isin(s, fixed_ends)
        v = problem.basis.design_matrix(s[kept], 1) @ C
        n_kept = int(np.count_nonzero(kept))
        at_times(interp.times[kept], np.sum(lam[i : i + n_kept] * v, axis=1))
        i += n_kept
    return g_alpha
