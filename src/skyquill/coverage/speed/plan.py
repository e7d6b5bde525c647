"""``plan_speed``: the grid LP, the pseudo-jerk iteration and the refinement, end to end."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy import sparse

from skyquill.coverage.deadline import Deadline
from skyquill.coverage.speed.banded_grid import BandedGrid, banded_rows
from skyquill.coverage.speed.curve import PathCurve, _derivs3, _eval, _Reparam
from skyquill.coverage.speed.grid import _grid_map
from skyquill.coverage.speed.iteration import _initial_solve, _refine
from skyquill.coverage.speed.norms import component_limits, components
from skyquill.coverage.speed.profile import SpeedPlan, _duration, _profile_spline
from skyquill.coverage.speed.reach import ReachGrid, acceleration_rows
from skyquill.coverage.speed.rows import (
    GridSolver,
    _acc_matrix,
    _Bounds,
    _GridLP,
    _jerk_matrix,
    _ones,
    _speed_bounds,
)
from skyquill.coverage.speed.validate import (
    _validate,
    _validate_limits,
    _validate_method,
    _validate_norm_sides,
    _validate_refine,
)
from skyquill.errors import InputError


def plan_speed(
    curve: PathCurve | Callable[..., Any],
    vmax: float,
    amax: float | npt.ArrayLike,
    jmax: float | npt.ArrayLike | None = None,
    *,
    n: int = 500,
    chord_error: float | None = None,
    control_period: float = 0.02,
    jerk_iterations: int = 20,
    jerk_tol: float = 1e-3,
    safety: float = 1.0,
    max_excess: float | None = 0.02,
    refine_rounds: int = 8,
    lp_backend: str = "auto",
    grid: str = "uniform",
    norm_sides: int | None = None,
    deadline: Deadline | None = None,
    method: str = "auto",
) -> SpeedPlan:
    """Plan the time-optimal rest-to-rest speed profile along ``curve``.

    Parameters
    ----------
    curve : callable
        ``curve(u, nu=k)`` returns the ``k``-th derivative at the array ``u``
        (shape ``(len(u), d)``), ``u in [0, 1]``; e.g. a
        :class:`scipy.interpolate.BSpline` of degree >= 3.
    vmax : float
        Speed limit (> 0).
    amax : float or array_like, shape (d,)
        Per-axis acceleration limit (> 0); a number, the norm limit, with
        ``norm_sides``.
    jmax : float or array_like, shape (d,), optional
        Per-axis jerk limit (a number, the norm limit, with ``norm_sides``);
        None disables jerk constraints.
    n : int, default 500
        Number of grid points (>= 3).
    chord_error : float, optional
        Maximum chord (sagitta) error ``eps``; adds ``v**2 <= 8 rho eps / T**2``.
    control_period : float, default 0.02
        Interpolation period ``T``.
    jerk_iterations : int, default 20
        Maximum number of pseudo-jerk iterations (per refinement round).
    jerk_tol : float, default 1e-3
        Stop when the relative change of ``sqrt(b)`` falls below this.
    safety : float, default 1.0
        Factor in ``(0, 1]`` applied to ``amax`` and ``jmax`` inside the LP
        (uniformly; the refinement below tightens only where needed).
    max_excess : float or None, default 0.02
        Target of the local refinement: while the interpolated plan exceeds a
        limit by more than this (relative, measured on the chain-rule
        derivatives at >= 3 even points per grid interval, 24 up to 2,000
        points, at its end from the left and at the path's kinks, where the
        dense check looks), the limits of the grid nodes around the
        excess are divided by ``(1 + excess)**r`` in round ``r = 1, 2, ...``
        and the LP is re-solved from the previous basis.  None disables the
        refinement.  The result is in ``SpeedPlan.excess_estimate``; it may
        stay above the target after ``refine_rounds`` rounds.
    refine_rounds : int, default 8
        Maximum number of refinement rounds.
    lp_backend : {"auto", "highspy", "linprog"}, default "auto"
        ``"highspy"`` keeps one HiGHS model and hot-starts every re-solve;
        ``"linprog"`` solves each LP from scratch with
        :func:`scipy.optimize.linprog`; ``"auto"`` takes highspy if installed.
    grid : {"uniform", "adaptive"}, default "uniform"
        ``"uniform"``: the ``n`` points are uniform in ``u``.  ``"adaptive"``
        (experimental): the LP runs on a parameter ``sigma`` with
        ``u = g(sigma)`` chosen so that a uniform ``sigma`` grid is half
        uniform in arc length and half uniform in an estimated time (denser at
        the rest ends and in tight curls); ``u`` and ``b`` of the plan are
        reported in ``u``.  On the 10 m square spiral it gives 0.5-2 % shorter
        plans than ``"uniform"`` at the same ``n`` and excess, but on paths
        whose end hooks are shorter than a grid cell its pseudo-jerk
        iteration can cycle and stop the vehicle at the last interior node
        (``InfeasibleError``) or plan twice as slowly.
    norm_sides : int, optional
        None (default): ``amax`` and ``jmax`` hold per axis.  An even ``m >= 4``:
        they are Euclidean norm limits ``|a| <= amax``, ``|j| <= jmax``, held in
        the LP by the inscribed regular ``m``-gon (rows
        ``n_k . (C'' b + 0.5 C' b') <= amax cos(pi/m)``, likewise the
        pseudo-jerk rows), i.e. up to ``1 - cos(pi/m)`` conservative at the
        grid nodes (0.5 % at ``m = 32``); the refinement and
        ``excess_estimate`` measure the norm itself.  2-D paths; on a 3-D
        path the polygon holds the horizontal norm and ``|a_z| <= amax``,
        ``|j_z| <= jmax`` the vertical component.
    deadline : Deadline, optional
        A wall-time budget: checked before every LP solve, whose HiGHS time
        limit is what is left of it (see :class:`~skyquill.coverage.deadline.Deadline`).
    method : {"auto", "reach", "warm", "banded", "lp"}, default "auto"
        How the grid problems are solved. ``"reach"``: without a jerk limit,
        by the backward and forward reachability passes (:mod:`.reach`; the
        LP's optimum, in linear time). ``"banded"``: with a jerk limit, the
        jerk-free problems by the passes and the pseudo-jerk LPs by the
        banded interior-point method (:mod:`.banded`, linear time per Newton
        step; with a norm limit on the rows of the polygon's directions that
        can bind, :mod:`.active_rows`); without one it is ``"reach"``.
        ``"warm"``: the jerk-free problems by the passes, the first pseudo-jerk
        LP by the banded interior point, and every LP after it by HiGHS,
        started from the basis of that answer's vertex, then from its own
        (:class:`~.banded_grid.BandedGrid`); without a jerk limit ``"reach"``.
        ``"lp"``: every problem by the HiGHS grid LP (the reference).
        ``"auto"``: ``"reach"`` without a jerk limit; with one ``"warm"`` below
        :data:`~.validate.BANDED_FROM_POINTS` grid points (the simplex
        re-solves from its last basis, which is faster on small grids) and
        ``"banded"`` from there (``"reach"`` with a jerk limit is refused:
        its rows couple three nodes).

    Returns
    -------
    SpeedPlan
        The plan; ``setpoints()`` and ``verify()`` give the time domain.

    Raises
    ------
    InputError
        Malformed argument.
    InfeasibleError
        The LP has no solution; or the deadline is spent (family ``"time_limit"``).
    SolverError
        HiGHS failed otherwise.
    """
    args = _validate(
        curve,
        n,
        vmax,
        control_period=control_period,
        chord_error=chord_error,
        jerk_iterations=jerk_iterations,
        jerk_tol=jerk_tol,
        safety=safety,
    )
    backend = _validate_refine(max_excess, refine_rounds, lp_backend, grid)
    n = args.n
    solver = _validate_method(method, jerk=jmax is not None, n=n)
    d = _eval(curve, np.array([0.0, 1.0]), 1).shape[1]
    norm = _validate_norm_sides(norm_sides, d)
    amax_a, jmax_a = _validate_limits(amax, jmax, d, norm_sides=norm)
    umap = None
    path: PathCurve = curve
    if grid == "adaptive":
        umap = _grid_map(curve, n, vmax=args.vmax, amax=amax_a, jmax=jmax_a)
        path = _Reparam(curve, umap)
    sig = np.linspace(0.0, 1.0, n)
    c1, c2, c3 = _derivs3(path, sig)
    speed2 = np.sum(c1 * c1, axis=1)
    if np.any(speed2 <= 1e-24):
        bad = sig[np.argmin(speed2)]
        raise InputError(
            f"curve: got a vanishing derivative |C'(u)| = 0 near u = {bad:.6g}, "
            "expected a regular path"
        )
    ub, vb = _speed_bounds(
        c1, c2, args.vmax, chord_error=args.chord_error, period=args.control_period
    )
    # The LP limits components: the axes, or the projections on the polygon's normals.
    p1, p2, p3 = (components(c, norm) for c in (c1, c2, c3))
    a = _acc_matrix(sig, (p1, p2), component_limits(amax_a, norm) * args.safety)
    jlim = None if jmax_a is None else component_limits(jmax_a, norm)
    if jlim is not None:
        a = sparse.vstack([a, _jerk_matrix((p1, p2, p3), jlim * args.safety, vb)], format="csr")
    lp: GridSolver

    def highs(rows: npt.NDArray[np.intp] | None = None) -> _GridLP:
        return _GridLP(a, backend=backend, deadline=deadline, rows=rows)

    if solver == "lp":
        lp = highs()
    else:
        acc = acceleration_rows(
            p1, p2, float(sig[1] - sig[0]), component_limits(amax_a, norm) * args.safety
        )
        if solver == "reach":
            lp = ReachGrid(acc, highs, deadline)
        else:
            assert jlim is not None  # "warm" and "banded" are "reach" without a jerk limit
            lp = BandedGrid(acc, banded_rows(acc, (p1, p2, p3), jlim * args.safety, vb), highs,
                            deadline, hand_over=solver == "warm")  # fmt: skip
    bounds = _Bounds(ub, None if jlim is None else vb, p1.shape[1], *_ones(n))
    log: tuple[list[float], list[float]] = ([], [])
    stop = (args.jerk_iterations, args.jerk_tol)
    b, iterations = _initial_solve(lp, bounds, c1=p1, jmax=jlim, stop=stop, log=log)
    plan = SpeedPlan(
        curve=curve,
        u=sig,
        b=b,
        duration=0.0,
        iterations=0,
        solve_time=0.0,
        objectives=(),
        jerk_changes=(),
        vmax=args.vmax,
        amax=amax_a,
        jmax=jmax_a,
        control_period=args.control_period,
        _bspline=_profile_spline(sig, b, jerk=jmax_a is not None),
        _path=path,
        _sigma=sig,
        _bsig=b,
        _umap=umap,
        grid=grid,
        norm_sides=norm,
        method=solver,
    )
    plan, rounds, est, extra = _refine(
        plan, lp, bounds, target=max_excess, rounds=refine_rounds, stop=stop, log=log
    )
    return replace(
        _in_caller_parameter(plan),
        duration=_duration(plan._bsig, sig[1], jerk=jmax_a is not None),
        iterations=iterations + extra,
        solve_time=lp.time,
        objectives=tuple(log[0]),
        jerk_changes=tuple(log[1]),
        refinements=rounds,
        excess_estimate=est,
        lp_solves=lp.solves,
        method="lp" if isinstance(lp, ReachGrid | BandedGrid) and lp.used_lp else solver,
    )


def _in_caller_parameter(plan: SpeedPlan) -> SpeedPlan:
    """``u``, ``b`` in the caller's parameter: ``u = g(sigma)``, ``b = b_sigma g'**2``."""
    if plan._umap is None:
        return replace(plan, u=plan._sigma, b=plan._bsig)
    u = np.clip(np.asarray(plan._umap(plan._sigma), dtype=np.float64), 0.0, 1.0)
    g1 = np.asarray(plan._umap(plan._sigma, 1), dtype=np.float64)
    return replace(plan, u=u, b=plan._bsig * g1**2)
