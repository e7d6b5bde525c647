"""A primal-dual interior-point method for LPs whose rows couple at most three neighbouring nodes.

The grid LP of the speed plan with jerk rows (:mod:`.rows`) reads

    maximise   sum_i w_i b_i
    subject to |L_ki b_{i-1} + M_ki b_i + U_ki b_{i+1}| <= r_ki   (row k of node i)
               0 <= b_i <= ub_i

Every row touches at most three consecutive nodes, so the normal matrix of an
interior-point step, ``A' D A`` plus the diagonal of the column bounds, is
pentadiagonal: one Newton step is a banded Cholesky factorisation (LAPACK
``pbtrf``) and a few banded solves, ``O(n)`` work. The general solvers we
depend on see the same band through their sparse orderings but pay much more
for it: on the 2,000-point pseudo-jerk LP of the 10 m square's spiral (12,000
rows; a loaded 2-core machine) HiGHS's dual simplex took 2.5 s from scratch,
its interior-point solvers (IPX with and without crossover, HiPO) 1.7-2.2 s,
Clarabel 0.67 s and PIQP 0.23 s.

The method is Mehrotra's predictor-corrector with separate primal and dual
step lengths, from an infeasible interior point, on the rows laid out as
``(R, n)`` arrays (row ``k`` of every node), so that every operation is a
handful of contiguous array operations. It stops when the complementarity gap
and the primal residual are below :data:`TOLERANCE` (relative to the
objective).

Accuracy. The jerk rows are second differences of ``b`` over ``h**2``: the
normal matrix's condition grows like ``n**4`` on a stretch where jerk rows are
active, and the dual residual stalls at ``1e-3``-``1e-2`` from about 8,000
points (the primal keeps converging: the objective agreed with HiGHS's
simplex to 1e-8 relative at 8,000 points). The dual is therefore not used
for anything; the tests compare the objective with HiGHS's. The rows are
homogeneous (``b = 0`` is feasible and every row bound is positive), so the
final iterate is made exactly feasible by scaling it down by the largest row
excess (about ``1e-10``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import cho_solve_banded, cholesky_banded

from skyquill.validation import FloatArray

#: Relative complementarity gap and primal residual at which the iteration stops.
TOLERANCE = 1e-9
#: Most Newton steps of one solve (20-30 are typical).
MAX_ITERATIONS = 60
#: Fraction of the step to the boundary of the positive orthant that is taken.
STEP_FRACTION = 0.995
#: Relative diagonal shift of the normal matrix (keeps the factorisation defined).
REGULARISATION = 1e-13
#: A column at most this fraction of its upper bound is 0. The interior point leaves a
#: column it drives to its lower bound at ~1e-11, never at 0; the simplex answers 0, and
#: a plan whose speed vanishes between two nodes is refused on that (a grid that collapses
#: around a turn shorter than a cell). Without it the iteration went on from a speed of
#: 1e-5 m/s: 122 solves and 68 s on the held-out 1.3 ha outline's spiral at 4,000 points,
#: where the LP stopped after 6 s.
VANISHING = 1e-9


@dataclass(frozen=True)
class BandedRows:
    """Rows ``|lower b_{i-1} + centre b_i + upper b_{i+1}|`` of every node ``i``.

    Attributes
    ----------
    lower, centre, upper : ndarray, shape (R, n)
        Coefficient of ``b_{i-1}``, ``b_i``, ``b_{i+1}`` in row ``k`` of node
        ``i`` (``lower[:, 0]`` and ``upper[:, -1]`` must be 0).
    """

    lower: FloatArray
    centre: FloatArray
    upper: FloatArray

    def values(self, b: FloatArray) -> FloatArray:
        """The rows at ``b`` (n,), shape (R, n)."""
        out = self.centre * b
        out[:, 1:] += self.lower[:, 1:] * b[:-1]
        out[:, :-1] += self.upper[:, :-1] * b[1:]
        return out


@dataclass(frozen=True)
class BandedSolution:
    """What :func:`solve_banded_lp` returns.

    Attributes
    ----------
    b : ndarray, shape (n,)
        The solution, inside every row and column bound.
    status : {"optimal", "iteration_limit"}
        ``"iteration_limit"``: the gap did not close in :data:`MAX_ITERATIONS`
        steps (``b`` is still feasible, but not optimal).
    iterations : int
        Newton steps taken.
    gap : float
        Relative complementarity gap at the end.
    """

    b: FloatArray
    status: str
    iterations: int
    gap: float


class _Scaled:
    """The rows divided by their bounds, the columns by theirs (``b = scale x``)."""

    def __init__(self, rows: BandedRows, bound: FloatArray, scale: FloatArray) -> None:
        with np.errstate(divide="ignore"):
            inv = np.where(np.isfinite(bound), 1.0 / bound, 0.0)
        self.lo = np.zeros_like(rows.lower)
        self.lo[:, 1:] = rows.lower[:, 1:] * inv[:, 1:] * scale[:-1]
        self.mid = rows.centre * inv * scale
        self.up = np.zeros_like(rows.upper)
        self.up[:, :-1] = rows.upper[:, :-1] * inv[:, :-1] * scale[1:]
        # Products for the normal matrix (fixed within a solve).
        self.ll, self.mm, self.uu = self.lo**2, self.mid**2, self.up**2
        self.lm, self.mu, self.lu = self.lo * self.mid, self.mid * self.up, self.lo * self.up

    def apply(self, x: FloatArray) -> FloatArray:
        """``A x``, shape (R, n)."""
        out = self.mid * x
        out[:, 1:] += self.lo[:, 1:] * x[:-1]
        out[:, :-1] += self.up[:, :-1] * x[1:]
        return out

    def transpose(self, y: FloatArray) -> FloatArray:
        """``A' y`` for ``y`` of shape (R, n), shape (n,)."""
        out: FloatArray = np.einsum("kn,kn->n", self.mid, y)
        out[:-1] += np.einsum("kn,kn->n", self.lo[:, 1:], y[:, 1:])
        out[1:] += np.einsum("kn,kn->n", self.up[:, :-1], y[:, :-1])
        return out

    def normal(self, d: FloatArray) -> FloatArray:
        """``A' diag(d) A`` in LAPACK's lower banded form, shape (3, n)."""
        n = d.shape[1]
        ab = np.zeros((3, n))
        ab[0] = np.einsum("kn,kn->n", self.mm, d)
        ab[0, :-1] += np.einsum("kn,kn->n", self.ll[:, 1:], d[:, 1:])
        ab[0, 1:] += np.einsum("kn,kn->n", self.uu[:, :-1], d[:, :-1])
        # (i, i + 1): node i's centre with its upper, node i + 1's lower with its centre.
        ab[1, :-1] = np.einsum("kn,kn->n", self.mu[:, :-1], d[:, :-1])
        ab[1, :-1] += np.einsum("kn,kn->n", self.lm[:, 1:], d[:, 1:])
        # (i - 1, i + 1) through the rows of node i.
        ab[2, :-2] = np.einsum("kn,kn->n", self.lu[:, 1:-1], d[:, 1:-1])
        return ab


def solve_banded_lp(
    rows: BandedRows,
    bound: FloatArray,
    ub: FloatArray,
    weights: FloatArray,
    *,
    tolerance: float = TOLERANCE,
) -> BandedSolution:
    """``max weights' b`` s.t. ``|rows(b)| <= bound`` and ``0 <= b <= ub``.

    Parameters
    ----------
    rows : BandedRows
        ``R`` rows per node.
    bound : ndarray, shape (R, n)
        Row bounds, ``> 0``; ``inf`` leaves a row free.
    ub : ndarray, shape (n,)
        Column upper bounds, finite, ``>= 0``; a column at 0 stays there.
    weights : ndarray, shape (n,)
        Objective weights, ``> 0``.
    tolerance : float, default :data:`TOLERANCE`
        Relative gap and primal residual at which to stop (an iterate of a
        fixed-point iteration needs less than the last solve).

    Returns
    -------
    BandedSolution
        The optimum (to :data:`TOLERANCE`), exactly feasible.
    """
    ub = np.maximum(np.asarray(ub, dtype=np.float64), 0.0)
    bound = np.asarray(bound, dtype=np.float64)
    if not np.any(ub > 0.0):
        return BandedSolution(np.zeros(ub.size), "optimal", 0, 0.0)
    # x in [0, 1]; a column fixed at 0 has scale 0 (its x is a free dummy in the box).
    a = _Scaled(rows, bound, ub)
    cost = -np.asarray(weights, dtype=np.float64) * ub
    cost /= float(np.max(np.abs(cost)))
    x, status, its, gap = _mehrotra(a, cost, tolerance)
    b = np.where(x <= VANISHING, 0.0, np.minimum(x, 1.0)) * ub
    return BandedSolution(feasible(rows, bound, b), status, its, gap)


def feasible(rows: BandedRows, bound: FloatArray, b: FloatArray) -> FloatArray:
    """``b`` scaled down so that every row holds (the rows are homogeneous in ``b``)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(np.isfinite(bound), np.abs(rows.values(b)) / bound, 0.0)
    worst = float(np.max(ratio))
    if worst <= 1.0:
        return b
    # 4 eps below: the caller evaluates the rows again, with its own round-off.
    return b * ((1.0 - 4.0 * np.finfo(float).eps) / worst)


class _State:
    """Slacks and duals of the four blocks ``A x <= 1``, ``-A x <= 1``, ``x <= 1``, ``-x <= 0``,
    stored flat: ``[rows upper (R n), rows lower (R n), columns upper (n), columns lower (n)]``."""

    def __init__(self, shape: tuple[int, int]) -> None:
        self.shape = shape
        self.m = shape[0] * shape[1]

    def split(self, v: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        m, n = self.m, self.shape[1]
        return (
            v[:m].reshape(self.shape),
            v[m : 2 * m].reshape(self.shape),
            v[2 * m : 2 * m + n],
            v[2 * m + n :],
        )

    def stack(self, ax: FloatArray, x: FloatArray) -> FloatArray:
        """``G x`` for ``A x`` and ``x``."""
        flat = ax.ravel()
        return np.concatenate([flat, -flat, x, -x])


def _mehrotra(a: _Scaled, cost: FloatArray, tolerance: float) -> tuple[FloatArray, str, int, float]:
    """Mehrotra's predictor-corrector on ``min cost' x`` s.t. ``|A x| <= 1``, ``0 <= x <= 1``.

    Returns ``x``, the status, the iterations and the relative gap.
    """
    n = cost.size
    st = _State(a.mid.shape)
    h = np.concatenate([np.ones(2 * st.m), np.ones(n), np.zeros(n)])
    x = np.full(n, 0.5)
    s = np.maximum(h - st.stack(a.apply(x), x), 0.5)
    z = np.ones_like(s)
    status, gap, its = "iteration_limit", np.inf, 0
    while its < MAX_ITERATIONS:
        its += 1
        zu, zl, zb, z0 = st.split(z)
        rd = a.transpose(zu - zl) + zb - z0 + cost
        rp = st.stack(a.apply(x), x) + s - h
        obj = float(cost @ x)
        # Relative to the objective itself, down to 1e-6 (an optimum at b = 0): the old
        # floor of 1 made the gap absolute where the objective is small (a path that all
        # but doubles back: column bounds 1e4 apart, |obj| 0.003), and the objective came
        # out 3.6e-7 below HiGHS's at a "gap" of 3e-10.
        gap = float(s @ z) / max(1e-6, abs(obj))
        if gap <= tolerance and float(np.max(np.abs(rp))) <= tolerance:
            status = "optimal"
            break
        mu = float(s @ z) / s.size
        w = z / s
        factor = _factor(a, st, w)
        # Predictor (affine scaling), then the corrector with centring and the
        # second-order term, on the same factorisation. (rc / s of the predictor is z.)
        wrp = w * rp
        dx, ds, dz = _newton(a, st, factor, w=w, res=(rd, rp, wrp), rcs=z)
        sigma = (_affine_mu(s, z, ds, dz) / mu) ** 3
        rcs = z + (ds * dz - sigma * mu) / s
        dx, ds, dz = _newton(a, st, factor, w=w, res=(rd, rp, wrp), rcs=rcs)
        ap = min(1.0, STEP_FRACTION * _max_step(s, ds))
        ad = min(1.0, STEP_FRACTION * _max_step(z, dz))
        x = x + ap * dx
        s = s + ap * ds
        z = z + ad * dz
    return x, status, its, gap


def _factor(a: _Scaled, st: _State, w: FloatArray) -> FloatArray:
    """Banded Cholesky factor of ``G' W G = A' (W_u + W_l) A + W_ub + W_lb``."""
    wu, wl, wb, w0 = st.split(w)
    ab = a.normal(wu + wl)
    ab[0] += wb + w0
    ab[0] *= 1.0 + REGULARISATION
    return np.asarray(cholesky_banded(ab, lower=True, check_finite=False), dtype=np.float64)


def _newton(
    a: _Scaled,
    st: _State,
    factor: FloatArray,
    *,
    w: FloatArray,
    res: tuple[FloatArray, FloatArray, FloatArray],
    rcs: FloatArray,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The direction of ``G' dz = -rd``, ``G dx + ds = -rp``, ``Z ds + S dz = -rc``.

    ``w = z / s``, ``res = (rd, rp, w rp)`` and ``rcs = rc / s`` (the predictor and the
    corrector share all but ``rcs``). With ``v = W rp - rc / s``, ``dz = W G dx + v``:
    ``G' W G dx = -rd - G' v``.
    """
    rd, rp, wrp = res
    v = wrp - rcs
    vu, vl, vb, v0 = st.split(v)
    rhs = -rd - (a.transpose(vu - vl) + vb - v0)
    dx = np.asarray(cho_solve_banded((factor, True), rhs, check_finite=False), dtype=np.float64)
    gdx = st.stack(a.apply(dx), dx)
    dz = w * gdx + v
    ds = -rp - gdx
    return dx, ds, dz


def _affine_mu(s: FloatArray, z: FloatArray, ds: FloatArray, dz: FloatArray) -> float:
    """Mean complementarity after the longest affine steps."""
    ap = _max_step(s, ds)
    ad = _max_step(z, dz)
    return float((s + ap * ds) @ (z + ad * dz)) / s.size


def _max_step(v: FloatArray, dv: FloatArray) -> float:
    """The largest ``alpha <= 1`` with ``v + alpha dv >= 0``, for ``v > 0`` (the slacks and
    duals stay strictly positive): ``1 / max(-dv / v)`` over the entries that decrease, in
    two passes over the arrays instead of five."""
    with np.errstate(divide="ignore", invalid="ignore"):  # (a slack that underflowed to 0)
        least = float(np.min(dv / v))
    return 1.0 if not least < -1.0 else -1.0 / least
