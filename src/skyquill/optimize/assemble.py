"""Turn a :class:`SmoothingProblem` into matrices (paper 003 §3-4, eq. 43).

The variable is the control-point matrix ``C`` of shape (M, d), vectorised
control-point-major, ``x = C.ravel()`` (the paper's ``C-hat``): the Hessian of
an axis-separable term is then ``V ⊗ I_d`` (eq. 9) and stays banded.

The objective ``sum_j C_j' G C_j + <F, C> + x' G_c x + f_c' x`` (plus a
constant) has an axis-separable part (smoothness, points) and a coupled part
(lines and planes, whose quadratic forms mix axes). ``cost_scale`` makes its
largest diagonal entry 1 in the closed form's KKT system: with jerk or snap
costs at fine knot spacing the raw entries grow like ``alpha^5`` or ``alpha^7``
and would be mixed with O(1) equality rows. (The QP backends equilibrate on
their own and keep the raw scale, on which their absolute tolerances were
set.) Equality rows are written in the path parameter ``s`` (derivative rows
divided by ``alpha^n``). Neither changes the minimiser; the reported cost is
evaluated term by term by :func:`problem_cost`, never from these matrices.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, TypeVar

import numpy as np
import scipy.sparse as sp

from skyquill.errors import InfeasibleError
from skyquill.limits import NormLimit
from skyquill.optimize.problem import (
    Corridor,
    LineDeviation,
    PlaneDeviation,
    PointDeviation,
    SmoothingProblem,
)
from skyquill.spline import HullKind, basis_for
from skyquill.spline.local import LocalBasis, rows_times
from skyquill.validation import FloatArray


@dataclass(frozen=True)
class InequalityFamily:
    """A named block of rows of ``G x <= h`` (for infeasibility reports)."""

    label: str
    rows: slice


@dataclass(frozen=True)
class NormCones:
    """Exact norm limits: ``||v_p|| <= radius_p`` on every derivative hull point ``p``.

    Attributes
    ----------
    map
        Shape (P d, M d): ``(map @ x).reshape(P, d)`` are the hull points
        ``v_p`` (SI units, already scaled by ``alpha^n``).
    radius
        Shape (P,): the bound of each point's limit.
    families
        One per limit; ``rows`` slices the *points* ``0..P-1``.
    """

    map: sp.csr_array
    radius: FloatArray
    families: tuple[InequalityFamily, ...]

    def norms(self, x: FloatArray) -> FloatArray:
        """``||v_p||`` of the control points ``x = C.ravel()``, shape (P,)."""
        v = (self.map @ x).reshape(self.radius.size, -1)
        return np.asarray(np.sqrt((v**2).sum(axis=1)))


@dataclass(frozen=True)
class Assembled:
    """The problem as matrices (module docstring)."""

    cost_scale: float  # 1 / largest diagonal entry of the Hessian
    G_axis: sp.csr_array  # (M, M): smoothness + points, per axis
    F: FloatArray  # (M, d)
    G_coupled: sp.csr_array | None  # (Md, Md)
    f_coupled: FloatArray | None  # (Md,)
    E: sp.csr_array  # (m_eq, M), same rows for every axis
    e: FloatArray  # (m_eq, d)
    G_ineq: sp.csr_array  # (m_in, Md)
    h_ineq: FloatArray  # (m_in,)
    families: tuple[InequalityFamily, ...]
    cones: NormCones | None = None  # exact norm limits (second-order cones)
    # (mask (d,), (M, M)): added to G_axis on the axes of mask only (a point
    # term whose axes differ, e.g. a brush tip's acceleration gain on x, y alone).
    G_axes: tuple[tuple[FloatArray, sp.csr_array], ...] = ()

    @property
    def separable(self) -> bool:
        """Whether every cost and equality term acts on each axis alone."""
        return self.G_coupled is None

    def axis_groups(self) -> list[tuple[list[int], sp.csr_array]]:
        """The axes that share one ``(M, M)`` Hessian, and that Hessian (separable only)."""
        d = self.F.shape[1]
        groups: dict[tuple[int, ...], list[int]] = {}
        for k in range(d):
            key = tuple(i for i, (mask, _) in enumerate(self.G_axes) if mask[k])
            groups.setdefault(key, []).append(k)
        out = []
        for key, axes in groups.items():
            G = self.G_axis
            for i in key:
                G = G + self.G_axes[i][1]
            out.append((axes, sp.csr_array(G)))
        return out

    def hessian(self) -> sp.csr_array:
        """Full ``G`` of ``x' G x`` with ``x = C.ravel()``, shape (Md, Md)."""
        d = self.F.shape[1]
        G = sp.kron(self.G_axis, sp.eye_array(d), format="csr")
        for mask, block in self.G_axes:
            G = G + sp.kron(block, sp.diags_array(mask), format="csr")
        return sp.csr_array(G + self.G_coupled) if self.G_coupled is not None else G

    def linear(self) -> FloatArray:
        """Full ``f`` of ``f' x``, shape (Md,)."""
        f = self.F.ravel()
        return f + self.f_coupled if self.f_coupled is not None else f


@dataclass(frozen=True)
class _Fixed:
    """The blocks of an assembly that the point times leave alone (:class:`AssemblyCache`)."""

    smooth: sp.csr_array  # (M, M): the smoothness Gram matrices
    boundary: tuple[list[FloatArray], list[FloatArray], dict[float, FloatArray]]
    E: sp.csr_array  # (m_b, M): the boundary rows alone
    e: FloatArray  # (m_b, d)
    G_ineq: sp.csr_array
    h_ineq: FloatArray
    families: tuple[InequalityFamily, ...]
    cones: NormCones | None


class AssemblyCache:
    """Re-use the blocks that stay the same across a sequence of assemblies.

    Re-segmentation assembles a dozen problems per plan that differ only in
    the point times: the smoothness Gram matrices, the boundary rows, the
    limit and corridor rows and the cones depend on the knots, ``alpha`` and
    the terms themselves, not on the times, and with the total time fixed
    they come out bit-identical every time. The cache keeps the last set,
    keyed on exactly what they are built from (degree, control points,
    ``alpha``, hull, dimension, smoothness weights, and the values of the
    boundary, limit and corridor terms), so a problem that differs in any of
    those is assembled afresh. One cache belongs to one sequence of solves
    (:class:`skyquill.optimize.workspace.Workspace`); there is no global state.
    """

    def __init__(self) -> None:
        self._key: tuple[object, ...] | None = None
        self._fixed: _Fixed | None = None
        self._design: dict[tuple[object, ...], tuple[FloatArray, sp.csr_array]] = {}
        self._local: dict[tuple[object, ...], tuple[FloatArray, LocalBasis]] = {}
        #: The same local bases by the times' values (bytes), knots and ``alpha``.
        self._by_content: dict[tuple[object, ...], LocalBasis] = {}
        self._kept: dict[str, list[tuple[tuple[object, ...], tuple[object, ...], Any]]] = {}
        self._band: tuple[sp.csr_array, int, FloatArray] | None = None
        #: How often the blocks were re-used, and built (for tests and benchmarks).
        self.hits = 0
        self.builds = 0

    def design_matrix(
        self, problem: SmoothingProblem, times: FloatArray, order: int = 0
    ) -> sp.csr_array:
        """The basis rows (derivative ``order`` in ``s``) at a term's ``times``, shape (N, M).

        The assembly, the cost and the time gradient of one problem each need
        them; they are kept for the very ``times`` array (held, so identity is
        exact) at the same knots and ``alpha``, for the last few terms.
        """
        key = (id(times), problem.alpha, problem.degree, problem.n_ctrl, order)
        held = self._design.get(key)
        if held is not None and held[0] is times:
            return held[1]
        if len(self._design) >= _DESIGN_ENTRIES:
            self._design.clear()
        if order > min(_LOCAL_ORDERS, problem.degree):
            matrix = problem.basis.design_matrix(_params(problem, times), order)
        else:
            local = self.local_basis(problem, times)
            matrix = problem.basis.rows(local.first, local.values[order])
        self._design[key] = (times, matrix)
        return matrix

    def local_basis(self, problem: SmoothingProblem, times: FloatArray) -> LocalBasis:
        """The nonzero basis functions and their ``s``-derivatives 0 to 3 (at most the
        degree) at a term's ``times``: what its design matrices, its banded normal
        matrix (:mod:`skyquill.optimize.banded`) and its time gradient are made of.
        Kept like :meth:`design_matrix`."""
        key = (id(times), problem.alpha, problem.degree, problem.n_ctrl)
        held = self._local.get(key)
        if held is not None and held[0] is times:
            return held[1]
        if len(self._local) >= _DESIGN_ENTRIES:
            self._local.clear()
        local = local_basis(problem, times)
        self._local[key] = (times, local)
        return local

    def band(
        self, matrix: sp.csr_array, k: int, build: Callable[[sp.csr_array, int], FloatArray]
    ) -> FloatArray:
        """``build(matrix, k)`` (a band of the smoothness block), kept while ``matrix`` is the
        very object :meth:`fixed` hands out again."""
        if self._band is None or self._band[0] is not matrix or self._band[1] != k:
            self._band = (matrix, k, build(matrix, k))
        return self._band[2]

    def local_bases(self, problem: SmoothingProblem, times: list[FloatArray]) -> list[LocalBasis]:
        """:meth:`local_basis` of several terms' ``times`` at once (one evaluation for
        those not kept yet: the terms of a writing route are four views of its samples)."""
        key = (problem.alpha, problem.degree, problem.n_ctrl)
        held = [self._local.get((id(t), *key)) for t in times]
        missing = [t for t, h in zip(times, held, strict=True) if h is None or h[0] is not t]
        if len(self._local) + len(missing) > _DESIGN_ENTRIES:
            self._local.clear()
        if len(self._by_content) + len(missing) > _DESIGN_ENTRIES:
            self._by_content.clear()
        # Equal times in new arrays (each problem validates copies of its terms' times):
        # the polish of a writing plan solves three problems at the same times.
        contents = {id(t): (t.tobytes(), *key) for t in missing}
        for t in missing:
            known = self._by_content.get(contents[id(t)])
            if known is not None:
                self._local[(id(t), *key)] = (t, known)
        missing = [t for t in missing if contents[id(t)] not in self._by_content]
        if missing:
            fresh = _split_local(
                local_basis(problem, np.concatenate(missing)), [t.size for t in missing]
            )
            for t, local in zip(missing, fresh, strict=True):
                self._local[(id(t), *key)] = (t, local)
                self._by_content[contents[id(t)]] = local
        return [self.local_basis(problem, t) for t in times]

    def kept(
        self,
        name: str,
        anchors: tuple[object, ...],
        values: tuple[object, ...],
        build: Callable[[], _T],
    ) -> _T:
        """``build()``, kept while ``anchors`` are the very objects and ``values`` are
        equal to those of a call with the same ``name`` (the last :data:`_KEPT` of them).

        The anchors are held, so their identity cannot be recycled.
        """
        entries = self._kept.setdefault(name, [])
        for held, same, kept_value in entries:
            if len(held) != len(anchors) or same != values:
                continue
            if all(a is b for a, b in zip(held, anchors, strict=True)):
                return kept_value  # type: ignore[no-any-return]
        value = build()
        entries.insert(0, (anchors, values, value))
        del entries[_KEPT:]
        return value

    def fixed(self, problem: SmoothingProblem) -> _Fixed:
        """The time-independent blocks of ``problem``, built or re-used."""
        key = _fixed_key(problem)
        if self._fixed is not None and key == self._key:
            self.hits += 1
            return self._fixed
        self._key, self._fixed = key, _build_fixed(problem)
        self.builds += 1
        return self._fixed


_T = TypeVar("_T")

#: Design matrices an :class:`AssemblyCache` keeps (a few terms of one or two problems).
_DESIGN_ENTRIES = 16
#: Values :meth:`AssemblyCache.kept` keeps per name (two groups of axes, two timings).
_KEPT = 4


#: Derivatives of the basis kept per term (:meth:`AssemblyCache.local_basis`): the tip's
#: first-order model needs the acceleration, its time gradient the jerk.
_LOCAL_ORDERS = 3


def _split_local(local: LocalBasis, sizes: list[int]) -> list[LocalBasis]:
    """``local`` of concatenated times cut back into one per part of ``sizes``."""
    # Views by plain slices (what np.split gives, without its per-part overhead).
    ends = np.cumsum(sizes).tolist()
    starts = [0, *ends[:-1]]
    return [
        LocalBasis(local.first[a:b], local.values[:, a:b])
        for a, b in zip(starts, ends, strict=True)
    ]


def local_basis(problem: SmoothingProblem, times: FloatArray) -> LocalBasis:
    """The nonzero basis rows and their ``s``-derivatives up to 3 (or the degree) at ``times``."""
    order = min(_LOCAL_ORDERS, problem.degree)
    return problem.basis.local_values(_params(problem, times), order)


def design_matrix(
    problem: SmoothingProblem, times: FloatArray, order: int = 0, cache: AssemblyCache | None = None
) -> sp.csr_array:
    """Basis rows of derivative ``order`` (in ``s``) at ``times`` (s), through ``cache`` if any."""
    if cache is not None:
        return cache.design_matrix(problem, times, order)
    return problem.basis.design_matrix(_params(problem, times), order)


def _fingerprint(value: object) -> object:
    """A hashable, exact (bitwise for arrays) stand-in for a problem term."""
    if isinstance(value, np.ndarray):
        return (value.shape, value.dtype.str, value.tobytes())
    if isinstance(value, tuple | list):
        return tuple(_fingerprint(v) for v in value)
    if hasattr(value, "__dataclass_fields__"):
        names = value.__dataclass_fields__
        return (type(value).__name__, *(_fingerprint(getattr(value, n)) for n in names))
    return value


def _fixed_key(problem: SmoothingProblem) -> tuple[object, ...]:
    return (
        problem.dim,
        problem.degree,
        problem.n_ctrl,
        problem.alpha,
        problem.hull,
        tuple(sorted(problem.smoothness.items())),
        _fingerprint(problem.boundary),
        _fingerprint(problem.limits),
        _fingerprint(problem.corridors),
    )


def _build_fixed(problem: SmoothingProblem) -> _Fixed:
    basis, alpha, M = problem.basis, problem.alpha, problem.n_ctrl
    smooth = [
        sigma * alpha ** (2 * order - 1) * basis.gram(order)
        for order, sigma in problem.smoothness.items()
        if sigma
    ]
    G_smooth = sp.csr_array(sum(smooth[1:], smooth[0]) if smooth else sp.csr_array((M, M)))
    G_ineq, h_ineq, families = _inequalities(problem)
    boundary = _boundary_rows(problem)
    E, e = _stack_equalities(problem, [np.array(boundary[0])] if boundary[0] else [], boundary[1])
    return _Fixed(G_smooth, boundary, E, e, G_ineq, h_ineq, families, _cones(problem))


def assemble(problem: SmoothingProblem, cache: AssemblyCache | None = None) -> Assembled:
    """Build the matrices of ``problem`` (validated).

    ``cache`` re-uses the blocks the point times do not change from the
    previous assembly when they would come out the same (:class:`AssemblyCache`).
    """
    M, d = problem.n_ctrl, problem.dim
    fixed = cache.fixed(problem) if cache is not None else _build_fixed(problem)
    G_axis = fixed.smooth
    F = np.zeros((M, d))
    coupled: list[tuple[sp.csr_array, FloatArray]] = []
    axes: list[tuple[FloatArray, sp.csr_array]] = []
    for term in problem.deviations:
        if not isinstance(term, PointDeviation):
            coupled.append(_flat_term(problem, term))
            continue
        groups = point_rows(problem, term, cache)
        for mask, H in groups:
            F -= 2.0 * term.weight * (H.T @ term.points) * mask
            if len(groups) == 1:
                G_axis = G_axis + term.weight * (H.T @ H)
            else:  # axes with different gains: one block per group of axes
                axes.append((mask, sp.csr_array(term.weight * (H.T @ H))))
    G_coupled = f_coupled = None
    if coupled:
        G_coupled = sp.csr_array(sum((g for g, _ in coupled), sp.csr_array((M * d, M * d))))
        f_coupled = np.sum([f for _, f in coupled], axis=0)

    diagonal = G_axis.diagonal().max(initial=0.0)
    for _, block in axes:
        diagonal = max(diagonal, (G_axis + block).diagonal().max(initial=0.0))
    if G_coupled is not None:
        diagonal = max(diagonal, G_coupled.diagonal().max(initial=0.0))
    # Without interpolated points the rows are the boundary's: the same objects
    # every time, which lets the solve re-use what it derives from them.
    E, e = _equalities(problem, fixed.boundary) if problem.interpolation else (fixed.E, fixed.e)
    return Assembled(
        1.0 / diagonal if diagonal > 0 else 1.0,
        sp.csr_array(G_axis),
        F,
        G_coupled,
        f_coupled,
        E,
        e,
        fixed.G_ineq,
        fixed.h_ineq,
        fixed.families,
        fixed.cones,
        tuple(axes),
    )


def problem_cost(
    problem: SmoothingProblem, C: FloatArray, cache: AssemblyCache | None = None
) -> dict[str, float]:
    """Cost of control points ``C`` (M, d), term by term: ``smoothness``, ``deviation``, ``total``.

    Smoothness is ``sum_n sigma_n alpha^(2n-1) sum_j D_j' W_n D_j`` on the
    derivative control points ``D = Gamma_n C`` (eq. 8-10), deviations are the
    residuals themselves (eq. 11, 25, 27): no cancellation of large terms.
    ``cache`` re-uses the design matrices of the assembly.
    """
    smooth = smoothness_cost(problem, C)
    deviation = 0.0
    for term in problem.deviations:
        if isinstance(term, PointDeviation):
            residual = point_model(problem, term, C, cache) - term.points
            deviation += term.weight * float(np.sum(residual**2))
        else:
            Q, w = term.quadratic()
            active = _window_controls(problem, term.t_start, term.t_end) > 0
            diff = C[active] - w
            deviation += term.weight * float(np.sum(diff * (diff @ Q)))
    return {"smoothness": smooth, "deviation": deviation, "total": smooth + deviation}


def smoothness_cost(problem: SmoothingProblem, C: FloatArray) -> float:
    """The smoothness part of :func:`problem_cost` for control points ``C`` (M, d)."""
    basis, alpha = problem.basis, problem.alpha
    smooth = 0.0
    for order, sigma in problem.smoothness.items():
        D = basis.derivative_map(order) @ C
        energy = float(np.sum(D * (basis.reduced_gram(order) @ D)))
        smooth += float(sigma * alpha ** (2 * order - 1) * energy)
    return smooth


def curve_at(
    problem: SmoothingProblem,
    times: FloatArray,
    C: FloatArray,
    order: int,
    cache: AssemblyCache | None = None,
) -> FloatArray:
    """The ``order``-th ``s``-derivative of the curve of ``C`` (M, d) at ``times``: (N, d).

    From the local basis rows (:meth:`AssemblyCache.local_basis`, kept per
    term), the same numbers as ``design_matrix(problem, times, order) @ C``
    without the sparse matrix.
    """
    local = cache.local_basis(problem, times) if cache is not None else local_basis(problem, times)
    if order >= local.values.shape[0]:
        return np.asarray(design_matrix(problem, times, order) @ C)
    return rows_times(local.first, local.values[order], C)


def curves_at(
    problem: SmoothingProblem,
    times: FloatArray,
    C: FloatArray,
    orders: int,
    cache: AssemblyCache | None = None,
) -> FloatArray:
    """The ``s``-derivatives ``0 .. orders - 1`` of the curve of ``C`` at ``times``:
    (orders, N, d), from the same local basis rows as :func:`curve_at`."""
    local = cache.local_basis(problem, times) if cache is not None else local_basis(problem, times)
    if orders > local.values.shape[0]:
        return np.stack([curve_at(problem, times, C, n, cache) for n in range(orders)])
    return rows_times(local.first, local.values[:orders], C)


def point_model(
    problem: SmoothingProblem,
    term: PointDeviation,
    C: FloatArray,
    cache: AssemblyCache | None = None,
) -> FloatArray:
    """What ``term`` compares with its points: ``p + c a`` at its times (N, d), m."""
    position = curve_at(problem, term.times, C, 0, cache)
    if term.accel_gain is None:
        return position
    acc = problem.alpha**2 * curve_at(problem, term.times, C, 2, cache)
    return np.asarray(position + term.accel_gain * acc)


def point_rows(
    problem: SmoothingProblem, term: PointDeviation, cache: AssemblyCache | None = None
) -> list[tuple[FloatArray, sp.csr_array]]:
    """The rows ``B(s_i) + c alpha^2 B''(s_i)`` of ``term`` (N, M), per group of axes.

    Returns ``[(mask (d,), rows), ...]``: the axes (``mask`` 1.0) whose gain
    ``c`` is the same share the rows (:meth:`PointDeviation.axis_groups`); one
    group, all axes, without a gain. ``d^2/dt^2 = alpha^2 d^2/ds^2``.
    """
    H = design_matrix(problem, term.times, 0, cache)
    groups = term.axis_groups()
    if len(groups) == 1 and groups[0][1] == 0.0:
        return [(groups[0][0], H)]
    H2 = design_matrix(problem, term.times, 2, cache) * problem.alpha**2
    return [(mask, sp.csr_array(H + gain * H2) if gain else H) for mask, gain in groups]


def _params(problem: SmoothingProblem, times: FloatArray) -> FloatArray:
    """Path parameters ``s = alpha * t`` of validated times, snapped to ``[0, L]``.

    ``SmoothingProblem`` accepts times up to 1e-9 * duration outside
    ``[0, duration]``, and even ``t = duration`` exactly can round to
    ``alpha * t`` just above or below ``L`` (e.g. L = 3, duration = 1.3437...).
    Above, the basis would reject it; below, a point meant for the end gets a
    row that is *almost* the boundary row, and the KKT matrix becomes nearly
    singular instead of exactly redundant. So parameters within 1e-9 L of an
    end are put on it.
    """
    L = float(problem.basis.n_spans)
    s = problem.alpha * np.asarray(times, dtype=float)
    s = np.where(np.abs(s - L) <= 1e-9 * L, L, s)
    s = np.where(np.abs(s) <= 1e-9 * L, 0.0, s)
    return np.clip(s, 0.0, L)


def _window_controls(problem: SmoothingProblem, t_start: float, t_end: float) -> FloatArray:
    """Indicator (M,) of the control points active on ``[t_start, t_end)`` (§3.4)."""
    first, last = problem.basis.spans_in_window(*_params(problem, np.array([t_start, t_end])))
    active = np.zeros(problem.n_ctrl)
    active[first : last + problem.degree + 1] = 1.0
    return active


def _flat_term(
    problem: SmoothingProblem, term: LineDeviation | PlaneDeviation
) -> tuple[sp.csr_array, FloatArray]:
    """Paper 003 eqs. (25), (27): ``sum_i (c_i - w)' Q (c_i - w)`` over the window.

    Returns the quadratic and linear parts; the constant ``w'Qw`` per point
    only enters :func:`problem_cost`.
    """
    Q, w = term.quadratic()
    active = _window_controls(problem, term.t_start, term.t_end)
    G = term.weight * sp.kron(sp.diags_array(active), Q, format="csr")
    f = -2.0 * term.weight * np.outer(active, Q @ w).ravel()
    return sp.csr_array(G), f


def _boundary_rows(
    problem: SmoothingProblem,
) -> tuple[list[FloatArray], list[FloatArray], dict[float, FloatArray]]:
    """Boundary rows (eq. 42) in ``s``, their right-hand sides, and the fixed end positions.

    Derivative rows are in ``s``: ``Gamma_n C = value / alpha^n`` (O(1) rows).
    """
    basis, alpha = problem.basis, problem.alpha
    dense_rows: list[FloatArray] = []
    rhs: list[FloatArray] = []
    fixed: dict[float, FloatArray] = {}
    for bc in problem.boundary:
        start_row, end_row = basis.end_rows(bc.order)
        to_s = alpha**-bc.order
        for row, value, s_end in ((start_row, bc.start, 0.0), (end_row, bc.end, basis.n_spans)):
            if value is not None:
                dense_rows.append(row)
                rhs.append(to_s * value[None, :])
                if bc.order == 0:
                    fixed[float(s_end)] = value
    return dense_rows, rhs, fixed


def _equalities(
    problem: SmoothingProblem,
    boundary: tuple[list[FloatArray], list[FloatArray], dict[float, FloatArray]],
) -> tuple[sp.csr_array, FloatArray]:
    """Boundary conditions (eq. 42, ``boundary`` from :func:`_boundary_rows`) and
    interpolated points (eq. 13), per axis.

    An interpolated point at ``t = 0`` or ``t = duration`` where the boundary
    already fixes the position repeats that row exactly (both are ``e_0`` or
    ``e_{M-1}``) and would make the KKT matrix singular: it is dropped if it
    agrees, and a contradiction raises :class:`InfeasibleError`.
    """
    basis = problem.basis
    dense_rows, boundary_rhs, fixed = boundary
    rhs = list(boundary_rhs)
    blocks: list[FloatArray | sp.csr_array] = [np.array(dense_rows)] if dense_rows else []
    for term in problem.interpolation:
        s = _params(problem, term.times)
        keep = np.ones(s.size, dtype=bool)
        for s_end, value in fixed.items():
            repeat = s == s_end
            if np.any(repeat) and not np.allclose(
                term.points[repeat], value, rtol=1e-12, atol=1e-12
            ):
                raise InfeasibleError(
                    "infeasible: the boundary conditions and interpolated points contradict "
                    f"each other: the position at s = {s_end:g} is fixed to {value.tolist()} "
                    f"and to {term.points[repeat][0].tolist()}",
                    ("equalities",),
                )
            keep &= ~repeat
        blocks.append(basis.design_matrix(s[keep]))
        rhs.append(term.points[keep])
    return _stack_equalities(problem, blocks, rhs)


def _stack_equalities(
    problem: SmoothingProblem, blocks: list[FloatArray | sp.csr_array], rhs: list[FloatArray]
) -> tuple[sp.csr_array, FloatArray]:
    """``E`` (m_eq, M) and ``e`` (m_eq, d) from row blocks and their right-hand sides."""
    if not blocks:
        return sp.csr_array((0, problem.n_ctrl)), np.zeros((0, problem.dim))
    return sp.csr_array(sp.vstack([sp.csr_array(b) for b in blocks])), np.vstack(rhs)


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
        if isinstance(lim, NormLimit) and lim.is_cone:
            continue  # held by _cones
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


@lru_cache(maxsize=64)
def _point_map(degree: int, n_ctrl: int, order: int, hull: HullKind, d: int) -> sp.csr_array:
    """``(Hull ⊗ I_d)`` in the normalised parameter: ``x -> vec(Hull C)``, point-major.

    Cached: re-segmentation assembles the same basis a dozen times per plan, and
    the Kronecker product cost more than a third of the assembly (3 ms a call on 永).
    """
    hull_map = basis_for(degree, n_ctrl).hull_map(order, kind=hull)
    points = kron_identity(hull_map, d)
    points.data.setflags(write=False)
    return points


def kron_identity(A: sp.csr_array, d: int) -> sp.csr_array:
    """``kron(A, I_d)`` for a CSR ``A`` (P, M) with sorted indices: (P d, M d).

    Row ``p d + a`` holds row ``p`` of ``A`` in columns ``m d + a``: built from ``A``'s
    arrays directly (``scipy.sparse.kron`` goes through COO and a sort: 3 ms a call).
    """
    A = sp.csr_array(A)
    A.sort_indices()
    per_row = np.repeat(np.diff(A.indptr), d)  # entries of each new row
    indptr = np.concatenate([[0], np.cumsum(per_row)])
    new_row = np.repeat(np.arange(A.shape[0] * d), per_row)
    entry = A.indptr[new_row // d] + np.arange(indptr[-1]) - indptr[new_row]
    indices = A.indices.take(entry) * d + new_row % d  # take: fancy indexing's values, faster
    shape = (A.shape[0] * d, A.shape[1] * d)
    return sp.csr_array((A.data.take(entry), indices, indptr), shape=shape)


def _cones(problem: SmoothingProblem) -> NormCones | None:
    """Exact norm limits on hull points: by convexity of the ball, on the whole curve."""
    basis, alpha, d = problem.basis, problem.alpha, problem.dim
    maps: list[sp.csr_array] = []
    radius: list[FloatArray] = []
    families: list[InequalityFamily] = []
    start = 0
    for lim in problem.limits:
        if not (isinstance(lim, NormLimit) and lim.is_cone):
            continue
        points = _point_map(basis.degree, basis.n_ctrl, lim.order, problem.hull, d)
        maps.append(points * alpha**lim.order)
        n_points = points.shape[0] // d
        radius.append(np.full(n_points, lim.radius))
        families.append(InequalityFamily(f"limit: {lim.label}", slice(start, start + n_points)))
        start += n_points
    if not maps:
        return None
    return NormCones(sp.csr_array(sp.vstack(maps)), np.concatenate(radius), tuple(families))


def _corridor_label(i: int, cor: Corridor) -> str:
    return f"corridor[{i}] on [{cor.t_start:g}, {cor.t_end:g}] s"
