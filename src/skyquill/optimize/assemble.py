"""Turn a :class:`SmoothingProblem` into matrices (paper 003 §3-4, eq. 43).

The variable is the control-point matrix ``C`` of shape (M, d), vectorised
control-point-major, ``x = C.ravel()`` (the paper's ``C-hat``): the Hessian of
an axis-separable term is then ``V ⊗ I_d`` (eq. 9) and stays banded.

Cost ``J(C) = sum_j C_j' G C_j + <F, C> + x' G_c x + f_c' x + const`` where the
first two terms are axis-separable (smoothness, points) and the coupled part
holds lines and planes, whose quadratic forms mix axes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from skyquill.optimize.problem import (
    Corridor,
    Interpolation,
    LineDeviation,
    PlaneDeviation,
    PointDeviation,
    SmoothingProblem,
)
from skyquill.validation import FloatArray


@dataclass(frozen=True)
class InequalityFamily:
    """A named block of rows of ``G x <= h`` (for infeasibility reports)."""

    label: str
    rows: slice


@dataclass(frozen=True)
class Assembled:
    """The problem as matrices. See the module docstring for the cost form."""

    G_smooth: sp.csr_array  # (M, M)
    G_points: sp.csr_array  # (M, M)
    F: FloatArray  # (M, d)
    G_coupled: sp.csr_array | None  # (Md, Md)
    f_coupled: FloatArray | None  # (Md,)
    const: float
    E: sp.csr_array  # (m_eq, M), same rows for every axis
    e: FloatArray  # (m_eq, d)
    G_ineq: sp.csr_array  # (m_in, Md)
    h_ineq: FloatArray  # (m_in,)
    families: tuple[InequalityFamily, ...]

    @property
    def separable(self) -> bool:
        """Whether every cost and equality term acts on each axis alone."""
        return self.G_coupled is None

    def hessian(self) -> sp.csr_array:
        """Full ``G`` of ``x' G x`` with ``x = C.ravel()``, shape (Md, Md)."""
        d = self.F.shape[1]
        G = sp.kron(self.G_smooth + self.G_points, sp.eye_array(d), format="csr")
        return sp.csr_array(G + self.G_coupled) if self.G_coupled is not None else G

    def linear(self) -> FloatArray:
        """Full ``f`` of ``f' x``, shape (Md,)."""
        f = self.F.ravel()
        return f + self.f_coupled if self.f_coupled is not None else f

    def cost_terms(self, C: FloatArray) -> dict[str, float]:
        """``{"smoothness", "deviation", "total"}`` at control points ``C`` (M, d)."""
        smooth = float(np.sum(C * (self.G_smooth @ C)))
        dev = float(np.sum(C * (self.G_points @ C)) + np.sum(self.F * C) + self.const)
        if self.G_coupled is not None and self.f_coupled is not None:
            x = C.ravel()
            dev += float(x @ (self.G_coupled @ x) + self.f_coupled @ x)
        return {"smoothness": smooth, "deviation": dev, "total": smooth + dev}


def assemble(problem: SmoothingProblem, margin: float = 0.0) -> Assembled:
    """Build the matrices of ``problem``.

    Parameters
    ----------
    problem
        The validated problem.
    margin
        Relative tightening of every inequality's right-hand side
        (``h - margin * max(|h|, 1e-3)``), so that a solver's tolerance cannot
        leave the result outside a limit it was asked to hold.
    """
    basis = problem.basis
    alpha = problem.alpha
    M, d = problem.n_ctrl, problem.dim

    G_smooth = sp.csr_array((M, M))
    for order, sigma in problem.smoothness.items():
        if sigma:
            G_smooth = G_smooth + sigma * alpha ** (2 * order - 1) * basis.gram(order)

    G_points = sp.csr_array((M, M))
    F = np.zeros((M, d))
    const = 0.0
    coupled: list[tuple[sp.csr_array, FloatArray, float]] = []
    for term in problem.deviations:
        if isinstance(term, PointDeviation):
            H = basis.design_matrix(_params(problem, term.times))
            G_points = G_points + term.weight * (H.T @ H)
            F -= 2.0 * term.weight * (H.T @ term.points)
            const += term.weight * float(np.sum(term.points**2))
        else:
            coupled.append(_flat_term(problem, term))

    G_coupled = f_coupled = None
    if coupled:
        G_coupled = sp.csr_array(sum((g for g, _, _ in coupled), sp.csr_array((M * d, M * d))))
        f_coupled = np.sum([f for _, f, _ in coupled], axis=0)
        const += sum(c for _, _, c in coupled)

    E, e = _equalities(problem)
    G_ineq, h_ineq, families = _inequalities(problem)
    h_ineq = h_ineq - margin * np.maximum(np.abs(h_ineq), 1e-3)
    return Assembled(
        sp.csr_array(G_smooth),
        sp.csr_array(G_points),
        F,
        G_coupled,
        f_coupled,
        const,
        E,
        e,
        G_ineq,
        h_ineq,
        families,
    )


def _params(problem: SmoothingProblem, times: FloatArray) -> FloatArray:
    """Path parameters ``s = alpha * t`` of validated times, clipped to ``[0, L]``.

    Fix: ``SmoothingProblem`` accepts times up to 1e-9 * duration outside
    ``[0, duration]``, and even ``t = duration`` exactly can round to
    ``alpha * t > L`` (e.g. L = 3, duration = 1.3437...); the basis rejects
    such ``s`` (and a window start below 0 gave span -1), so clip here.
    """
    s = problem.alpha * np.asarray(times, dtype=float)
    return np.clip(s, 0.0, float(problem.basis.n_spans))


def _window_controls(problem: SmoothingProblem, t_start: float, t_end: float) -> FloatArray:
    """Indicator (M,) of the control points active on ``[t_start, t_end)`` (§3.4)."""
    first, last = problem.basis.spans_in_window(*_params(problem, np.array([t_start, t_end])))
    active = np.zeros(problem.n_ctrl)
    active[first : last + problem.degree + 1] = 1.0
    return active


def _flat_term(
    problem: SmoothingProblem, term: LineDeviation | PlaneDeviation
) -> tuple[sp.csr_array, FloatArray, float]:
    """Paper 003 eqs. (25), (27): ``sum_i (c_i - w)' Q (c_i - w)`` over the window."""
    Q, w = term.quadratic()
    active = _window_controls(problem, term.t_start, term.t_end)
    G = term.weight * sp.kron(sp.diags_array(active), Q, format="csr")
    f = -2.0 * term.weight * np.outer(active, Q @ w).ravel()
    c = term.weight * float(active.sum()) * float(w @ Q @ w)
    return sp.csr_array(G), f, c


def _equalities(problem: SmoothingProblem) -> tuple[sp.csr_array, FloatArray]:
    """Boundary conditions (eq. 42) and interpolated points (eq. 13), per axis."""
    basis, alpha, M = problem.basis, problem.alpha, problem.n_ctrl
    rows: list[sp.csr_array] = []
    rhs: list[FloatArray] = []
    for bc in problem.boundary:
        D = basis.derivative_map(bc.order) * alpha**bc.order
        if bc.start is not None:
            rows.append(sp.csr_array(D[[0], :]))
            rhs.append(bc.start[None, :])
        if bc.end is not None:
            rows.append(sp.csr_array(D[[D.shape[0] - 1], :]))
            rhs.append(bc.end[None, :])
    for term in problem.interpolation:
        if isinstance(term, Interpolation):
            rows.append(basis.design_matrix(_params(problem, term.times)))
            rhs.append(term.points)
    if not rows:
        return sp.csr_array((0, M)), np.zeros((0, problem.dim))
    return sp.csr_array(sp.vstack(rows)), np.vstack(rhs)


def _inequalities(
    problem: SmoothingProblem,
) -> tuple[sp.csr_array, FloatArray, tuple[InequalityFamily, ...]]:
    """Derivative limits (eq. 39) and corridors (eq. 32) on hull points."""
    basis, alpha, d = problem.basis, problem.alpha, problem.dim
    blocks: list[sp.csr_array] = []
    rhs: list[FloatArray] = []
    families: list[InequalityFamily] = []
    start = 0

    def add(label: str, hull: sp.csr_array, A: FloatArray, b: FloatArray) -> None:
        nonlocal start
        # (Hull ⊗ A) x = vec(Hull C A'): every hull point satisfies A v <= b.
        blocks.append(sp.csr_array(sp.kron(hull, A, format="csr")))
        rhs.append(np.tile(b, hull.shape[0]))
        families.append(InequalityFamily(label, slice(start, start + blocks[-1].shape[0])))
        start += blocks[-1].shape[0]

    for lim in problem.limits:
        A, b = lim.halfspaces()
        add(
            f"limit: {lim.label}",
            basis.hull_map(lim.order, kind=problem.hull) * alpha**lim.order,
            A,
            b,
        )
    for i, cor in enumerate(problem.corridors):
        first, last = basis.spans_in_window(*_params(problem, np.array([cor.t_start, cor.t_end])))
        add(_corridor_label(i, cor), basis.hull_map(0, first, last, problem.hull), cor.A, cor.b)
    if not blocks:
        return sp.csr_array((0, problem.n_ctrl * d)), np.zeros(0), ()
    return sp.csr_array(sp.vstack(blocks)), np.concatenate(rhs), tuple(families)


def _corridor_label(i: int, cor: Corridor) -> str:
    return f"corridor[{i}] on [{cor.t_start:g}, {cor.t_end:g}] s"
