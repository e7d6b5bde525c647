"""Central finite differences of the optimal cost: paper 000 eq. (56), the reference.

One solve per perturbed time (two for the central scheme): the check of the
analytic gradient (:mod:`.gradient`) and the paper's own method, which the
benchmark compares against.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from skyquill.optimize.resegment.gradient import time_gradient
from skyquill.optimize.resegment.problems import (
    ProblemFactory,
    times_from_segments,
    zero_based,
)
from skyquill.optimize.resegment.results import Mode
from skyquill.optimize.solve import solve
from skyquill.solvers import DEFAULT_BACKEND
from skyquill.validation import FloatArray


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
    t = zero_based("times", times)
    T = np.diff(t)
    n = T.size
    h = step * float(T.mean())

    def f(T_new: FloatArray) -> float:
        tt = times_from_segments(T_new)
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
