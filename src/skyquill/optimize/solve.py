"""Solve a :class:`SmoothingProblem`: closed form or QP, then verify.

* Only equalities (boundary conditions, interpolated points): the KKT system
  of the equality-constrained quadratic is solved by a sparse LU
  factorisation (paper 003 eqs. 44-54, paper 000 eq. 43;
  :func:`skyquill.optimize.kkt.solve_equality_qp`). Its matrix is banded up
  to a permutation, so time and memory grow linearly with ``M``. When every
  term acts on each axis alone the ``M``-sized system is factored once and
  solved for all ``d`` axes together.
* With limits or corridors: a sparse QP through a backend adapter
  (:mod:`skyquill.solvers`). Every inequality is tightened by a tiny relative
  margin and the result is checked against the *untightened* hull
  constraints; if a solver's tolerance still leaves it outside, the margin
  grows tenfold and the QP is solved again. A trajectory that violates a
  guaranteed limit is never returned.
* With an exact norm limit (:class:`~skyquill.limits.NormLimit` with
  ``sides=None``): the same, as a conic program with one second-order cone
  per derivative hull point, solved by Clarabel whatever ``solver`` names
  (the other backends take no cones). The margin shrinks each radius by the
  same relative amount and the norms are checked against the untightened
  radius.

Either way the result keeps the multipliers of the problem it solved
(:attr:`FitResult.y`, :attr:`FitResult.z`, :attr:`FitResult.cone_z`); the re-segmentation gradient
(:mod:`skyquill.optimize.resegment`) is built on them.

Paper 003 eq. (54) drops the factor ``-1/2`` of the stationarity condition
of ``x'Gx + f'x``; solving the KKT system sidesteps the slip.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cached_property
from typing import Any, Literal

import numpy as np
import scipy.linalg
import scipy.optimize
import scipy.sparse as sp
from numpy.typing import NDArray

from skyquill.errors import InfeasibleError, InputError, SolverError
from skyquill.optimize.assemble import (
    Assembled,
    NormCones,
    _Fixed,
    assemble,
    problem_cost,
    smoothness_cost,
)
from skyquill.optimize.banded import banded_closed_form
from skyquill.optimize.kkt import SingularKKTError, solve_equality_qp
from skyquill.optimize.problem import SmoothingProblem
from skyquill.optimize.workspace import Workspace
from skyquill.solvers import (
    BACKENDS,
    CONIC_BACKENDS,
    DEFAULT_BACKEND,
    QuadraticProgram,
    SecondOrderCones,
    solve_qp,
)
from skyquill.trajectory import SplineTrajectory
from skyquill.validation import FloatArray
from skyquill.verify import Verification

log = logging.getLogger(__name__)

#: The closed form's solver when the Hessian is banded (:mod:`skyquill.optimize.banded`).
BANDED = "banded-cholesky"

#: Hull constraints must hold to this relative tolerance (docs/architecture.md: 1e-9).
GUARANTEE_RTOL = 1e-9
_MARGINS = (1e-9, 1e-8, 1e-7, 1e-6, 1e-5)


@dataclass(frozen=True)
class FitResult:
    """A solved problem.

    Attributes
    ----------
    trajectory
        The B-spline trajectory.
    method
        ``"closed_form"`` or ``"qp"`` (also for the conic program of exact norm limits).
        With a workspace, also ``"closed_form"`` for a problem with
        inequalities that its equality-only minimiser meets (:func:`solve`).
    solver
        ``"banded-cholesky"`` (:data:`BANDED`) or ``"sparse-lu"`` for the closed form,
        else the QP backend's name.
    cost
        Total cost ``smoothness + deviation`` (paper 003 eq. 7).
    cost_terms
        ``{"smoothness", "deviation", "total"}``.
    solve_time_s
        Wall time of assembly, solve and retries (not the dense check).
    margin
        Relative tightening that was needed (0 for the closed form).
    problem
        The problem that was solved.
    n_variables, n_equalities, n_inequalities
        Problem size (``n_inequalities``: linear rows).
    n_cones
        Second-order cones (one per hull point of an exact norm limit).
    y
        Equality multipliers, shape (n_equalities,), one per row of
        ``A_eq = kron(E, I_d)`` of ``assemble(problem)`` (row ``i d + j``:
        equality ``i`` on axis ``j``; ``x = C.ravel()``).
    z
        Inequality multipliers ``>= 0``, shape (n_inequalities,), one per row
        of ``assemble(problem).G_ineq`` (empty for the closed form). They
        belong to the QP that was solved, i.e. with ``h`` tightened by
        ``margin``, whose minimiser is ``trajectory``.

    With ``J(x) = x'Hx + f'x`` the assembled cost (``H = hessian()``,
    ``f = linear()``; the QP's ``P = 2 H``, ``q = f``), the multipliers satisfy
    ``2 H x + f + A_eq' y + G_ineq' z + A_c' cone_z = 0`` (the sign convention
    of :class:`skyquill.solvers.QPSolution`), to the backend's tolerance on the
    QP route.
    cone_z
        Second-order cone multipliers, shape (n_cones (d + 1),), or ``None``
        without exact norm limits: one block ``(z_0, z_1..z_d)`` per hull point,
        ``||(z_1..z_d)|| <= z_0``, for the rows ``A_c`` of
        ``_to_qp(assemble(problem), margin).cones`` (Clarabel's ``b_c - A_c x in
        SOC(d + 1)`` with ``A_c x = (0, v_p)``, ``b_c = (r_p, 0)``). At an active
        cone ``z_1..z_d = (z_0 / r_p) v_p``.
    """

    trajectory: SplineTrajectory
    method: Literal["closed_form", "qp"]
    solver: str
    cost: float
    cost_terms: dict[str, float]
    solve_time_s: float
    margin: float
    problem: SmoothingProblem
    n_variables: int
    n_equalities: int
    n_inequalities: int
    y: FloatArray
    z: FloatArray
    n_cones: int = 0
    cone_z: FloatArray | None = None

    @property
    def status(self) -> Literal["optimal"]:
        """Always ``"optimal"``: an infeasible or failed solve raises instead of returning."""
        return "optimal"

    @cached_property
    def verification(self) -> Verification:
        """The dense check against the problem's limits and corridors.

        Computed on first access (~0.7 ms for 10,000 samples) so that inner
        loops -- bisection on time, re-segmentation -- do not pay for it; the
        limits themselves are guaranteed by the exact hull check in the solve,
        which is never skipped.
        """
        return self.trajectory.verify(self.problem.limits, self.problem.corridors)


def solve(
    problem: SmoothingProblem,
    solver: str = DEFAULT_BACKEND,
    *,
    workspace: Workspace | None = None,
) -> FitResult:
    """Solve ``problem``; the result carries its dense check (``verification``).

    Parameters
    ----------
    problem
        The validated problem.
    solver
        QP backend for problems with inequalities (see :data:`BACKENDS`).
    workspace
        Shared with the other solves of a sequence of related problems
        (re-segmentation): re-used assembly blocks and PIQP setups
        (:class:`~skyquill.optimize.workspace.Workspace`). With a workspace a
        problem with inequalities is first solved subject to its equalities
        alone (the closed form, one per-axis factorisation): when that point
        meets every limit, corridor and cone exactly it is the optimum (of a
        relaxation, and feasible), with all inequality multipliers 0, and is
        returned as ``method="closed_form"`` (a writing mission's
        re-segmentation at its default limits, where nothing binds). Either
        way the result is the fresh solve's, to the backend's tolerance.

    Raises
    ------
    InfeasibleError
        The constraints cannot all be met; ``families`` names which
        (``("equalities",)`` for contradictory equalities, on either route).
    SolverError
        Every backend failed, or the cost does not determine the closed form.
    """
    if solver not in BACKENDS:
        raise InputError(f"solver: got {solver!r}, expected one of {sorted(BACKENDS)}")
    start = time.perf_counter()
    inside, deviation = (
        _inside_optimum(problem, workspace) if workspace is not None else (None, None)
    )
    if inside is not None:
        C, (y, z, cone_z), used, margin, asm = inside
        method: Literal["closed_form", "qp"] = "closed_form"
    elif problem.has_inequalities:
        C, (y, z, cone_z), used, margin, asm = _solve_qp(problem, solver, workspace)
        method = "qp"
    else:
        C, y, used, asm = _equality_optimum(problem, workspace)
        z, margin, cone_z = np.zeros(0), 0.0, None
        method = "closed_form"
    solved = (C, (y, z, cone_z), used, margin, asm)
    elapsed = time.perf_counter() - start
    return _fit_result(problem, solved, method, elapsed, workspace, deviation=deviation)


def solve_inside(problem: SmoothingProblem, workspace: Workspace) -> FitResult | None:
    """``solve(problem)`` when no inequality binds at its optimum, else ``None`` (no QP).

    The closed form subject to the equalities alone, kept only if it meets every
    limit, corridor and cone exactly (:func:`solve`'s first route with a
    workspace): a descent that only wants to stay where nothing binds
    (:func:`~skyquill.optimize.resegment.resegment` with ``interior=True``)
    asks this, and skips the conic solve of a point it would reject.
    """
    if not problem.has_inequalities:
        return solve(problem, workspace=workspace)  # the closed form is the solve
    start = time.perf_counter()
    inside, deviation = _inside_optimum(problem, workspace)
    if inside is None:
        return None
    elapsed = time.perf_counter() - start
    return _fit_result(problem, inside, "closed_form", elapsed, workspace, deviation=deviation)


def _fit_result(
    problem: SmoothingProblem,
    solved: _Solved,
    method: Literal["closed_form", "qp"],
    elapsed: float,
    workspace: Workspace | None,
    *,
    deviation: float | None = None,
) -> FitResult:
    """The result of ``solved``; ``deviation``: the point deviations' cost where the
    solve already has it (the banded closed form's), else it is measured on the curve."""
    C, (y, z, cone_z), used, margin, asm = solved
    traj = SplineTrajectory(C, problem.degree, problem.duration)
    if deviation is None:
        terms = problem_cost(problem, C, workspace.assembly if workspace is not None else None)
    else:
        smooth = smoothness_cost(problem, C)
        terms = {"smoothness": smooth, "deviation": deviation, "total": smooth + deviation}
    return FitResult(
        traj,
        method,
        used,
        terms["total"],
        terms,
        elapsed,
        margin,
        problem,
        n_variables=C.size,
        n_equalities=asm.E.shape[0] * problem.dim,
        n_inequalities=asm.G_ineq.shape[0],
        y=y,
        z=z,
        n_cones=asm.cones.radius.size if asm.cones is not None else 0,
        cone_z=cone_z,
    )


def _inside_optimum(
    problem: SmoothingProblem, workspace: Workspace
) -> tuple[_Solved | None, float | None]:
    """The minimiser subject to the equalities, if it meets every inequality exactly,
    and its point deviations' cost where the banded closed form found it.

    A relaxation's optimum that is feasible is optimal, and no inequality
    holds it, so every inequality and cone multiplier is 0. Exactly: ``G x <=
    h`` and ``||v_p|| <= r_p`` without tolerance, so the guarantee's excess is
    0. ``None`` without inequalities, when one is not met, or when the
    equalities alone do not determine the point (the QP route decides).
    """
    if not problem.has_inequalities:
        return None, None
    fast = banded_closed_form(problem, workspace.assembly)
    blocks: Assembled | _Fixed
    deviation = None
    if fast is not None:
        C, y, used, blocks, deviation = fast.C, fast.y, BANDED, fast.fixed, fast.deviation
    else:
        asm = workspace.assemble(problem)
        try:
            C, y = _closed_form_kkt(asm)
        except SingularKKTError:
            return None, None
        used, blocks = "sparse-lu", asm
    x = C.ravel()
    if not np.all(np.isfinite(x)) or np.any(blocks.G_ineq @ x > blocks.h_ineq):
        return None, None
    cone_z = None
    if blocks.cones is not None:
        if np.any(blocks.cones.norms(x) > blocks.cones.radius):
            return None, None
        cone_z = np.zeros(blocks.cones.radius.size * (problem.dim + 1))
    return (C, (y, np.zeros(blocks.G_ineq.shape[0]), cone_z), used, 0.0, blocks), deviation


def _equality_optimum(
    problem: SmoothingProblem, workspace: Workspace | None
) -> tuple[FloatArray, FloatArray, str, Assembled | _Fixed]:
    """The closed form subject to the equalities: banded Cholesky where the problem is
    of that form (:mod:`skyquill.optimize.banded`), else one sparse LU of the KKT system.
    Control points, multipliers, the solver's name and the blocks it met."""
    fast = banded_closed_form(problem, workspace.assembly if workspace is not None else None)
    if fast is not None:
        return fast.C, fast.y, BANDED, fast.fixed
    asm = workspace.assemble(problem) if workspace is not None else assemble(problem)
    C, y = _closed_form(asm)
    return C, y, "sparse-lu", asm


def _closed_form(asm: Assembled) -> tuple[FloatArray, FloatArray]:
    """Minimise the quadratic subject to the equalities by one sparse LU.

    Returns the control points (M, d) and the multipliers ``y`` (m_eq d,) of
    the rows of ``kron(E, I_d)`` (:attr:`FitResult.y`).

    Consistent but redundant equalities that assembly cannot see as exact
    repeats make the KKT matrix singular although the QP route would solve
    the problem. On a singular factorisation the dependent rows are dropped
    (their multipliers are 0) and the system solved again; contradictory rows
    raise :class:`InfeasibleError`, as on the QP route.
    """
    try:
        return _closed_form_kkt(asm)
    except SingularKKTError as exc:
        keep = _independent_equalities(asm)
        if keep is None:
            raise _singular(exc) from exc
        try:
            C, y_kept = _closed_form_kkt(replace(asm, E=sp.csr_array(asm.E[keep]), e=asm.e[keep]))
        except SingularKKTError as again:
            raise _singular(again) from again
        d = asm.F.shape[1]
        y = np.zeros((asm.E.shape[0], d))
        y[keep] = y_kept.reshape(-1, d)
        return C, y.ravel()


def _singular(exc: SingularKKTError) -> SolverError:
    return SolverError(
        "closed form: the KKT matrix is singular -- the equalities are redundant or "
        "contradictory, or the cost does not determine every control point (add a "
        f"deviation term or boundary conditions) ({exc})"
    )


def _independent_equalities(asm: Assembled) -> NDArray[np.intp] | None:
    """Indices of a linearly independent subset of the equality rows; ``None`` if all are.

    Dense pivoted QR of ``E'``: only reached after a singular factorisation.
    """
    E = asm.E.toarray()
    if E.shape[0] == 0:
        return None
    _, R, piv = scipy.linalg.qr(E.T, mode="economic", pivoting=True)
    diag = np.abs(np.diag(R))
    rank = int(np.count_nonzero(diag > diag[0] * max(E.shape) * np.finfo(float).eps))
    if rank == E.shape[0]:
        return None
    keep = np.sort(piv[:rank])
    C0 = np.linalg.lstsq(E[keep], asm.e[keep], rcond=None)[0]
    # Residual relative to each row's magnitude (rows scale with alpha^order).
    scale = np.abs(E).sum(axis=1)[:, None] * max(float(np.abs(C0).max()), 1e-300) + np.abs(asm.e)
    if float((np.abs(E @ C0 - asm.e) / scale).max()) > 1e-9:
        raise InfeasibleError(
            "infeasible: the boundary conditions and interpolated points contradict each other",
            ("equalities",),
        )
    return keep


def _closed_form_kkt(asm: Assembled) -> tuple[FloatArray, FloatArray]:
    """One KKT solve: control points (M, d) and equality multipliers (m_eq d,).

    ``J = x'Hx + f'x``, so the QP has ``P = 2 H`` and ``q = f``. When every
    term acts on each axis alone the ``M``-sized system is solved for all
    ``d`` axes with one factorisation; row ``i`` of the multipliers (m_eq, d)
    then belongs to rows ``i d .. i d + d - 1`` of ``kron(E, I_d)``.
    """
    M, d = asm.F.shape
    if asm.separable:
        C, y = np.zeros((M, d)), np.zeros((asm.E.shape[0], d))
        for axes, G in asm.axis_groups():
            sol = solve_equality_qp(2.0 * G, asm.F[:, axes], asm.E, asm.e[:, axes])
            C[:, axes] = sol.x
            y[:, axes] = sol.y.reshape(-1, len(axes))
        return C, y.ravel()
    A = sp.csr_array(sp.kron(asm.E, sp.eye_array(d), format="csr"))
    sol = solve_equality_qp(2.0 * asm.hessian(), asm.linear(), A, asm.e.ravel())
    return sol.x.reshape(M, d), sol.y


def _to_qp(
    asm: Assembled, margin: float = 0.0, workspace: Workspace | None = None
) -> QuadraticProgram:
    """The QP of ``asm``, every inequality tightened by ``margin * max(|h|, 1e-3)``.

    The margin keeps a solver's feasibility tolerance from leaving the result
    outside a limit it was asked to hold; cone radii shrink the same way.
    ``workspace`` re-uses the equality rows, inequality rows and cones derived
    from the same assembly blocks (what the times leave alone).
    """
    d = asm.F.shape[1]

    def memo(name: str, keys: tuple[object, ...], build: Callable[[], Any]) -> Any:
        return workspace.memo(name, keys, build) if workspace is not None else build()

    cones = None
    if asm.cones is not None:
        held = asm.cones
        cones = memo(f"cones {margin!r}", (held,), lambda: _second_order_cones(held, margin))
    return QuadraticProgram(
        P=memo("P", (asm.G_axis, asm.G_coupled, asm.G_axes), lambda: _hessian(asm, workspace)),
        q=asm.linear(),
        A_eq=memo("A_eq", (asm.E,), lambda: sp.csc_array(sp.kron(asm.E, sp.eye_array(d)))),
        b_eq=asm.e.ravel(),
        G=memo("G", (asm.G_ineq,), lambda: sp.csc_array(asm.G_ineq)),
        h=asm.h_ineq - margin * np.maximum(np.abs(asm.h_ineq), 1e-3),
        cones=cones,
    )


def _hessian(asm: Assembled, workspace: Workspace | None) -> sp.csc_array:
    """The QP's ``P = 2 H`` (CSC); separable ``H = G_axis (x) I_d`` through the workspace."""
    if workspace is None or asm.G_coupled is not None or asm.G_axes:
        return sp.csc_array(2.0 * asm.hessian())
    return workspace.kron_eye(sp.csr_array(2.0 * asm.G_axis), asm.F.shape[1])


def _second_order_cones(
    cones: NormCones, margin: float, points: slice | None = None
) -> SecondOrderCones:
    """Clarabel's ``b - A x in SOC(d + 1)`` per hull point: ``(r, -v_p)``, ``||v_p|| <= r``.

    ``points`` keeps only those hull points (infeasibility diagnosis).
    """
    keep = points if points is not None else slice(0, cones.radius.size)
    radius = cones.radius[keep]
    P = radius.size
    d = cones.map.shape[0] // cones.radius.size
    rows = cones.map[keep.start * d : keep.stop * d].tocoo()
    # Row j of point p goes to row p (d + 1) + 1 + j; row p (d + 1) is the radius.
    A = sp.csc_array(
        (rows.data, ((rows.row // d) * (d + 1) + 1 + rows.row % d, rows.col)),
        shape=(P * (d + 1), cones.map.shape[1]),
    )
    b = np.zeros(P * (d + 1))
    b[:: d + 1] = radius - margin * np.maximum(radius, 1e-3)
    return SecondOrderCones(A, b, (d + 1,) * P)


def _hull_excess(asm: Assembled, x: FloatArray) -> float:
    """Largest relative excess over the untightened hull constraints (linear rows and cones)."""
    scale = np.maximum(np.abs(asm.h_ineq), 1e-3)
    excess = float(((asm.G_ineq @ x - asm.h_ineq) / scale).max(initial=0.0))
    if asm.cones is not None:
        r = asm.cones.radius
        cone = (asm.cones.norms(x) - r) / np.maximum(r, 1e-3)
        excess = max(excess, float(cone.max(initial=0.0)))
    return excess


#: Control points, the duals ``(y, z, cone_z)``, the backend, the margin, the assembly
#: (or, from the banded closed form, the time-independent blocks alone).
_Solved = tuple[
    FloatArray, tuple[FloatArray, FloatArray, FloatArray | None], str, float, Assembled | _Fixed
]


def _solve_qp(problem: SmoothingProblem, solver: str, workspace: Workspace | None) -> _Solved:
    """Control points, the duals ``(y, z, cone_z)`` of the same (tightened) QP, backend, margin."""
    exact = workspace.assemble(problem) if workspace is not None else assemble(problem)
    session = workspace.session("qp") if workspace is not None else None
    if exact.cones is not None:
        relaxed = _relaxed(problem, exact, workspace)
        if relaxed is not None:
            return relaxed
        backends = list(CONIC_BACKENDS)
    else:
        backends = [solver, *(b for b in ("clarabel", "piqp") if b != solver)]
    failures: list[str] = []
    for margin in _MARGINS:
        qp = _to_qp(exact, margin, workspace)
        for backend in backends:
            sol = solve_qp(qp, backend, session=session)
            if sol.status == "infeasible":
                _raise_infeasible(problem, exact)
            if sol.status == "optimal" and sol.x is not None:
                break
            failures.append(f"{backend}: {sol.message}")
        else:
            continue
        assert sol.x is not None and sol.y is not None and sol.z is not None
        excess = _hull_excess(exact, sol.x)
        if excess <= GUARANTEE_RTOL:
            C = sol.x.reshape(problem.n_ctrl, problem.dim)
            return C, (sol.y, sol.z, sol.cone_z), sol.solver, margin, exact
        log.info("hull excess %.3g at margin %.0e; tightening", excess, margin)
    if failures and len(failures) >= len(backends) * len(_MARGINS):
        # Backends fail this way on problems that are infeasible by a hair.
        _raise_infeasible(problem, exact, certain=False)
    raise SolverError(
        "QP: could not meet the hull constraints to 1e-9 relative even with a 1e-5 margin"
        + (f" (backend failures: {'; '.join(failures[:3])})" if failures else "")
    )


def _relaxed(
    problem: SmoothingProblem, exact: Assembled, workspace: Workspace | None
) -> (
    tuple[FloatArray, tuple[FloatArray, FloatArray, FloatArray | None], str, float, Assembled]
    | None
):
    """The conic program's optimum from a QP, when the norm limits turn out not to bind.

    Every ball ``||v_p|| <= r_p`` is replaced by its circumscribing box
    ``-r_p <= v_p,i <= r_p``: a relaxation, solved by the (faster) QP backend,
    one two-sided row per component. If its solution meets every ball to the
    guarantee tolerance it is the conic program's optimum (a relaxation's
    optimum that is feasible is optimal), and if no box row is active the
    dropped rows carry no multiplier, so the duals are the conic program's too
    (cone duals 0). Writing at the default limits is such a case: nothing
    binds, and a Clarabel solve takes ~2x a PIQP one. Returns None when a ball
    or a box binds (then the cones are needed).
    """
    assert exact.cones is not None
    margin = _MARGINS[0]
    qp = _relaxed_qp(exact, margin, workspace)
    session = workspace.session("relaxed") if workspace is not None else None
    sol = solve_qp(qp, DEFAULT_BACKEND, session=session)
    if sol.status != "optimal" or sol.x is None or sol.y is None or sol.z is None:
        return None
    if _hull_excess(exact, sol.x) > GUARANTEE_RTOL:
        return None  # a ball is violated: the norm limit binds
    bound = np.repeat(exact.cones.radius, problem.dim)
    slack = bound - np.abs(exact.cones.map @ sol.x)
    if np.any(slack <= 1e-6 * np.maximum(bound, 1e-3)):
        return None  # a box row binds: its multiplier would be lost
    C = sol.x.reshape(problem.n_ctrl, problem.dim)
    m = exact.G_ineq.shape[0]
    cone_z = np.zeros(exact.cones.radius.size * (problem.dim + 1))
    return C, (sol.y, sol.z[:m], cone_z), sol.solver, margin, exact


def _relaxed_qp(exact: Assembled, margin: float, workspace: Workspace | None) -> QuadraticProgram:
    """The QP of ``exact`` with its cones replaced by two-sided box rows (:func:`_relaxed`)."""
    cones = exact.cones
    assert cones is not None
    linear = _to_qp(replace(exact, cones=None), margin, workspace)
    bound = np.repeat(cones.radius, exact.F.shape[1])
    tight = bound - margin * np.maximum(bound, 1e-3)

    def rows() -> sp.csc_array:
        return sp.csc_array(sp.vstack([linear.G, cones.map]))

    G = workspace.memo("relaxed G", (linear.G, cones), rows) if workspace is not None else rows()
    return replace(
        linear,
        G=G,
        h=np.concatenate([linear.h, tight]),
        h_lower=np.concatenate([np.full(linear.h.size, -np.inf), -tight]),
    )


def _raise_infeasible(problem: SmoothingProblem, asm: Assembled, certain: bool = True) -> None:
    """Find which constraint families cannot be met, then raise :class:`InfeasibleError`.

    Linear families are tested by an LP (HiGHS); once a cone family is among
    them, by Clarabel with a zero objective.
    """
    d = problem.dim
    A_eq = sp.csr_array(sp.kron(asm.E, sp.eye_array(d)))
    b_eq = asm.e.ravel()
    # (label, is_cone, rows): rows of G_ineq, or hull points of asm.cones.
    families = [(f.label, False, f.rows) for f in asm.families]
    if asm.cones is not None:
        families += [(f.label, True, f.rows) for f in asm.cones.families]

    def feasible(chosen: list[tuple[str, bool, slice]]) -> bool:
        rows = [r for _, is_cone, r in chosen if not is_cone]
        points = [r for _, is_cone, r in chosen if is_cone]
        if points:
            return _conic_feasible(asm, rows, points)
        G = sp.vstack([asm.G_ineq[r, :] for r in rows]) if rows else None
        h = np.concatenate([asm.h_ineq[r] for r in rows]) if rows else None
        # scipy accepts sparse A_ub / A_eq; its stubs only list dense arrays.
        res = scipy.optimize.linprog(  # type: ignore[call-overload]
            np.zeros(asm.G_ineq.shape[1]),
            A_ub=G,
            b_ub=h,
            A_eq=A_eq if b_eq.size else None,
            b_eq=b_eq if b_eq.size else None,
            bounds=(None, None),
            method="highs",
        )
        return bool(res.status == 0)

    prefix = "infeasible" if certain else "the QP solvers failed; most likely infeasible"
    if b_eq.size and not feasible([]):
        raise InfeasibleError(
            f"{prefix}: the boundary conditions and interpolated points contradict each other",
            ("equalities",),
        )
    alone = [f[0] for f in families if not feasible([f])]
    if alone:
        raise InfeasibleError(
            f"{prefix}: cannot be met together with the boundary conditions and interpolated "
            f"points: {'; '.join(alone)} (try a longer duration, more control points or "
            "looser limits)",
            tuple(alone),
        )
    raise InfeasibleError(
        f"{prefix}: each constraint family is satisfiable alone but not all together: "
        f"{'; '.join(f[0] for f in families)}",
        tuple(f[0] for f in families),
    )


def _conic_feasible(asm: Assembled, rows: list[slice], points: list[slice]) -> bool:
    """Whether the equalities, the linear ``rows`` and the cones on hull ``points`` can all hold."""
    assert asm.cones is not None
    n, d = asm.G_ineq.shape[1], asm.F.shape[1]
    blocks = [_second_order_cones(asm.cones, 0.0, p) for p in points]
    program = QuadraticProgram(
        P=sp.csc_array((n, n)),
        q=np.zeros(n),
        A_eq=sp.csc_array(sp.kron(asm.E, sp.eye_array(d))),
        b_eq=asm.e.ravel(),
        G=sp.csc_array(sp.vstack([asm.G_ineq[r, :] for r in rows] or [sp.csr_array((0, n))])),
        h=np.concatenate([asm.h_ineq[r] for r in rows] or [np.zeros(0)]),
        cones=SecondOrderCones(
            sp.csc_array(sp.vstack([c.A for c in blocks])),
            np.concatenate([c.b for c in blocks]),
            tuple(k for c in blocks for k in c.dims),
        ),
    )
    return solve_qp(program, "clarabel", tol=1e-8).status == "optimal"
