"""Polish a QP solution: the exact minimiser on the active set of the solver's duals.

An interior-point solution is optimal only to the solver's tolerance: with
PIQP at tolerance 1e-10 the time gradient from its own point and duals was
off by up to 7e-5 relative (1e-5 with Clarabel) against central differences
of the exact optimal cost, on the random limited problems of
``tests/optimize/resegment``; the gradient is first-order in that error
where the cost is only second-order. So the rows with a positive multiplier
that are also tight at the solver's point (slack at most ``_TIGHT`` of the
bound: interior-point duals of nearby inactive rows are small but not zero,
and when nothing is active all of them are) are held at their (tightened)
bounds and the equality-constrained QP is solved exactly by one KKT solve
(:func:`skyquill.optimize.kkt.solve_equality_qp`), which also gives the
multipliers: the gradient error drops to ~1e-10.

Active second-order cones ``||v_p|| <= r_p`` (exact norm limits, ``v_p =
M_p x``) are held as the curved equalities ``1/2 (||M_p x||^2 - r_p^2) = 0``
with multipliers ``lambda_p = z_0 / r_p`` (Clarabel's block ``(z_0, z_1)``
has ``z_1 = lambda_p v_p``). They are solved by Newton's method on the KKT
conditions (SQP): each step is one KKT solve with the Hessian ``P + sum_p
lambda_p M_p' M_p`` and the cones linearised at the current point, started
from the solver's point and ``lambda``; it converges quadratically, in 2-4
steps. Without active cones this is the single KKT solve above.

Rows (and cones) the polished point violates are added and those with a
negative multiplier dropped until neither happens (a primal-dual active-set
iteration started from the solver's active set; one pass in the usual case).
If it does not settle, the KKT matrix is singular (the active rows are
dependent: no LICQ), or the polished point strays from the solver's, there
is no polished point and the solver's own point and duals are used.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from skyquill.optimize.kkt import SingularKKTError, solve_equality_qp
from skyquill.solvers import QuadraticProgram, SecondOrderCones
from skyquill.validation import FloatArray

#: ``() -> (x, y)``: the minimiser subject to the equalities alone and their multipliers.
EqualitySolve = Callable[[], tuple[FloatArray, FloatArray]]

#: A row is active when its multiplier exceeds this fraction of the largest.
_ACTIVE_DUAL_RTOL = 1e-6
_ITERATIONS = 10
#: Newton steps per active set (quadratic convergence: 2-4 in practice).
_NEWTON_STEPS = 12
#: Newton has converged when a step moves the point by less than this (relative):
#: it converges quadratically, so the point after a step of ``delta`` is off by
#: ~``delta^2``. Or when steps below ``_NEWTON_STALL`` stop shrinking (rounding level).
_NEWTON_RTOL = 1e-9
_NEWTON_STALL = 1e-9
#: A row (cone) with a positive multiplier is held only if its slack at the
#: solver's point is at most this, relative to its bound (radius).
_TIGHT = 1e-5
#: The polished point may move this far (relative) from the solver's.
_MAX_MOVE = 1e-3


@dataclass(frozen=True)
class Polished:
    """The exact minimiser on an active set and its multipliers.

    Attributes
    ----------
    x
        Minimiser, shape (n,) (the control points, vectorised).
    y
        Multipliers of the rows of ``A_eq``, shape (m_eq,).
    z
        Multipliers of the rows of ``G``, shape (m_in,), ``>= 0``; zero off
        the active set.
    cone_z
        Multipliers of the rows of ``qp.cones.A``, shape (m_c,), in the
        convention of :class:`skyquill.solvers.QPSolution` (block ``(lambda_p
        r_p, lambda_p v_p)`` on an active cone, zero elsewhere); ``None``
        without cones.
    """

    x: FloatArray
    y: FloatArray
    z: FloatArray
    cone_z: FloatArray | None = None


@dataclass(frozen=True)
class _Cones:
    """Uniform second-order cones ``||M_p x|| <= r_p`` split into maps and radii."""

    M: sp.csr_array  # (P d, n): rows of v_p, point-major
    r: FloatArray  # (P,)

    @classmethod
    def of(cls, cones: SecondOrderCones | None) -> _Cones | None:
        if cones is None:
            return None
        k = cones.dims[0]
        assert all(dim == k for dim in cones.dims), "the engine builds SOC(d + 1) only"
        vector_rows = np.flatnonzero(np.arange(cones.b.size) % k)
        # Clarabel's rows are (r_p, -v_p) = b - A x with A x = (0, M_p x).
        return cls(sp.csr_array(cones.A)[vector_rows.tolist(), :], cones.b[::k].copy())

    @property
    def dim(self) -> int:
        return self.M.shape[0] // self.r.size

    def v(self, x: FloatArray) -> FloatArray:
        return np.asarray(self.M @ x).reshape(self.r.size, -1)

    def lam(self, cone_z: FloatArray) -> FloatArray:
        """``lambda_p = z_0 / r_p`` from Clarabel's blocks."""
        return cone_z[:: self.dim + 1] / self.r

    def spread(self, lam: FloatArray, x: FloatArray) -> FloatArray:
        """Clarabel's blocks ``(lambda_p r_p, lambda_p v_p)``, shape (P (d + 1),)."""
        return np.column_stack([lam * self.r, lam[:, None] * self.v(x)]).ravel()


def polish(
    qp: QuadraticProgram,
    x0: FloatArray,
    z0: FloatArray,
    cone_z0: FloatArray | None = None,
    *,
    equality_solve: EqualitySolve | None = None,
) -> Polished | None:
    """Polish the solution ``x0`` (n,) with inequality duals ``z0`` (m_in,) of ``qp``.

    Parameters
    ----------
    qp
        The QP that was solved (with the solve's tightened ``h`` and cone
        radii: :func:`skyquill.optimize.solve._to_qp`).
    x0
        The solver's point, shape (n,).
    z0
        The solver's inequality multipliers, shape (m_in,).
    cone_z0
        The solver's cone multipliers, shape (m_c,) (``QPSolution.cone_z``);
        required when ``qp`` has cones.
    equality_solve
        Another way to the minimiser subject to the equalities alone, and
        their multipliers (the closed form, which factors the per-axis
        system once for all axes: a third of the unknowns). Used when nothing
        is held, the usual case of a writing mission at its default limits;
        raises :class:`SingularKKTError` like the KKT solve it replaces.

    Returns
    -------
    Polished or None
        ``None`` when there is no polished point (module docstring).
    """
    G, h = qp.G, qp.h
    scale = np.maximum(np.abs(h), 1e-3)
    cones = _Cones.of(qp.cones)
    # Only rows tight at the solver's point: when no row is active the duals are all
    # ~0 and a relative threshold alone would hold every row (more rows than unknowns).
    active = _active(z0)
    active = active[(h[active] - G[active.tolist(), :] @ x0) / scale[active] <= _TIGHT]
    lam = np.zeros(0)
    if cones is not None:
        assert cone_z0 is not None, "polish: cone duals are required with cones"
        lam = np.maximum(cones.lam(cone_z0), 0.0)
    on_cone = _active(lam)
    if cones is not None:
        # Clarabel leaves lambda ~1e-3 of the largest on cones 1e-3 (relative) inside
        # their radius next to the active ones (the interior-point path's centring):
        # held on their spheres they come back with lambda < 0, one active-set pass
        # each. A cone counts only if it is also tight at the solver's point.
        slack = 1.0 - np.linalg.norm(cones.v(x0), axis=1) / cones.r
        on_cone = on_cone[slack[on_cone] <= _TIGHT]
    x = x0
    for _ in range(_ITERATIONS):
        try:
            # Warm start: the last active set's minimiser is near the next one's.
            if equality_solve is not None and active.size == 0 and on_cone.size == 0:
                x, y = equality_solve()
                z_active, lam_active = np.zeros(0), np.zeros(0)
            else:
                x, y, z_active, lam_active = _newton(
                    qp, cones, x, lam=lam, active=active, on_cone=on_cone
                )
        except SingularKKTError:
            return None
        violated = np.setdiff1d(np.flatnonzero((G @ x - h) / scale > 1e-12), active)
        negative = z_active < -1e-9 * max(float(np.abs(z_active).max(initial=0.0)), 1e-300)
        cone_violated, cone_negative = _cone_changes(cones, x, on_cone, lam_active)
        if not (violated.size or negative.any() or cone_violated.size or cone_negative.any()):
            return _accept(
                x,
                x0,
                y=y,
                z=z_active,
                active=active,
                m_in=G.shape[0],
                cones=cones,
                lam=lam_active,
                on_cone=on_cone,
            )
        active = np.union1d(active[~negative], violated)
        if cones is not None:
            lam = np.zeros(cones.r.size)
            lam[on_cone[~cone_negative]] = lam_active[~cone_negative]
            on_cone = np.union1d(on_cone[~cone_negative], cone_violated)
    return None


def _cone_changes(
    cones: _Cones | None, x: FloatArray, on_cone: NDArray[np.intp], lam: FloatArray
) -> tuple[NDArray[np.intp], NDArray[np.bool_]]:
    """Cones ``x`` violates off ``on_cone``, and which of ``on_cone`` have ``lam < 0``."""
    if cones is None:
        return np.zeros(0, np.intp), np.zeros(0, bool)
    excess = (np.linalg.norm(cones.v(x), axis=1) - cones.r) / np.maximum(cones.r, 1e-3)
    violated = np.setdiff1d(np.flatnonzero(excess > 1e-12), on_cone)
    return violated, lam < -1e-9 * max(float(np.abs(lam).max(initial=0.0)), 1e-300)


def _active(duals: FloatArray) -> NDArray[np.intp]:
    """Indices of the multipliers above ``_ACTIVE_DUAL_RTOL`` of the largest."""
    return np.flatnonzero(duals > _ACTIVE_DUAL_RTOL * float(duals.max(initial=0.0)))


def _newton(
    qp: QuadraticProgram,
    cones: _Cones | None,
    x: FloatArray,
    *,
    lam: FloatArray,
    active: NDArray[np.intp],
    on_cone: NDArray[np.intp],
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Minimiser on the active set: ``(x, y, z_active, lambda_on_cone)`` (module docstring).

    ``lam`` (P,) starts the cone multipliers; only ``on_cone`` entries are used.
    """
    m, n_lin = qp.b_eq.size, active.size
    linear = sp.csr_array(sp.vstack([qp.A_eq, qp.G[active.tolist(), :]], format="csr"))
    rhs = np.concatenate([qp.b_eq, qp.h[active]])
    P = sp.csr_array(qp.P)
    if cones is None or on_cone.size == 0:
        sol = solve_equality_qp(P, qp.q, linear, rhs)
        return sol.x, sol.y[:m], sol.y[m:], np.zeros(0)
    d = cones.dim
    rows = (on_cone[:, None] * d + np.arange(d)).ravel()
    M = cones.M[rows.tolist(), :]  # (|on| d, n)
    r = cones.r[on_cone]
    lam_on = lam[on_cone].copy()
    last = np.inf
    for _ in range(_NEWTON_STEPS):
        v = np.asarray(M @ x).reshape(-1, d)
        weights = sp.diags_array(np.repeat(lam_on, d))
        hessian = sp.csr_array(P + M.T @ weights @ M)
        # Row p: v_p' M_p, the gradient of 1/2 ||M_p x||^2 at the current x.
        select = sp.csr_array(
            (v.ravel(), (np.repeat(np.arange(r.size), d), np.arange(r.size * d))),
            shape=(r.size, r.size * d),
        )
        jac = sp.csr_array(select @ M)
        sol = solve_equality_qp(
            hessian,
            qp.q - M.T @ (np.repeat(lam_on, d) * (M @ x)),
            sp.csr_array(sp.vstack([linear, jac], format="csr")),
            np.concatenate([rhs, 0.5 * ((v**2).sum(axis=1) + r**2)]),
        )
        size = max(1.0, float(np.linalg.norm(sol.x)))
        step = float(np.linalg.norm(sol.x - x)) / size
        x, lam_on = sol.x, sol.y[m + n_lin :]
        if step <= _NEWTON_RTOL or (step < _NEWTON_STALL and step >= 0.5 * last):
            return x, sol.y[:m], sol.y[m : m + n_lin], lam_on
        last = step
    raise SingularKKTError(f"Newton on {r.size} active cone(s) did not converge")


def _accept(
    x: FloatArray,
    x0: FloatArray,
    *,
    y: FloatArray,
    z: FloatArray,
    active: NDArray[np.intp],
    m_in: int,
    cones: _Cones | None,
    lam: FloatArray,
    on_cone: NDArray[np.intp],
) -> Polished | None:
    """The polished point with ``z`` (active rows) spread over all ``m_in`` rows,
    unless it strays from the solver's ``x0``."""
    if float(np.linalg.norm(x - x0)) > _MAX_MOVE * max(1.0, float(np.linalg.norm(x0))):
        return None
    z_all = np.zeros(m_in)
    z_all[active] = np.maximum(z, 0.0)
    if cones is None:
        return Polished(x, y, z_all)
    lam_all = np.zeros(cones.r.size)
    lam_all[on_cone] = np.maximum(lam, 0.0)
    return Polished(x, y, z_all, cones.spread(lam_all, x))
